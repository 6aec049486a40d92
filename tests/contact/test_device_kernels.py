"""The GPU kernel set's CUDA kernels (amontons.contact.device_sources, run by
``DeviceKernels`` and ``ReducingKernels`` on CuPy) against the array code they replace
(``ArrayKernels``).

Without a GPU the sources are compiled as C++ (tests/contact/cuda_harness.py) and called on
numpy arrays as CuPy calls them, so the kernels' arithmetic and ``DeviceKernels``' glue (the
arguments, the flags, the records) run here; only nvcc's code generation and the device's
reductions are left to a machine with a GPU (tests/contact/test_array_kernels.py runs the
whole solves there with ``backend="cupy"``).

Tolerance: none, everything is compared to the last bit. The sources evaluate the array
code's expressions in its association, the harness compiles them without fused
multiply-adds (``-ffp-contract=off``), and ``DeviceKernels`` sums the terms the kernels write
with the same numpy reductions the array code applies to its temporaries: so the element-
wise results, the sums and whole solves (every iterate) are the same bytes, and any
difference is a changed expression. (On a GPU, nvcc's multiply-adds and CuPy's reductions
make them agree to round-off instead: tests/contact/test_array_kernels.py holds the device's
whole solves to the CPU path within 1e-10 of the peak pressure.) The reducing kernels'
sums, folded block by block, are held to round-off instead (their section below).
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from amontons.contact import self_affine, sphere
from amontons.contact.array_backends import NUMPY
from amontons.contact.array_convolution import ArrayConvolution
from amontons.contact.array_kernels import (
    ArrayKernels,
    DeviceKernels,
    ReducingKernels,
    fold_partials,
)
from amontons.contact.cg import run_to_outcome
from amontons.contact.cg_iteration import CGIteration
from amontons.contact.constraints import BoundedWall, HardWall
from amontons.contact.convolution import fast_padded_shape
from amontons.contact.device_sources import (
    REDUCE_BLOCK,
    REDUCE_MAX_BLOCKS,
    REDUCING_STEP,
    reduce_blocks,
)
from amontons.contact.options import CGOptions


def _load(name):
    """tests/contact/<name>.py (tests import helpers by file)."""
    spec = importlib.util.spec_from_file_location(name, Path(__file__).with_name(f"{name}.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


harness, kernel_cases = _load("cuda_harness"), _load("kernel_cases")
COMPILER, harness_module = harness.COMPILER, harness.harness_module
pytestmark = pytest.mark.skipif(COMPILER is None, reason="no C++ compiler (g++) here")

N = 50_000
A = ArrayKernels(NUMPY)


@pytest.fixture(scope="module")
def device():
    return DeviceKernels(harness_module())


def _state():
    """A CG state (tests/contact/kernel_cases.py) with constrained points whose sigma·p
    (sigma 1.1 in test_direction) is at the bound 0.9: the violator test's second clause."""
    return kernel_cases.cg_state(np.random.default_rng(5), N, at_bound=0.9 / 1.1)


def test_gap_moments(device):
    s = _state()
    args = (s["u"], 1.3, s["h"], s["m"], s["t"], 0.2)
    assert device.gap_moments(*args) == A.gap_moments(*args)


@pytest.mark.parametrize("bounded", [False, True])
def test_direction(device, bounded):
    s = _state()
    p_max = s["p_max"] if bounded else np.full(1, np.inf)
    out = {}
    for name, ks in (("device", device), ("array", A)):
        t, violators = s["t"].copy(), np.zeros(1, np.int64)
        total = ks.direction(
            s["u"], 1.1, s["h"], s["m"], t, 0.1, 0.7, 0.05, s["p"], p_max, bounded, violators,
            None, None,
        )  # fmt: skip
        out[name] = (t, int(violators[0]), float(total))
    assert np.array_equal(out["device"][0], out["array"][0])
    assert out["device"][1:] == out["array"][1:] and out["array"][1] > 0


@pytest.mark.parametrize("winkler", [False, True])
def test_step_dots(device, winkler):
    s = _state()
    comp = np.abs(s["h"]) if winkler else np.zeros(1)
    r_dev, r_arr = s["r"].copy(), s["r"].copy()
    got = device.step_dots(r_dev, s["t"], s["m"], comp, winkler)
    want = A.step_dots(r_arr, s["t"], s["m"], comp, winkler)
    assert np.array_equal(r_dev, r_arr) and got == want


