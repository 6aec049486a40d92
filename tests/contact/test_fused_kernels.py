"""The fused numba path of the CG (the default) against the numpy reference loop.

Both run the same algorithm (amontons.contact.cg, amontons.contact.fused); they differ in
summation order and in when the displacement is refreshed by a full convolution (the fused
path applies up to ~12-32 changed points as point responses, the numpy one up to 3), so the
iterates agree to round-off, not bit for bit. The converged fields are held to 1e-10 (area
fraction, approach over the rms height), far below the solve tolerance, and the iteration
counts to 5 % (issue 23's bounds): a wrong kernel moves the fixed point by at least the
tolerance or changes the iteration path.
"""

import numba
import numpy as np
import pytest
from threadpoolctl import threadpool_limits

from amontons.contact import kernels as K
from amontons.contact import self_affine, sphere
from amontons.contact.cg import BoundedWall, polonsky_keer
from amontons.contact.convolution import get_operator
from amontons.contact.plasticity import _WinklerOperator


def _pair(op, h, **kw):
    """(numpy reference, fused) outcomes of the same solve."""
    base = {"pixel_area": 1.0, "h_scale": float(h.std()), "tol": 1e-9, "max_iter": 2000}
    base.update(kw)
    with threadpool_limits(limits=1):  # as solve() runs it: no spinning BLAS threads
        ref = polonsky_keer(op, h, kernels=False, **base)
        new = polonsky_keer(op, h, kernels=True, **base)
    return ref, new


def _assert_same_fixed_point(ref, new, h):
    assert ref.converged and new.converged
    area_ref, area_new = np.mean(ref.pressure > 0), np.mean(new.pressure > 0)
    assert abs(area_new - area_ref) <= 1e-10
    assert abs(new.rigid_displacement - ref.rigid_displacement) <= 1e-10 * h.std()
    assert abs(new.iterations - ref.iterations) <= 0.05 * ref.iterations
    # pressure: both are within tol of the same solution
    scale = ref.pressure.max()
    assert np.abs(new.pressure - ref.pressure).max() <= 1e-6 * scale


@pytest.fixture(scope="module")
def rough():
    n = 128
    h = self_affine((n, n), 1.0, 0.8, rms_slope=0.1, rng=3)
    return h, 0.005 * n * n


def test_periodic_load_control_matches_numpy(rough):
    h, load = rough
    op = get_operator(h.shape, 1.0, 1.0, periodic=True)
    ref, new = _pair(op, h, p_init=np.ones_like(h), load=load)
    _assert_same_fixed_point(ref, new, h)


def test_non_periodic_sphere_matches_numpy():
    n = 128
    h = sphere((n, n), 1.0, 4.0 * n) + self_affine((n, n), 1.0, 0.8, rms_height=0.5, rng=1)
    op = get_operator(h.shape, 1.0, 1.0, periodic=False)
    ref, new = _pair(op, h, p_init=np.ones_like(h), load=4 * (n / 5) ** 3 / (3 * 4.0 * n))
    _assert_same_fixed_point(ref, new, h)


def test_displacement_control_matches_numpy(rough):
    h, _ = rough
    op = get_operator(h.shape, 1.0, 1.0, periodic=True)
    ref, new = _pair(op, h, p_init=np.zeros_like(h), displacement=-1.0 * h.std())
    _assert_same_fixed_point(ref, new, h)


@pytest.mark.parametrize("per_pixel", [False, True])
def test_bounded_projection_matches_numpy(rough, per_pixel):
    """The bounded projection and the fall-violators (open points at p_max) of the plastic
    route: p_max at 30 % of the elastic peak so the bound is active."""
    h, _ = rough
    op = get_operator(h.shape, 1.0, 1.0, periodic=True)
    kw = {"p_init": np.zeros_like(h), "displacement": -1.0 * h.std()}
    elastic, _ = _pair(op, h, **kw)
    p_max = 0.3 * elastic.pressure.max()
    if per_pixel:
        p_max = p_max * (1 + 0.5 * (np.arange(h.size) % 2).reshape(h.shape))
    ref, new = _pair(op, h, constraint=BoundedWall(p_max), **kw)
    assert (ref.pressure >= np.broadcast_to(p_max, h.shape)).sum() > 10  # the bound is active
    _assert_same_fixed_point(ref, new, h)


def test_winkler_term_matches_numpy(rough):
    """Contact hardening's elastic-plus-Winkler operator: the fused path adds t/k inside
    step_dots and in the point responses instead of through the wrapper."""
    h, load = rough
    op = get_operator(h.shape, 1.0, 1.0, periodic=True)
    winkler = _WinklerOperator(op, np.full(h.shape, 1.0 / 0.05))
    ref, new = _pair(winkler, h, p_init=np.ones_like(h), load=load)
    _assert_same_fixed_point(ref, new, h)


@pytest.mark.parametrize("case", ["load", "bounded", "winkler"])
def test_kernels_give_the_same_bits_on_one_and_two_threads(case):
    """Sums are taken over fixed chunks (kernels.CHUNK), so the thread count cannot change a
    single bit; a 600² grid has 22 chunks, enough to split across threads. The hard wall
    under load control, the bounded projection and the Winkler term each have their own
    kernel variants."""
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("numba has one thread here")
    n = 600
    h = self_affine((n, n), 1.0, 0.8, rms_slope=0.1, rng=5)
    op = get_operator(h.shape, 1.0, 1.0, periodic=True)
    kw = {"pixel_area": 1.0, "h_scale": float(h.std()), "tol": 1e-30, "max_iter": 15}
    kw.update(raise_on_failure=False, p_init=np.ones_like(h))
    if case == "bounded":
        kw.update(displacement=-1.0 * h.std(), constraint=BoundedWall(0.02))
    else:
        kw.update(load=0.005 * n * n)
    if case == "winkler":
        op = _WinklerOperator(op, np.full(h.shape, 1.0 / 0.05))
    one = polonsky_keer(op, h, threads=1, **kw)
    two = polonsky_keer(op, h, threads=2, **kw)
    assert np.array_equal(one.pressure, two.pressure)
    assert np.array_equal(one.history, two.history)


@pytest.mark.parametrize("periodic", [True, False])
def test_point_responses_equal_the_convolution(periodic):
    """The real-space kernel sweep gives K*c of a few point pressures to round-off (1e-12 of
    the peak), including points next to the wrap-around and a repeated index."""
    n0, n1 = 40, 56
    op = get_operator((n0, n1), 0.5, 2.0, periodic=periodic)
    idx = np.array([0, 57, 1000, n0 * n1 - 1, 57])
    vals = np.array([1.0, -2.0, 0.5, 3.0, 0.25])
    c = np.zeros(n0 * n1)
    np.add.at(c, idx, vals)
    ref = op(c.reshape(n0, n1))
    u = np.zeros((n0, n1))
    K.add_point_responses(u, op.real_space_kernel(), idx, vals)
    assert np.abs(u - ref).max() <= 1e-12 * np.abs(ref).max()


def test_bad_thread_count_is_refused(rough):
    h, load = rough
    op = get_operator(h.shape, 1.0, 1.0, periodic=True)
    with pytest.raises(ValueError, match="threads must be a positive integer, got 0"):
        polonsky_keer(
            op, h, pixel_area=1.0, h_scale=1.0, p_init=np.ones_like(h), load=load, threads=0
        )
