"""The array kernel set (amontons.contact.array_kernels) on numpy against the numba set.

The array set is the GPU route's code (``backend="cupy"``) written in array-namespace code;
with ``xp = numpy`` it runs here, without a GPU, and these tests hold its logic to the CPU
path. Only the device execution (CuPy's kernels, cuFFT) is left untested here: the
whole-solve comparisons also run with ``backend="cupy"`` where CuPy finds a CUDA device, and
are skipped elsewhere.

Tolerances, and why:

* element-wise results (masks, counts, the direction, the step, the records' indices):
  exact or 1e-15 relative. Both sets evaluate the same expressions, but the numba set is
  compiled with fast-math, which may contract ``sigma·u - h`` into a fused multiply-add;
* sums: 1e-12 relative to the sum of the magnitudes. The array set sums with numpy's
  pairwise summation, the numba set over fixed chunks in order: the two orders round
  differently by ~n·1e-16 at worst, far less in practice;
* whole solves: the same contact set, pressures within 1e-10 of the peak pressure (the
  issue's target for the GPU route; 1e-7 for the appendix's root find, see REL), approach
  within 1e-10 of the rms height, the same iteration count within 5 %. The solves converge
  to 1e-8 of the residual; the two paths follow the same iterates to round-off, so a wrong
  kernel moves the fixed point by the tolerance or changes the path, far outside these
  bounds.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from amontons.contact import (
    BackendUnavailableError,
    ContactHardening,
    ContactInputError,
    PenetrationHardness,
    self_affine,
    solve,
    solve_load_series,
    sphere,
)
from amontons.contact import kernels as K
from amontons.contact.array_backends import NUMPY, NUMPY_ARRAY, array_module, numpy_fft_pair
from amontons.contact.array_convolution import ArrayConvolution
from amontons.contact.array_kernels import ArrayKernels
from amontons.contact.cg import polonsky_keer
from amontons.contact.constraints import BoundedWall
from amontons.contact.convolution import fast_padded_shape, get_operator
from amontons.contact.options import CGOptions

A = ArrayKernels(NUMPY)
SUM_RTOL = 1e-12
ELEMENT_RTOL = 1e-15
# several numba chunks, the last one partial
N = 2 * K.CHUNK + 1234
HAVE_CUPY = importlib.util.find_spec("cupy") is not None


@pytest.fixture(autouse=True)
def _numba_kernels_from_the_cache():
    """The numba kernels called directly run from numba's disk cache, as in every solve
    (kernels.kernel_threads; a cold cache is compiled in a child first). Compiled in this
    process instead, they would round otherwise than the cached ones for every later test of
    the session (tests/contact/test_kernel_cache.py)."""
    with K.kernel_threads(1):
        yield


def _device() -> bool:
    """Whether backend="cupy" can run here (CuPy and a CUDA device)."""
    try:
        array_module("cupy")
    except BackendUnavailableError:
        return False
    return True


# The whole-solve comparisons run on numpy here and, where a GPU is, on CuPy too: the device
# check a session with a GPU runs (benchmarks/README.md, "The GPU route").
BACKENDS = [
    NUMPY_ARRAY,
    pytest.param(
        "cupy", marks=pytest.mark.skipif(not _device(), reason="no CuPy or no CUDA device")
    ),
    # the array code on the GPU, without the CUDA kernels (the benchmarks' baseline)
    pytest.param(
        "cupy-array",
        marks=pytest.mark.skipif(not _device(), reason="no CuPy or no CUDA device"),
    ),
    # the CUDA kernels that write their terms, summed by CuPy (the reducing kernels' baseline)
    pytest.param(
        "cupy-terms",
        marks=pytest.mark.skipif(not _device(), reason="no CuPy or no CUDA device"),
    ),
]


def _close_sum(got, want, magnitude):
    assert abs(got - want) <= SUM_RTOL * magnitude, (got, want)


def _load_cases():
    """tests/contact/kernel_cases.py (tests import helpers by file)."""
    spec = importlib.util.spec_from_file_location(
        "kernel_cases", Path(__file__).with_name("kernel_cases.py")
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


kernel_cases = _load_cases()


@pytest.fixture
def state():
    """A CG state with a free set of ~60 %, a direction, ``r``, bounds."""
    return kernel_cases.cg_state(np.random.default_rng(5), N)


def test_free_mask(state):
    for bounded in (False, True):
        p_max = state["p_max"] if bounded else np.full(1, np.inf)
        m_num, m_arr = np.empty(N, np.uint8), np.empty(N, np.uint8)
        assert K.free_mask(state["p"], m_num, p_max, bounded) == A.free_mask(
            state["p"], m_arr, p_max, bounded
        )
        assert np.array_equal(m_num, m_arr)


def test_gap_moments(state):
    s = state
    args = (s["u"], 1.3, s["h"], s["m"], s["t"], 0.2)
    got, want = A.gap_moments(*args), K.gap_moments(*args)
    a = np.abs((1.3 * s["u"] - s["h"] - 0.2) * s["m"])
    for g, w, mag in zip(
        got,
        want,
        (a.sum(), (a * a).sum(), (a * np.abs(s["t"])).sum(), np.abs(s["t"]).sum()),
        strict=True,
    ):
        _close_sum(g, w, mag)


def _violator_records(ks, nch):
    """``(vidx, vg)`` of a kernel set's direction."""
    return np.zeros((nch, ks.SLOTS), np.int64), np.zeros((nch, ks.SLOTS))