@pytest.mark.parametrize("sigma", [1.2, 1.0])
@pytest.mark.parametrize("bounded", [False, True])
@pytest.mark.parametrize("events", [0, 4, 200])
@pytest.mark.parametrize(("keep_mask", "with_u"), [(False, False), (False, True), (True, True)])
def test_update(device, sigma, bounded, events, keep_mask, with_u):
    """At sigma 1 the points clipped at the bound, closed, stay on it, so the share at the
    bound (the third result, which bounded load control reads) is not nil."""
    rng = np.random.default_rng(events + 10 * bounded)
    case = kernel_cases.update_case(rng, N, bounded, events, closed=sigma == 1.0)
    out = {}
    for name, ks in (("device", device), ("array", A)):
        c = {k: v.copy() for k, v in case.items()}
        idx, val = np.zeros((1, ks.SLOTS), np.int64), np.zeros((1, ks.SLOTS))
        counts = np.zeros((1, 2), np.int64)
        p_new = c["p"] if not keep_mask else np.empty(N)
        fields = [c[k] for k in ("u", "r", "t", "h", "m", "p_max")]
        records = (np.zeros(1, np.int64), idx, val, counts, keep_mask, with_u, None, None, 32)
        result = ks.update(c["p"], p_new, *fields, bounded, sigma, 0.1, 0.3, *records)
        out[name] = (result, c, p_new, ks.event_counts(counts), idx, val)
    (o_d, c_d, p_d, k_d, i_d, v_d), (o_a, c_a, p_a, k_a, i_a, v_a) = out["device"], out["array"]
    assert k_d == k_a
    if events:
        assert sum(k_a) >= 2 * events * 0.9  # the case made the events it was meant to
    assert np.array_equal(p_d, p_a)
    for field in ("m", "t", "u", "p"):
        assert np.array_equal(c_d[field], c_a[field]), field
    assert o_d == o_a
    if bounded and events and sigma == 1.0:
        assert o_a[2] > 0  # points at the bound
    if o_a[3]:
        k = sum(k_a)
        assert np.array_equal(i_d[0, :k], i_a[0, :k]) and np.array_equal(v_d[0, :k], v_a[0, :k])


def _rough(n):
    return self_affine((n, n), 1.0, 0.8, rms_slope=0.1, rng=3)


def _sphere(n):
    return sphere((n, n), 1.0, 4.0 * n) + self_affine((n, n), 1.0, 0.8, rms_height=0.3, rng=4)


SOLVES = {
    "periodic, load": (lambda: _rough(96), True, {"load": 0.005 * 96**2}, None),
    "padded, load": (lambda: _sphere(96), False, {"load": 20.0}, None),
    "padded, displacement, bounded": (
        lambda: _sphere(96),
        False,
        {"displacement": 1.0 - float(_sphere(96).max())},
        0.08,
    ),
    # bounded load control: the fused bounded load step (.bounded_load), which reads
    # update's share at the bound
    "padded, load, bounded": (lambda: _sphere(96), False, {"load": 20.0}, 0.08),
}


@pytest.mark.parametrize("name", sorted(SOLVES))
def test_whole_solve_agrees_with_the_array_code(device, name):
    make, periodic, control, p_y = SOLVES[name]
    h = make()
    padded = None if periodic else fast_padded_shape(h.shape)
    op = ArrayConvolution(h.shape, 1.0, 1.0, np, padded)
    constraint = HardWall() if p_y is None else BoundedWall(np.full(h.shape, p_y))
    options = CGOptions(tol=1e-8, max_iter=3000)
    outs = [
        run_to_outcome(
            CGIteration(
                ks,
                op,
                h,
                options,
                pixel_area=1.0,
                h_scale=float(h.std()),
                p_init=np.ones_like(h),
                constraint=constraint,
                load=control.get("load"),
                displacement=control.get("displacement"),
            )
        )
        for ks in (device, A)
    ]
    dev, arr = outs
    assert dev.status == arr.status == 0
    assert dev.iterations == arr.iterations
    assert np.array_equal(dev.pressure, arr.pressure)
    if p_y is not None:
        assert np.any(arr.pressure >= p_y * (1 - 1e-12))  # the bound is reached somewhere


# -- the reducing kernels (ReducingKernels, the set backend="cupy" runs) --
#
# Their element-wise results are the same expressions as the array code's: compared to the
# last bit. Their sums fold each thread's points, then each block's tree, then the blocks,
# where numpy sums pairwise: they agree to round-off, SUM_RTOL of the sum of the magnitudes
# (a sum of N = 5e4 terms in another order differs by at most ~N·eps of it; pairwise and
# blocked orders stay near log2(N)·eps ~ 4e-15). Counts and maxima are exact.
SUM_RTOL = 1e-13


@pytest.fixture(scope="module")
def reducing():
    return ReducingKernels(harness_module())


def _close(got, want, magnitude):
    assert abs(got - want) <= SUM_RTOL * magnitude, (got, want, magnitude)


