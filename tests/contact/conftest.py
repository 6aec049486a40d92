"""Shared fixtures for the contact-solver tests (small grids: the suite must stay fast)."""

import numpy as np
import pytest

from amontons.contact import solve, sphere


@pytest.fixture(scope="session")
def hertz_case():
    """Non-periodic Hertz problem on 128², contact radius ~30 pixels.

    SI-like but arbitrary units: R = 1 m, E* = 1 Pa, spacing 0.01 m; the target radius
    a = 0.30 m spans 30 pixels and the window edge is 64 pixels from the apex.
    """
    e_star, radius, dx, n = 1.0, 1.0, 0.01, 128
    a_target = 0.30
    load = 4 * e_star * a_target**3 / (3 * radius)
    h = sphere((n, n), dx, radius)
    res = solve(h, dx, e_star, load=load)
    return {
        "e_star": e_star,
        "radius": radius,
        "dx": dx,
        "n": n,
        "load": load,
        "heights": h,
        "result": res,
    }


@pytest.fixture(scope="session")
def rough_case():
    """Periodic self-affine surface, 64², ~10 % contact, converged to 1e-10."""
    from amontons.contact import self_affine

    n, dx, e_star = 64, 1.0, 1.0
    h = self_affine((n, n), dx, 0.8, rms_slope=0.1, rng=7)
    load = 0.005 * e_star * (n * dx) ** 2
    res = solve(h, dx, e_star, load=load, periodic=True, tol=1e-10)
    return {
        "e_star": e_star,
        "dx": dx,
        "n": n,
        "load": load,
        "heights": h,
        "result": res,
        "rng": np.random.default_rng(0),
    }
