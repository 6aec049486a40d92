"""The fused numba path of the CG (the solver's) against the numpy reference loop.

Both run the same algorithm (amontons.contact.cg, tests/contact/numpy_oracle.py); they differ in
summation order and in when the displacement is refreshed by a full convolution (the fused
path applies up to ~12-32 changed points as point responses, the numpy one up to 3), so the
iterates agree to round-off, not bit for bit. The converged fields are held to 1e-10 (area
fraction, approach over the rms height), far below the solve tolerance, and the iteration
counts to 5 % (issue 23's bounds): a wrong kernel moves the fixed point by at least the
tolerance or changes the iteration path.
"""

import importlib.util
from dataclasses import replace
from pathlib import Path

import numba
import numpy as np
import pytest
from threadpoolctl import threadpool_limits

from amontons.contact import kernels as K
from amontons.contact import self_affine, sphere
from amontons.contact.cg import polonsky_keer
from amontons.contact.constraints import BoundedWall
from amontons.contact.convolution import get_operator
from amontons.contact.options import CGOptions
from amontons.contact.winkler import WinklerOperator


def _load_oracle():
    """The numpy reference loop (tests/contact/numpy_oracle.py; tests import by file)."""
    spec = importlib.util.spec_from_file_location(
        "numpy_oracle", Path(__file__).with_name("numpy_oracle.py")
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.numpy_polonsky_keer


numpy_polonsky_keer = _load_oracle()


def _pair(op, h, **kw):
    """(numpy reference, fused) outcomes of the same solve."""
    options = CGOptions(tol=1e-9, max_iter=2000)
    base = {"pixel_area": 1.0, "h_scale": float(h.std())}
    base.update(kw)
    with threadpool_limits(limits=1):  # as solve() runs it: no spinning BLAS threads
        ref = numpy_polonsky_keer(op, h, options, **base)
        new = polonsky_keer(op, h, options, **base)
    return ref, new


def _assert_same_fixed_point(ref, new, h):
    assert ref.converged and new.converged
    area_ref, area_new = np.mean(ref.pressure > 0), np.mean(new.pressure > 0)
    assert abs(area_new - area_ref) <= 1e-10
    assert abs(new.displacement - ref.displacement) <= 1e-10 * h.std()
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
    winkler = WinklerOperator(op, np.full(h.shape, 1.0 / 0.05))
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
    options = CGOptions(tol=1e-30, max_iter=15, raise_on_failure=False)
    kw = {"pixel_area": 1.0, "h_scale": float(h.std()), "p_init": np.ones_like(h)}
    if case == "bounded":
        kw.update(displacement=-1.0 * h.std(), constraint=BoundedWall(0.02))
    else:
        kw.update(load=0.005 * n * n)
    if case == "winkler":
        op = WinklerOperator(op, np.full(h.shape, 1.0 / 0.05))
    one = polonsky_keer(op, h, replace(options, threads=1), **kw)
    two = polonsky_keer(op, h, replace(options, threads=2), **kw)
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
    with K.kernel_threads(1):
        K.add_point_responses(u, op.real_space_kernel(), idx, vals)
    assert np.abs(u - ref).max() <= 1e-12 * np.abs(ref).max()


def test_bad_thread_count_is_refused(rough):
    h, load = rough
    op = get_operator(h.shape, 1.0, 1.0, periodic=True)
    with pytest.raises(ValueError, match="threads must be a positive integer, got 0"):
        polonsky_keer(
            op,
            h,
            CGOptions(threads=0),
            pixel_area=1.0,
            h_scale=1.0,
            p_init=np.ones_like(h),
            load=load,
        )


@pytest.mark.parametrize(
    ("shape", "periodic", "pruned"),
    [
        ((40, 56), True, None),
        ((41, 57), True, None),
        ((40, 56), False, True),
        ((33, 20), False, False),
    ],
)
def test_convolution_in_halves_is_the_convolution(shape, periodic, pruned):
    """forward + multiply_energy + inverse give the operator's K*t to round-off (1e-14 of the
    peak), and multiply_energy returns Σ t·(K*t) by Parseval to 1e-12 relative: for an even
    and an odd last axis (the Nyquist column is held once or not at all in the
    half-spectrum) and on the Hockney-padded grid, pruned and plain."""
    kw = {} if pruned is None else {"pruned": pruned}
    op = get_operator(shape, 0.5, 2.0, periodic=periodic, **kw)
    t = np.random.default_rng(1).normal(size=shape)
    whole = op(t)
    op.forward(t)
    energy = op.multiply_energy()
    halves = op.inverse(np.empty(shape))
    assert np.abs(halves - whole).max() <= 1e-14 * np.abs(whole).max()
    assert energy == pytest.approx(float(np.sum(t * whole)), rel=1e-12)


class _Whole:
    """An operator that offers only whole convolutions (as a custom one would)."""

    def __init__(self, op):
        self.op = op
        self.periodic = op.periodic

    def __call__(self, x, out=None):
        return self.op(x, out=out)

    def real_space_kernel(self):
        return self.op.real_space_kernel()


@pytest.mark.parametrize("periodic", [True, False])
def test_skipping_the_inverse_keeps_the_iterates(rough, periodic):
    """Taking r = K*t in halves changes which transforms run, not the iterates: the same
    iterations and fields to 1e-10 of the peak as whole convolutions (the step's Σ r t comes
    from the spectrum instead of a real-space sum, so the two paths differ by round-off,
    measured 1.8e-12 on the sphere), and fewer FFT pairs (each iteration that takes u afresh
    skips the inverse of K*t)."""
    if periodic:
        h, load = rough
    else:
        n = 128
        h = sphere((n, n), 1.0, 4.0 * n)
        load = 4 * (n / 5) ** 3 / (3 * 4.0 * n)
    op = get_operator(h.shape, 1.0, 1.0, periodic=periodic)
    options = CGOptions(tol=1e-9, max_iter=2000)
    kw = {"pixel_area": 1.0, "h_scale": float(h.std()), "p_init": np.ones_like(h), "load": load}
    halves = polonsky_keer(op, h, options, **kw)
    whole = polonsky_keer(_Whole(op), h, options, **kw)
    assert halves.iterations == whole.iterations
    scale = whole.pressure.max()
    assert np.abs(halves.pressure - whole.pressure).max() <= 1e-10 * scale
    skipped = halves.info["forward_only_transforms"]
    assert skipped > 0 and whole.info["forward_only_transforms"] == 0
    assert halves.convolutions == pytest.approx(whole.convolutions - 0.5 * skipped)


def test_load_control_direction_has_zero_sum_on_the_free_set():
    """direction with shift = β Σ t_old / nc leaves Σ_Ic t = 0 (to round-off of Σ|t|) when
    the gap has zero mean on Ic and t_old does not sum to zero there (points clipped)."""
    rng = np.random.default_rng(2)
    n = 3 * K.CHUNK + 17
    m = (rng.random(n) < 0.3).astype(np.uint8)
    u, h, p = rng.normal(size=n), rng.normal(size=n), np.ones(n)
    t = rng.normal(size=n) * m + 0.3 * m  # non-zero sum on the free set
    nc = int(m.sum())
    d = float(np.sum((u - h) * m)) / nc  # the approach: zero-mean gap on Ic
    beta = 0.7
    shift = beta * float(t.sum()) / nc
    viol = np.zeros(K.n_chunks(n), dtype=np.int64)
    vidx = np.zeros((K.n_chunks(n), K.SLOTS), dtype=np.int64)
    vg = np.zeros((K.n_chunks(n), K.SLOTS))
    with K.kernel_threads(1):
        K.direction(u, 1.0, h, m, t, d, beta, shift, p, np.full(1, np.inf), False, viol, vidx, vg)
    assert abs(t.sum()) <= 1e-12 * np.abs(t).sum()
    assert not np.any(t[m == 0])


def _step_reference(p, u, t, h, m, sigma, d, tau):
    """The hard-wall step in numpy (docs/models.md §2.2): free points step and clip at 0 and
    leave the free set; constrained ones that penetrate (and the clipped ones) join at
    -tau·g. Stored units: true p = sigma·p."""
    g = sigma * u - h - d
    q = p - tau / sigma * t
    free = m.astype(bool)
    clip = free & (q < 0)
    q[clip] = 0.0
    join = (~free | clip) & (g < 0)
    q[join] = -tau * g[join] / sigma
    m_new = ((free & ~clip) | join).astype(np.uint8)
    return q, m_new, clip, join, g


@pytest.mark.parametrize("record_max", [K.SLOTS, 4, -1])
def test_update_records_few_events_and_counts_many(record_max):
    """update's event paths give the numpy step's pressure, free set and counts: the
    recording one (a chunk's clipped points and the violators direction recorded), the same
    pass when a chunk's events outnumber ``record_max`` (4: two violators recorded, three
    clipped points and the joins found in the step) and the branch-free sweep of a chunk
    whose violators alone outnumber it (-1). The recording one lists exactly the changed
    points and the pressure each event added, and only it says its records are complete."""
    rng = np.random.default_rng(4)
    n = 2 * K.CHUNK + 100
    m = (rng.random(n) < 0.4).astype(np.uint8)
    p = np.where(m == 1, 0.1 + rng.random(n), 0.0)
    t = np.where(m == 1, rng.normal(size=n), 0.0)
    u, h = rng.normal(size=n), rng.normal(size=n)
    sigma, d = 1.3, 0.0
    # constrained points open (g = 1), but two per chunk penetrating (g = -0.5), one among
    # three free points per chunk that the step drives below 0, one in a block of its own
    tau = 1e-3
    h[m == 0] = sigma * u[m == 0] - d - 1.0
    for c in range(K.n_chunks(n)):
        lo = c * K.CHUNK
        free = lo + np.flatnonzero(m[lo : lo + 200])[:3]
        t[free] = p[free] * sigma / tau * 1.5 + 1.0
        fixed = lo + np.flatnonzero(m[lo : lo + 200] == 0)[:1]
        far = lo + 2 * K.SCAN + np.flatnonzero(m[lo + 2 * K.SCAN : lo + 3 * K.SCAN] == 0)[:1]
        fixed = np.concatenate([fixed, far[far < n]])
        h[fixed] = sigma * u[fixed] - d + 0.5
    ref_p, ref_m, clip, join, g = _step_reference(p.copy(), u, t, h, m, sigma, d, tau)
    nch = K.n_chunks(n)
    viol = np.zeros(nch, dtype=np.int64)
    vidx = np.zeros((nch, K.SLOTS), dtype=np.int64)
    vg = np.zeros((nch, K.SLOTS))
    tt = t.copy()
    with K.kernel_threads(1):
        K.direction(u, sigma, h, m, tt, d, 0.0, 0.0, p, np.full(1, np.inf), False, viol, vidx, vg)
    idx = np.zeros((nch, K.SLOTS), dtype=np.int64)
    val = np.zeros((nch, K.SLOTS))
    counts = np.zeros((nch, 2), dtype=np.int64)
    mm, pp, t2 = m.copy(), p.copy(), t.copy()
    with K.kernel_threads(1):
        psum, pen, _, complete = K.update(
            pp, pp, u.copy(), np.zeros(n), t2, h, mm, np.full(1, np.inf), False, sigma, d, tau,
            viol, idx, val, counts, False, False, vidx, vg, record_max,
        )  # fmt: skip
    assert clip.sum() == 3 * nch and join.sum() >= 2 * nch - 1
    assert np.allclose(pp, ref_p, rtol=1e-14, atol=0)
    assert np.array_equal(mm, ref_m)
    assert not np.any(t2[clip])
    assert (counts[:, 0].sum(), counts[:, 1].sum()) == (clip.sum(), join.sum())
    assert psum == pytest.approx(ref_p.sum(), rel=1e-13)
    assert pen == pytest.approx(np.abs(g[join]).max(), rel=1e-15)
    # the records are complete unless a chunk was swept without them
    assert complete == (record_max == K.SLOTS)
    if record_max == K.SLOTS:
        got_idx, got_val = K.changed_points(counts, idx, val)
        step = p - tau / sigma * t
        expect = {int(i): -sigma * step[i] for i in np.flatnonzero(clip)}
        for i in np.flatnonzero(join):
            expect[int(i)] = expect.get(int(i), 0.0) - tau * g[i]
        got = {}
        for i, v in zip(got_idx.tolist(), got_val.tolist(), strict=True):
            got[i] = got.get(i, 0.0) + v
        assert got.keys() == expect.keys()
        assert all(got[i] == pytest.approx(expect[i], rel=1e-12) for i in got)