def test_reducing_gap_moments(reducing):
    s = _state()
    args = (s["u"], 1.3, s["h"], s["m"], s["t"], 0.2)
    a = np.abs((1.3 * s["u"] - s["h"] - 0.2) * s["m"])
    scales = (a.sum(), (a * a).sum(), (a * np.abs(s["t"])).sum(), np.abs(s["t"]).sum())
    for got, want, scale in zip(
        reducing.gap_moments(*args), A.gap_moments(*args), scales, strict=True
    ):
        _close(got, want, scale)


@pytest.mark.parametrize("bounded", [False, True])
def test_reducing_direction(reducing, bounded):
    s = _state()
    p_max = s["p_max"] if bounded else np.full(1, np.inf)
    out = {}
    for name, ks in (("reducing", reducing), ("array", A)):
        t, violators = s["t"].copy(), np.zeros(1, np.int64)
        total = ks.direction(
            s["u"], 1.1, s["h"], s["m"], t, 0.1, 0.7, 0.05, s["p"], p_max, bounded, violators,
            None, None,
        )  # fmt: skip
        out[name] = (t, int(violators[0]), float(total))
    assert np.array_equal(out["reducing"][0], out["array"][0])
    assert out["reducing"][1] == out["array"][1] > 0
    _close(out["reducing"][2], out["array"][2], np.abs(out["array"][0]).sum())


def test_reducing_step_dots(reducing):
    s = _state()
    got = reducing.step_dots(s["r"].copy(), s["t"], s["m"], np.zeros(1), False)
    want = A.step_dots(s["r"].copy(), s["t"], s["m"], np.zeros(1), False)
    _close(got[0], want[0], np.abs(s["r"] * s["t"]).sum())
    _close(got[1], want[1], np.abs(s["r"] * s["m"]).sum())


def test_reducing_relative_change(reducing):
    s = _state()
    p_new = s["p"] * 1.01 + 0.001
    got = reducing.relative_change(p_new, 1.2, s["p"], 1.1)
    want = A.relative_change(p_new, 1.2, s["p"], 1.1)
    for g, w in zip(got, want, strict=True):
        _close(g, w, abs(w))


@pytest.mark.parametrize("bounded", [False, True])
@pytest.mark.parametrize("events", [0, 4, 200])
@pytest.mark.parametrize(("keep_mask", "with_u"), [(False, True), (True, True)])
def test_reducing_update(reducing, bounded, events, keep_mask, with_u):
    """The step's fields to the last bit, its counts and records exact, its sums to
    round-off; the counts reach event_counts and changed_points without a transfer."""
    rng = np.random.default_rng(events + 10 * bounded)
    case = kernel_cases.update_case(rng, N, bounded, events, closed=True)
    out = {}
    for name, ks in (("reducing", reducing), ("array", A)):
        c = {k: v.copy() for k, v in case.items()}
        idx, val = np.zeros((1, ks.SLOTS), np.int64), np.zeros((1, ks.SLOTS))
        counts = np.zeros((1, 2), np.int64)
        p_new = c["p"] if not keep_mask else np.empty(N)
        fields = [c[k] for k in ("u", "r", "t", "h", "m", "p_max")]
        records = (np.zeros(1, np.int64), idx, val, counts, keep_mask, with_u, None, None, 32)
        result = ks.update(c["p"], p_new, *fields, bounded, 1.0, 0.1, 0.3, *records)
        changed = [a.copy() for a in ks.changed_points(counts, idx, val)]
        out[name] = (result, c, p_new, ks.event_counts(counts), counts.copy(), changed)
    (o_r, c_r, p_r, k_r, n_r, ch_r), (o_a, c_a, p_a, k_a, n_a, ch_a) = out.values()
    assert k_r == k_a and np.array_equal(n_r, n_a)
    if events:
        assert sum(k_a) >= 2 * events * 0.9  # the case made the events it was meant to
    assert np.array_equal(p_r, p_a)
    for field in ("m", "t", "u", "p"):
        assert np.array_equal(c_r[field], c_a[field]), field
    _close(o_r[0], o_a[0], np.abs(p_a).sum())
    assert o_r[1] == o_a[1]  # the worst penetration: a maximum
    _close(o_r[2], o_a[2], np.abs(p_a).sum())
    assert o_r[3] == o_a[3]
    if bounded and events:
        assert o_a[2] > 0  # points at the bound
    if o_a[3]:
        assert all(np.array_equal(x, y) for x, y in zip(ch_r, ch_a, strict=True))