@pytest.mark.parametrize("bounded", [False, True])
def test_direction(state, bounded):
    s = state
    p_max = s["p_max"] if bounded else np.full(1, np.inf)
    t_num, t_arr = s["t"].copy(), s["t"].copy()
    nch = K.n_chunks(N)
    v_num, v_arr = np.zeros(nch, np.int64), np.zeros(1, np.int64)
    head = (s["u"], 1.1, s["h"], s["m"])
    tail = (0.1, 0.7, 0.05, s["p"], p_max, bounded)
    got = A.direction(*head, t_arr, *tail, v_arr, *_violator_records(A, 1))
    want = K.direction(*head, t_num, *tail, v_num, *_violator_records(K, nch))
    np.testing.assert_allclose(t_arr, t_num, rtol=ELEMENT_RTOL, atol=1e-15)
    _close_sum(float(got), want, np.abs(t_num).sum())
    # the violator count (the numba set keeps a chunk's count when it exceeds SLOTS)
    g = 1.1 * s["u"] - s["h"] - 0.1
    q = 1.1 * s["p"]
    ub = p_max if bounded else np.inf
    join = (s["m"] == 0) & (((q <= 0) & (g < 0) & (q < ub)) | ((q >= ub) & (g > 0) & (q > 0)))
    assert v_arr[0] == join.sum() == v_num.sum()


@pytest.mark.parametrize("winkler", [False, True])
def test_step_dots(state, winkler):
    s = state
    comp = np.abs(s["h"]) if winkler else np.zeros(1)
    r_num, r_arr = s["r"].copy(), s["r"].copy()
    got = A.step_dots(r_arr, s["t"], s["m"], comp, winkler)
    want = K.step_dots(r_num, s["t"], s["m"], comp, winkler)
    np.testing.assert_allclose(r_arr, r_num, rtol=ELEMENT_RTOL)
    mag = np.abs(r_num).sum() * (1 + np.abs(s["t"]).max())
    _close_sum(got[0], want[0], mag)
    _close_sum(got[1], want[1], mag)


def _records(counts, idx, val):
    per = counts.sum(axis=1)
    pairs = [
        (int(i), float(v))
        for c in np.flatnonzero(per)
        for i, v in zip(idx[c, : per[c]], val[c, : per[c]], strict=True)
    ]
    return sorted(pairs)


