"""States of one CG step that the kernel-set tests share (tests/contact/test_array_kernels.py,
tests/contact/test_device_kernels.py; tests import helpers by file)."""

from __future__ import annotations

import numpy as np


def cg_state(rng, n: int, at_bound: float | None = None) -> dict:
    """A CG state of ``n`` points with a free set of ~60 %, a direction, ``r``, bounds 0.9;
    with ``at_bound``, about 30 % of the constrained points get that pressure (for the
    violator test's second clause: at the bound and open)."""
    p = np.where(rng.random(n) < 0.6, rng.random(n), 0.0)
    m = (p > 0).astype(np.uint8)
    if at_bound is not None:
        p[(m == 0) & (rng.random(n) < 0.3)] = at_bound
    return {
        "p": p,
        "m": m,
        "u": rng.normal(size=n),
        "h": rng.normal(size=n),
        "t": rng.normal(size=n) * m,
        "r": rng.normal(size=n),
        "p_max": np.full(n, 0.9),
    }


def update_case(rng, n: int, bounded: bool, events: int, closed: bool = False) -> dict:
    """A state of ``n`` points whose step clips about ``events`` free points and adds as
    many violators: free points step by ``tau·t`` with ``t`` small except on the chosen ones.
    With ``closed`` the clipped points penetrate, so that those clipped at the bound (0.9)
    stay there."""
    p = np.where(rng.random(n) < 0.6, 0.2 + 0.5 * rng.random(n), 0.0)
    m = (p > 0).astype(np.uint8)
    t = 1e-3 * rng.normal(size=n) * m
    free, bound = np.flatnonzero(m), np.flatnonzero(m == 0)
    clip = rng.choice(free, events, replace=False)
    t[clip] = 5.0 * np.sign(rng.normal(size=events)) if bounded else 5.0
    u = np.abs(rng.normal(size=n)) + 3.0  # open everywhere (g > 0) ...
    h = np.zeros(n)
    join = rng.choice(bound, events, replace=False)
    u[join] = -0.5  # ... but at the chosen constrained points
    if closed:
        u[clip] = -0.5
    p_max = np.full(n, 0.9) if bounded else np.full(1, np.inf)
    if bounded:
        # a few constrained points at the bound, open: they fall
        top = rng.choice(np.setdiff1d(bound, join), events, replace=False)
        p[top] = 0.9
    return {"p": p, "m": m, "t": t, "u": u, "h": h, "r": rng.normal(size=n), "p_max": p_max}
