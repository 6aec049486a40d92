"""The bounded constraint 0 <= p <= p_max slotted into the same CG (no plasticity here)."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from amontons.contact.cg import polonsky_keer
from amontons.contact.constraints import BoundedWall, HardWall
from amontons.contact.convolution import get_operator
from amontons.contact.options import CGOptions
from amontons.contact.surfaces import self_affine


def _load_oracle():
    """The numpy reference loop (tests/contact/numpy_oracle.py; tests import by file)."""
    spec = importlib.util.spec_from_file_location(
        "numpy_oracle", Path(__file__).with_name("numpy_oracle.py")
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.numpy_polonsky_keer


numpy_polonsky_keer = _load_oracle()


@pytest.fixture(scope="module")
def problem():
    n = 64
    h = self_affine((n, n), 1.0, 0.8, rms_slope=0.1, rng=2)
    op = get_operator((n, n), 1.0, 1.0, periodic=True)
    kw = {"pixel_area": 1.0, "h_scale": h.std(), "displacement": -1.0 * h.std()}
    return op, h, {"options": CGOptions(tol=1e-10), **kw}


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


def test_numpy_loop_refuses_bounded_load_control(problem):
    """Only the fused loop imposes the load on the free points; the numpy reference would
    rescale the points at the bound through it, so it refuses rather than answer wrongly."""
    op, h, kw = problem
    kw = dict(kw, displacement=None)
    with pytest.raises(ValueError, match="fused loop"):
        numpy_polonsky_keer(
            op, h, p_init=np.ones_like(h), load=10.0, constraint=BoundedWall(1.0), **kw
        )


@pytest.mark.parametrize("per_pixel", [False, True])
def test_bounded_load_control_is_the_displacement_controlled_solution(problem, per_pixel):
    """Load control with 0 <= p <= p_max (p_max 30 % of the elastic peak, so ~40 % of the
    contact sits at the bound): the load is met to round-off (the free points carry what
    the bound points leave, bounded_load.impose_bounded_load), and the displacement-controlled
    bounded solve at the returned approach gives the same field. Both solves run to 1e-10;
    the fields agree to 1e-8 of p_max (the residual is a gap, ~E*·g/Δx in pressure, and the
    approach is itself a solver output), and the bound holds exactly."""
    op, h, kw = problem
    load = 0.005 * h.size  # mean pressure 0.005 E* (E* = 1, unit pixels)
    ref = polonsky_keer(op, h, p_init=np.zeros_like(h), **kw)
    p_max = 0.3 * ref.pressure.max()
    if per_pixel:
        p_max = np.full(h.shape, p_max) * (1 + 0.5 * (np.arange(h.size) % 2).reshape(h.shape))
    kw_load = dict(kw, displacement=None)
    out = polonsky_keer(
        op, h, p_init=np.ones_like(h), load=load, constraint=BoundedWall(p_max), **kw_load
    )
    upper = np.broadcast_to(p_max, h.shape)
    assert out.converged
    assert out.pressure.sum() == pytest.approx(load, rel=1e-12)
    assert out.pressure.min() >= 0 and (out.pressure <= upper).all()
    assert (out.pressure == upper).sum() > 10  # the bound is active
    dc = dict(kw, displacement=out.displacement)
    at_d = polonsky_keer(op, h, p_init=np.zeros_like(h), constraint=BoundedWall(p_max), **dc)
    assert np.abs(at_d.pressure - out.pressure).max() < 1e-8 * upper.max()