@pytest.mark.parametrize("bounded", [False, True])
@pytest.mark.parametrize("events", [0, 4, 200])
@pytest.mark.parametrize(("keep_mask", "with_u"), [(False, False), (False, True), (True, True)])
def test_update(bounded, events, keep_mask, with_u):
    rng = np.random.default_rng(events + 10 * bounded)
    case = kernel_cases.update_case(rng, N, bounded, events)
    sigma, d, tau, record_max = 1.2, 0.1, 0.3, 32
    results = {}
    for name, ks in (("numba", K), ("array", A)):
        c = {k: v.copy() for k, v in case.items()}
        nch = ks.n_chunks(N)
        if ks is K:
            viol = np.zeros(nch, np.int64)
            vidx, vg = _violator_records(K, nch)
            K.direction(
                c["u"],
                sigma,
                c["h"],
                c["m"],
                c["t"],
                d,
                0.0,
                0.0,
                c["p"],
                c["p_max"],
                bounded,
                viol,
                vidx,
                vg,
            )
            c["t"] = case["t"].copy()  # the direction above only recorded the violators
        else:
            viol, vidx, vg = np.zeros(1, np.int64), None, None
        idx, val = np.zeros((nch, ks.SLOTS), np.int64), np.zeros((nch, ks.SLOTS))
        counts = np.zeros((nch, 2), np.int64)
        p_new = c["p"] if not keep_mask else np.empty(N)
        fields = [c[k] for k in ("u", "r", "t", "h", "m", "p_max")]
        step = (bounded, sigma, d, tau)
        records = (viol, idx, val, counts, keep_mask, with_u, vidx, vg, record_max)
        out = ks.update(c["p"], p_new, *fields, *step, *records)
        results[name] = (out, c, p_new, ks.event_counts(counts), _records(counts, idx, val))
    (o_n, c_n, p_n, k_n, r_n), (o_a, c_a, p_a, k_a, r_a) = results["numba"], results["array"]
    assert k_n == k_a  # (clipped, added)
    if events:
        assert sum(k_n) >= 2 * events * 0.9  # the case made the events it was meant to
    np.testing.assert_allclose(p_a, p_n, rtol=ELEMENT_RTOL, atol=0)
    assert np.array_equal(c_a["m"], c_n["m"]) and np.array_equal(c_a["t"], c_n["t"])
    np.testing.assert_allclose(c_a["u"], c_n["u"], rtol=ELEMENT_RTOL)
    _close_sum(o_a[0], o_n[0], np.abs(p_n).sum())
    assert o_a[1] == pytest.approx(o_n[1], rel=ELEMENT_RTOL)
    _close_sum(o_a[2], o_n[2], np.abs(p_n).sum())
    assert o_a[3] == o_n[3]
    if o_n[3] and sum(k_n):
        assert [i for i, _ in r_a] == [i for i, _ in r_n]
        np.testing.assert_allclose([v for _, v in r_a], [v for _, v in r_n], rtol=1e-14)


def test_rescale_free():
    rng = np.random.default_rng(2)
    p = np.where(rng.random(N) < 0.5, rng.random(N), 0.0)
    p_max = np.full(N, 0.95)
    p[:5] = 0.95
    m_old = ((p > 0) & (p < p_max)).astype(np.uint8)
    t, u, v = rng.normal(size=N) * m_old, rng.normal(size=N), rng.normal(size=N)
    for s, with_u in ((1.02, True), (1.3, False)):
        out = {}
        for name, ks in (("numba", K), ("array", A)):
            c = [x.copy() for x in (p, u, t)]
            m_new = np.empty(N, np.uint8)
            nch = ks.n_chunks(N)
            idx, val = np.zeros((nch, ks.SLOTS), np.int64), np.zeros((nch, ks.SLOTS))
            counts = np.zeros((nch, 2), np.int64)
            res = ks.rescale_free(
                c[0], c[1], v, m_old, m_new, c[2], p_max, s, with_u, idx, val, counts
            )
            out[name] = (res, c, m_new, int(counts.sum()), _records(counts, idx, val))
        (rn, cn, mn, kn, recn), (ra, ca, ma, ka, reca) = out["numba"], out["array"]
        assert kn == ka and rn[2:] == ra[2:] and np.array_equal(mn, ma)
        for x, y in zip(ca, cn, strict=True):
            np.testing.assert_allclose(x, y, rtol=ELEMENT_RTOL)
        _close_sum(ra[0], rn[0], p.sum() * s)
        _close_sum(ra[1], rn[1], p.sum() * s)
        if kn <= A.SLOTS:
            assert [i for i, _ in reca] == [i for i, _ in recn]


