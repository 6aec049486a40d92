"""Failure is loud: bad input, non-convergence and contact at the window edge raise."""

import numpy as np
import pytest

from amontons.contact import (
    ContactInputError,
    ConvergenceError,
    FreeBoundaryError,
    solve,
    sphere,
)

H = sphere((32, 32), 0.01, 1.0)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"load": -1.0}, "load"),
        ({"load": 0.0}, "load"),
        ({"load": float("nan")}, "load"),
        ({}, "exactly one"),
        ({"load": 1e-3, "displacement": 1e-3}, "exactly one"),
        ({"load": 1e-3, "tol": 0.0}, "tol"),
        ({"load": 1e-3, "max_iter": 0}, "max_iter"),
    ],
)
def test_bad_control_values(kwargs, match):
    with pytest.raises(ContactInputError, match=match):
        solve(H, 0.01, 1.0, **kwargs)


def test_nan_heights_named():
    h = H.copy()
    h[3, 4] = np.nan
    with pytest.raises(ContactInputError, match=r"non-finite.*\(3, 4\)"):
        solve(h, 0.01, 1.0, load=1e-3)


@pytest.mark.parametrize(
    ("spacing", "e_star", "match"),
    [
        (0.0, 1.0, "spacing"),
        (-1.0, 1.0, "spacing"),
        (0.01, 0.0, "e_star"),
        (0.01, -2.0, "e_star"),
        (0.01, float("inf"), "e_star"),
    ],
)
def test_bad_spacing_or_modulus(spacing, e_star, match):
    with pytest.raises(ContactInputError, match=match):
        solve(H, spacing, e_star, load=1e-3)


@pytest.mark.parametrize("bad", [np.zeros(10), np.zeros((2, 3, 4)), [[1.0]]])
def test_bad_shape(bad):
    with pytest.raises(ContactInputError, match="heights"):
        solve(bad, 0.01, 1.0, load=1e-3)


def test_bad_warm_start():
    with pytest.raises(ContactInputError, match="warm_start"):
        solve(H, 0.01, 1.0, load=1e-3, warm_start=-np.ones_like(H))
    with pytest.raises(ContactInputError, match="warm_start"):
        solve(H, 0.01, 1.0, load=1e-3, warm_start=np.ones((3, 3)))


def test_convergence_error_carries_history():
    """Two iterations cannot reach 1e-8: ConvergenceError with the numbers attached."""
    with pytest.raises(ConvergenceError, match="did not converge in 2 iterations") as info:
        solve(H, 0.01, 1.0, load=1e-3, max_iter=2)
    err = info.value
    assert err.iterations == 2 and len(err.residual_history) == 2
    assert err.residual > err.tol == 1e-8
    assert err.status == 1  # iteration cap, as a returned result would say


def test_free_boundary_error():
    """A load so large that the Hertz radius exceeds the window raises, naming the edge
    pixel count, instead of returning a padded (wrong) solution."""
    load = 4 * 1.0 * 0.3**3 / 3  # a = 0.30 m on a 0.32 m window
    with pytest.raises(FreeBoundaryError, match="edge pixel") as info:
        solve(H, 0.01, 1.0, load=load)
    assert info.value.edge_pixels > 0 and info.value.edge_force > 0


def test_periodic_displacement_control_full_contact_is_refused():
    """Periodic + displacement control at full contact is singular (uniform pressure costs
    no displacement): the solver must say so instead of diverging."""
    x = np.arange(64) / 64
    h = np.broadcast_to(1e-3 * np.cos(2 * np.pi * x), (4, 64)).copy()
    with pytest.raises(ConvergenceError, match="full contact") as info:
        solve(h, 1 / 64, 1.0, displacement=5e-3, periodic=True)
    assert info.value.status == 2  # stalled