def _launch_order_partials(x: np.ndarray, blocks: int) -> np.ndarray:
    """The per-block sums of ``x`` in a CUDA launch's order, emulated in numpy: thread g =
    b·B + tid folds x[g], x[g + G], ... (G = blocks·B) one after the other, then each
    block's tree adds slot tid + s into slot tid, s = B/2, ..., 1."""
    width = blocks * REDUCE_BLOCK
    rows = -(-x.size // width)
    padded = np.zeros(rows * width)  # + 0.0 changes no sum
    padded[: x.size] = x
    acc = np.zeros(width)
    for row in padded.reshape(rows, width):
        acc = acc + row
    tree = acc.reshape(blocks, REDUCE_BLOCK)
    s = REDUCE_BLOCK // 2
    while s:
        tree[:, :s] = tree[:, :s] + tree[:, s : 2 * s]
        s //= 2
    return tree[:, 0]


def test_reducing_partials_fold_in_the_launch_order():
    """The harness's partials are, to the last bit, a CUDA launch's fold (emulated above) of
    terms over sixteen decades, whose sums depend on their order: a block's plain numpy sum
    differs from it in some block, so another order would fail here."""
    kernel = harness.compile_reducing(REDUCING_STEP)
    n = 3 * REDUCE_BLOCK * REDUCE_MAX_BLOCKS + 17  # threads with several points each
    rng = np.random.default_rng(11)
    r = rng.normal(size=n) * 10.0 ** rng.integers(-8, 8, n)
    t = rng.normal(size=n)
    partials = kernel(r, t, np.ones(n, np.uint8))
    blocks = reduce_blocks(n)
    assert partials.shape == (blocks, 2) == (REDUCE_MAX_BLOCKS, 2)
    want = _launch_order_partials(r * t, blocks)
    assert np.array_equal(partials[:, 0], want)
    assert np.array_equal(partials[:, 1], _launch_order_partials(r, blocks))
    # the same blocks' points summed in index order (numpy's pairwise sum): another order,
    # other bits in some block, so the equality above pins the order
    block_of = (np.arange(n) % (blocks * REDUCE_BLOCK)) // REDUCE_BLOCK
    terms = r * t
    other = np.array([np.sum(terms[block_of == b]) for b in range(16)])
    assert not np.array_equal(other, want[:16])
    assert fold_partials(partials, REDUCING_STEP.reduced)[0] == float(np.sum(want))


@pytest.mark.parametrize("name", sorted(SOLVES))
def test_reducing_whole_solve_agrees_with_the_array_code(reducing, name):
    """Same status, iterations and contact set; pressures within 1e-10 of the peak, the
    GPU route's tolerance against the CPU path (tests/contact/test_array_kernels.py): the
    sums' order moves each iterate by round-off, which the tolerance of the solve (1e-8)
    does not amplify beyond it."""
    make, periodic, control, p_y = SOLVES[name]
    h = make()
    padded = None if periodic else fast_padded_shape(h.shape)
    constraint = HardWall() if p_y is None else BoundedWall(np.full(h.shape, p_y))
    outs = []
    for ks in (reducing, A):
        op = ArrayConvolution(h.shape, 1.0, 1.0, np, padded)
        it = CGIteration(
            ks,
            op,
            h,
            CGOptions(tol=1e-8, max_iter=3000),
            pixel_area=1.0,
            h_scale=float(h.std()),
            p_init=np.ones_like(h),
            constraint=constraint,
            load=control.get("load"),
            displacement=control.get("displacement"),
        )
        outs.append(run_to_outcome(it))
    red, arr = outs
    assert red.status == arr.status == 0
    assert red.iterations == arr.iterations
    peak = float(np.abs(arr.pressure).max())
    assert float(np.abs(red.pressure - arr.pressure).max()) <= 1e-10 * peak
    assert np.array_equal(red.pressure > 0, arr.pressure > 0)


@pytest.mark.parametrize("periodic", [True, False])
def test_point_responses_in_one_pass(device, periodic):
    """The changed points' responses in one pass (DeviceKernels) are the array code's, point
    by point in the same order, to the last bit; a point repeated adds twice."""
    shape = (40, 48)
    padded = None if periodic else fast_padded_shape(shape)
    green = ArrayConvolution(shape, 1.0, 1.0, np, padded).real_space_kernel()
    rng = np.random.default_rng(8)
    u0 = rng.normal(size=shape)
    idx = np.array([0, 5, 39 * 48 + 47, 5, 1000, 17 * 48], dtype=np.int64)
    vals = rng.normal(size=idx.size)
    u_d, u_a = u0.copy(), u0.copy()
    device.add_point_responses(u_d, green, idx, vals)
    A.add_point_responses(u_a, green, idx, vals)
    assert np.array_equal(u_d, u_a) and not np.array_equal(u_a, u0)
    device.add_point_responses(u_d, green, idx[:0], vals[:0])  # no point: nothing
    assert np.array_equal(u_d, u_a)