def test_relative_change_worst_violation_subtract_scaled(state):
    s = state
    q = s["p"] * 1.01
    got, want = A.relative_change(q, 0.9, s["p"], 1.1), K.relative_change(q, 0.9, s["p"], 1.1)
    for g, w in zip(got, want, strict=True):
        _close_sum(g, w, 2 * s["p"].sum())
    for bounded in (False, True):
        p_max = s["p_max"] if bounded else np.full(1, np.inf)
        args = (s["p"], s["u"], s["h"], 0.3, s["m"], p_max, bounded)
        assert A.worst_violation(*args) == pytest.approx(K.worst_violation(*args), rel=ELEMENT_RTOL)
    u_a, u_n = s["u"].copy(), s["u"].copy()
    A.subtract_scaled(u_a, s["r"], 0.7)
    K.subtract_scaled(u_n, s["r"], 0.7)
    np.testing.assert_allclose(u_a, u_n, rtol=ELEMENT_RTOL)


@pytest.mark.parametrize("shape", [(48, 40), (47, 39)])
@pytest.mark.parametrize("periodic", [True, False])
def test_planned_transforms_give_the_operator(periodic, shape):
    """The operator through planned transforms (the path CuPy's cuFFT plans take; here
    numpy.fft's) against the CPU operator, into a given ``out``, a new array and a strided
    one, twice (the padded buffers are reused), on even and odd sides. Tolerance 1e-13 of
    the peak: transforms of 2e3 points in another association and the normalisation folded
    into the spectrum."""
    spacing, e_star = 0.5, 2.0
    rng = np.random.default_rng(2)
    padded = None if periodic else fast_padded_shape(shape)
    op = ArrayConvolution(shape, spacing, e_star, np, padded, numpy_fft_pair)
    ref = get_operator(shape, spacing, e_star, periodic=periodic)
    for _ in range(2):
        p = rng.random(shape)
        want = ref(p)
        atol = 1e-13 * np.abs(want).max()
        out = np.empty(shape)
        assert op(p, out=out) is out
        np.testing.assert_allclose(out, want, rtol=0, atol=atol)
        np.testing.assert_allclose(op(p), want, rtol=0, atol=atol)
        strided = np.empty((shape[0], 2 * shape[1]))[:, ::2]
        op(p, out=strided)
        np.testing.assert_allclose(strided, want, rtol=0, atol=atol)


@pytest.mark.parametrize("periodic", [True, False])
def test_point_responses_and_operator(periodic):
    """The array operator against the CPU one, and point responses on its real-space kernel
    against the numba kernel's."""
    shape, spacing, e_star = (48, 40), 0.5, 2.0
    rng = np.random.default_rng(1)
    p = rng.random(shape)
    padded = None if periodic else fast_padded_shape(shape)
    op = ArrayConvolution(shape, spacing, e_star, np, padded)
    ref = get_operator(shape, spacing, e_star, periodic=periodic)
    want = ref(p)
    np.testing.assert_allclose(op(p), want, rtol=0, atol=1e-13 * np.abs(want).max())
    green = op.real_space_kernel()
    np.testing.assert_allclose(
        green, ref.real_space_kernel(), rtol=0, atol=1e-15 * np.abs(green).max()
    )
    idx = np.array([0, 5, 47 * 40 + 39, 5, 1000])
    vals = rng.normal(size=idx.size)
    u_a, u_n = p.copy(), p.copy()
    A.add_point_responses(u_a, green, idx, vals)
    K.add_point_responses(u_n, green, idx, vals)
    np.testing.assert_allclose(u_a, u_n, rtol=0, atol=1e-14 * np.abs(u_n).max())
    assert not np.allclose(u_a, p)  # the points did add something


