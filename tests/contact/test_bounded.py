"""The bounded constraint 0 <= p <= p_max slotted into the same CG (no plasticity here)."""

import numpy as np
import pytest

from amontons.contact.cg import BoundedWall, HardWall, polonsky_keer
from amontons.contact.convolution import get_operator
from amontons.contact.surfaces import self_affine


@pytest.fixture(scope="module")
def problem():
    n = 64
    h = self_affine((n, n), 1.0, 0.8, rms_slope=0.1, rng=2)
    op = get_operator((n, n), 1.0, 1.0, periodic=True)
    kw = {"pixel_area": 1.0, "h_scale": h.std(), "displacement": -1.0 * h.std(), "tol": 1e-10}
    return op, h, kw


def test_infinite_bound_is_hard_wall(problem):
    """p_max far above any pressure: identical problem, so the fields agree to the
    solver tolerance (1e-8 of the peak pressure)."""
    op, h, kw = problem
    ref = polonsky_keer(op, h, p_init=np.zeros_like(h), constraint=HardWall(), **kw)
    big = polonsky_keer(op, h, p_init=np.zeros_like(h), constraint=BoundedWall(1e6), **kw)
    assert np.abs(big.pressure - ref.pressure).max() < 1e-8 * ref.pressure.max()


@pytest.mark.parametrize("per_pixel", [False, True])
def test_bound_respected_with_complementarity(problem, per_pixel):
    """With p_max at 30 % of the elastic peak: 0 <= p <= p_max; free points close the gap
    (|g| < 1e-8 h_rms); points at the bound penetrate (g <= 1e-8 h_rms); unloaded points
    are open (g >= -1e-8 h_rms). Tolerance: the 1e-10 solve tolerance on rms/max gaps,
    loosened to 1e-8 for max-vs-rms."""
    op, h, kw = problem
    ref = polonsky_keer(op, h, p_init=np.zeros_like(h), **kw)
    p_max = 0.3 * ref.pressure.max()
    if per_pixel:
        p_max = np.full(h.shape, p_max) * (1 + 0.5 * (np.arange(h.size) % 2).reshape(h.shape))
    out = polonsky_keer(op, h, p_init=np.zeros_like(h), constraint=BoundedWall(p_max), **kw)
    p, g, tol = out.pressure, out.gap, 1e-8 * h.std()
    upper = np.broadcast_to(p_max, h.shape)
    assert out.converged
    assert p.min() >= 0 and (p <= upper).all()
    at_bound = p == upper
    free = (p > 0) & ~at_bound
    assert at_bound.sum() > 10  # the bound is active
    assert np.abs(g[free]).max() < tol
    assert g[at_bound].max() < tol
    assert g[p == 0].min() > -tol


def test_bounded_refuses_load_control(problem):
    op, h, kw = problem
    kw = dict(kw, displacement=None)
    with pytest.raises(ValueError, match="displacement control"):
        polonsky_keer(op, h, p_init=np.ones_like(h), load=10.0, constraint=BoundedWall(1.0), **kw)