# -- whole solves, the array set on numpy against the CPU path --

SPACING, E_STAR = 1.0, 1.0


def _rough(n, rng=3):
    return self_affine((n, n), SPACING, 0.8, rms_slope=0.1, rng=rng)


def _sphere(n):
    return sphere((n, n), SPACING, 4.0 * n) + self_affine(
        (n, n), SPACING, 0.8, rms_height=0.3, rng=1
    )


def _assert_agree(cpu, arr, h, backend, rel=1e-10):
    assert cpu.converged and arr.converged
    assert np.array_equal(cpu.pressure > 0, arr.pressure > 0), "contact sets differ"
    scale = np.abs(cpu.pressure).max()
    assert np.abs(arr.pressure - cpu.pressure).max() <= rel * scale
    assert abs(arr.displacement - cpu.displacement) <= rel * float(np.std(h))
    assert abs(arr.iterations - cpu.iterations) <= max(1, 0.05 * cpu.iterations)
    if cpu.plastic_displacement is not None and np.abs(cpu.plastic_displacement).max() > 0:
        plastic = np.abs(cpu.plastic_displacement).max()
        assert np.abs(arr.plastic_displacement - cpu.plastic_displacement).max() <= rel * plastic
    assert isinstance(arr.pressure, np.ndarray) and isinstance(arr.gap, np.ndarray)
    assert arr.info.backend == backend


CASES = {
    # name: (heights, solve keywords)
    "periodic, load": (lambda: _rough(128), {"periodic": True, "load": 0.005 * 128**2}),
    "periodic 256², load": (lambda: _rough(256, 4), {"periodic": True, "load": 0.005 * 256**2}),
    "periodic, displacement": (
        lambda: _rough(128),
        # the highest peaks pressed in by half the rms height (larger heights are closer)
        {
            "periodic": True,
            "displacement": 0.5 * float(_rough(128).std()) - float(_rough(128).max()),
        },
    ),
    "padded, load": (lambda: _sphere(128), {"periodic": False, "load": 40.0}),
    "padded, displacement": (
        lambda: _sphere(128),
        {"periodic": False, "displacement": 1.0 - float(_sphere(128).max())},
    ),
    "penetration hardness, load": (
        lambda: _sphere(128),
        {"periodic": False, "load": 40.0, "plasticity": PenetrationHardness(p_y=0.08)},
    ),
    "penetration hardness, displacement": (
        lambda: _sphere(128),
        {
            "periodic": False,
            "displacement": 1.0 - float(_sphere(128).max()),
            "plasticity": PenetrationHardness(p_y=0.08),
        },
    ),
    "penetration hardness, periodic load": (
        lambda: _rough(128),
        {"periodic": True, "load": 0.005 * 128**2, "plasticity": PenetrationHardness(p_y=0.05)},
    ),
    "penetration hardness (appendix)": (
        lambda: _sphere(96),
        {
            "periodic": False,
            "load": 20.0,
            "plasticity": PenetrationHardness(p_y=0.08),
            "method": "appendix",
        },
    ),
    "hardening (winkler)": (
        lambda: _sphere(128),
        {"periodic": False, "load": 40.0, "plasticity": ContactHardening(k=0.5)},
    ),
}


# The appendix's scheme ends its root find on the approach at its own tolerance, which turns
# the inner solves' round-off into differences of ~1e-9 to 1e-8 of the peak pressure: the CPU
# path's two FFT backends (pyfftw, numpy) differ by 2e-9 on this case, the array set by 4e-8.
# Its inner solves (the bounded displacement-controlled CG) are held to 1e-10 above.
REL = {"penetration hardness (appendix)": 1e-7}


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", sorted(CASES))
def test_solve_agrees_with_the_cpu_path(name, backend):
    make, kw = CASES[name]
    h = make()
    cpu = solve(h, SPACING, E_STAR, **kw)
    arr = solve(h, SPACING, E_STAR, backend=backend, **kw)
    _assert_agree(cpu, arr, h, backend, rel=REL.get(name, 1e-10))


def test_bounded_load_numpy_step_agrees():
    """Bounded load control's numpy step (bounded_load_sweep=False), which the array set runs
    through on_host, against the CPU path's."""
    h = _sphere(96)
    kw = {"pixel_area": 1.0, "h_scale": float(h.std()), "p_init": np.ones_like(h), "load": 20.0}
    constraint = BoundedWall(np.full(h.shape, 0.08))
    outs = []
    for module, op in (
        (None, get_operator(h.shape, SPACING, E_STAR, periodic=False)),
        (NUMPY_ARRAY, ArrayConvolution(h.shape, SPACING, E_STAR, np, fast_padded_shape(h.shape))),
    ):
        options = CGOptions(tol=1e-8, max_iter=3000, bounded_load_sweep=False, array_module=module)
        outs.append(polonsky_keer(op, h, options, constraint=constraint, **kw))
    _assert_agree_outcome(*outs, h)


def _assert_agree_outcome(cpu, arr, h):
    assert cpu.status == arr.status == 0
    assert np.array_equal(cpu.pressure > 0, arr.pressure > 0)
    assert np.abs(arr.pressure - cpu.pressure).max() <= 1e-10 * cpu.pressure.max()
    assert abs(arr.displacement - cpu.displacement) <= 1e-10 * float(np.std(h))


@pytest.mark.parametrize("backend", BACKENDS)
def test_load_series_agrees(backend):
    h = _sphere(96)
    loads = [10.0, 20.0, 40.0]
    law = ContactHardening(k=0.5)
    cpu = solve_load_series(h, SPACING, E_STAR, loads, plasticity=law)
    arr = solve_load_series(h, SPACING, E_STAR, loads, plasticity=law, backend=backend)
    for c, a in zip(cpu, arr, strict=True):
        _assert_agree(c, a, h, backend)


# -- backend="cupy" without CuPy --


@pytest.mark.skipif(HAVE_CUPY, reason="CuPy is installed: the error path is not reachable")
def test_cupy_array_backend_without_cupy_names_the_install():
    with pytest.raises(BackendUnavailableError, match=r"amontons\[gpu\]"):
        solve(_rough(32), SPACING, E_STAR, load=1.0, periodic=True, backend="cupy-array")


@pytest.mark.skipif(HAVE_CUPY, reason="CuPy is installed: the error path is not reachable")
def test_cupy_backend_without_cupy_names_the_backend_and_the_install():
    h = _rough(32)
    with pytest.raises(BackendUnavailableError, match=r"backend='cupy'.*amontons\[gpu\]"):
        solve(h, SPACING, E_STAR, load=1.0, periodic=True, backend="cupy")
    with pytest.raises(BackendUnavailableError, match="backend='cupy'"):
        solve_load_series(h, SPACING, E_STAR, [1.0, 2.0], periodic=True, backend="cupy")
    with pytest.raises(BackendUnavailableError, match="backend='cupy'"):
        array_module("cupy")
    options = CGOptions(array_module="cupy")
    op = get_operator(h.shape, SPACING, E_STAR, periodic=True)
    with pytest.raises(BackendUnavailableError, match="pip install"):
        polonsky_keer(op, h, options, pixel_area=1.0, h_scale=1.0, p_init=np.ones_like(h), load=1.0)


def test_an_unknown_backend_is_an_input_error():
    with pytest.raises(ContactInputError, match="'cupy'"):
        solve(_rough(32), SPACING, E_STAR, load=1.0, periodic=True, backend="cuda")
