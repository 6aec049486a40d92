"""Transforms on several threads (amontons.contact.fft): slabs of one-thread FFTW plans.

Each slab computes the 1-D transforms a whole-array plan computes, so every comparison
with numpy.fft below is round-off: 1e-12 of the largest coefficient (float64, transform
lengths below 10³: FFT round-off grows like log2(n) times 1e-16)."""

import multiprocessing
import os
import threading
import time

import numpy as np
import pytest

from amontons.contact import fft
from amontons.contact.convolution import NonPeriodicConvolution, PeriodicConvolution
from amontons.contact.fft import (
    HAVE_PYFFTW,
    SLAB_ALIGNMENT,
    SLAB_POINTS,
    SlabTransform,
    TwoPassRealFFT2,
    aligned,
    axis_fft,
    empty,
    real_fft2,
    slab_edges,
)

pytestmark = pytest.mark.skipif(not HAVE_PYFFTW, reason="pyfftw not installed")

RTOL = 1e-12


def _close(a, b):
    return np.abs(a - b).max() <= RTOL * np.abs(b).max()


@pytest.mark.parametrize("length", [1, 5, 64, 257, 513, 1025])
@pytest.mark.parametrize("parts", [1, 2, 3, 8, 16])
@pytest.mark.parametrize("step", [1, 2, 4])
def test_slab_edges_cover_the_axis_once_in_near_equal_aligned_slabs(length, parts, step):
    edges = slab_edges(length, parts, step)
    starts, stops = zip(*edges, strict=True)
    assert starts[0] == 0 and stops[-1] == length
    assert list(starts[1:]) == list(stops[:-1])  # contiguous, no overlap, no gap
    assert all(stop > start for start, stop in edges)  # no empty slab
    assert len(edges) <= parts
    assert all(edge % step == 0 for edge in starts[1:])
    sizes = [stop - start for start, stop in edges]
    if length >= parts * step:  # room for every part: they differ by at most one step
        assert len(edges) == parts
        assert max(sizes) - min(sizes) <= step


def _spectrum_pair(shape):
    real = empty(shape, np.float64, "pyfftw")
    spec = empty((shape[0], shape[1] // 2 + 1), np.complex128, "pyfftw")
    return real, spec


@pytest.mark.parametrize("shape", [(64, 64), (96, 80), (33, 50), (130, 126)])
@pytest.mark.parametrize("threads", [2, 3, 16])
def test_a_two_pass_real_fft_is_numpys_rfft2_and_back(shape, threads):
    """Forward: rfft2. Inverse: irfft2 times the size (plans run unnormalised, as the
    operators run them). 16 threads on 33 rows: fewer slabs than threads."""
    real, spec = _spectrum_pair(shape)
    fwd = TwoPassRealFFT2(real, spec, threads=threads, min_points=1)
    inv = TwoPassRealFFT2(spec, real, inverse=True, threads=threads, min_points=1)
    x = np.random.default_rng(shape[0] + threads).random(shape)
    real[...] = x
    fwd.execute()
    assert _close(spec, np.fft.rfft2(x))
    inv.execute()
    assert _close(real, x * x.size)


@pytest.mark.parametrize("threads", [2, 5])
def test_slab_transforms_run_on_other_arrays_like_the_planned_ones(threads):
    """update_arrays moves every slab's plan onto the same slab of new aligned arrays (the
    periodic operator runs on the solver's own arrays without copies)."""
    shape = (48, 40)
    real, spec = _spectrum_pair(shape)
    fwd = TwoPassRealFFT2(real, spec, threads=threads, min_points=1)
    inv = TwoPassRealFFT2(spec, real, inverse=True, threads=threads, min_points=1)
    other_real, other_spec = _spectrum_pair(shape)
    x = np.random.default_rng(7).random(shape)
    other_real[...] = x
    real[...] = 0.0
    spec[...] = 0.0
    fwd.update_arrays(other_real, other_spec)
    fwd.execute()
    assert _close(other_spec, np.fft.rfft2(x))
    inv.update_arrays(other_spec, other_real)
    inv.execute()
    assert _close(other_real, x * x.size)
    assert not np.any(real) and not np.any(spec)  # the planned arrays were left alone


@pytest.mark.parametrize("axis", [0, 1])
@pytest.mark.parametrize("threads", [2, 4])
def test_an_axis_transform_in_place_is_numpys_fft_along_that_axis(axis, threads):
    shape = (40, 36)
    a = empty(shape, np.complex128, "pyfftw")
    rng = np.random.default_rng(axis + 10 * threads)
    x = rng.random(shape) + 1j * rng.random(shape)
    fwd = SlabTransform(a, a, axis, threads=threads, min_points=1)
    inv = SlabTransform(a, a, axis, inverse=True, threads=threads, min_points=1)
    a[...] = x  # after planning: FFTW_MEASURE writes over the arrays
    fwd.execute()
    assert _close(a, np.fft.fft(x, axis=axis))
    inv.execute()
    assert _close(a, x * shape[axis])


def test_every_slab_plan_is_as_aligned_as_the_whole_array():
    """Slab edges a multiple of SLAB_ALIGNMENT bytes from the array's start: no slab plan
    falls back to FFTW_UNALIGNED (no SIMD), on rows of real and of complex numbers (spectrum
    rows of 33 complex = 528 bytes, so row slabs start on multiples of 4 rows) and on
    columns."""
    real, spec = _spectrum_pair((64, 64))
    for transform, src, dst in (
        (SlabTransform(real, spec, 1, threads=3, min_points=1), real, spec),
        (SlabTransform(spec, spec, 0, threads=3, min_points=1), spec, spec),
    ):
        assert len(transform._plans) == 3
        for plan in transform._plans:
            for a, whole in ((plan.input_array, src), (plan.output_array, dst)):
                assert (a.ctypes.data - whole.ctypes.data) % SLAB_ALIGNMENT == 0
            assert "FFTW_UNALIGNED" not in plan.flags


def test_a_slab_transform_needs_arrays_of_one_length_across_it():
    real = empty((8, 16), np.float64, "pyfftw")
    spec = empty((6, 9), np.complex128, "pyfftw")
    with pytest.raises(ValueError, match=r"one length along axis 0.*\(8, 16\).*\(6, 9\)"):
        SlabTransform(real, spec, 1, threads=2)


def test_one_thread_is_one_fftw_plan():
    """On one thread the operators keep one whole-array FFTW plan (the same plans, bits and
    speed as before slabs existed)."""
    real, spec = _spectrum_pair((16, 16))
    plan = real_fft2(real, spec, threads=1)
    assert type(plan).__name__ == "FFTW"
    assert plan.axes == (0, 1)


def test_slabs_have_at_least_slab_points_points():
    """Below SLAB_POINTS a slab costs more to wake than it saves: a 128² transform stays
    one slab on 16 threads; 512² (its spectrum 512 × 257 = 131584 points) takes 8 slabs for
    its columns and 16 for its real rows."""
    real, spec = _spectrum_pair((128, 128))
    assert len(SlabTransform(real, spec, 1, threads=16)._plans) == 1
    real, spec = _spectrum_pair((512, 512))
    assert SLAB_POINTS == 16384
    assert len(SlabTransform(spec, spec, 0, threads=16)._plans) == 8
    assert len(SlabTransform(real, spec, 1, threads=16)._plans) == 16
    two = axis_fft(spec, spec, 0, threads=2)
    assert isinstance(two, SlabTransform) and len(two._plans) == 2
    assert isinstance(real_fft2(real, spec, threads=2), TwoPassRealFFT2)
    # 128²: its spectrum (8320 points) is less than two slabs: the whole-array plan
    small_real, small_spec = _spectrum_pair((128, 128))
    assert type(real_fft2(small_spec, small_real, inverse=True, threads=16)).__name__ == "FFTW"


def _transform_in_child(transform, spec, x, queue):
    spec[...] = x
    transform.execute()
    queue.put(np.abs(spec - np.fft.fft(x, axis=0)).max() / np.abs(spec).max())


@pytest.mark.skipif(
    "fork" not in multiprocessing.get_all_start_methods(), reason="no fork on this platform"
)
# Python 3.12+ warns that forking a multi-threaded process may deadlock: what this checks
@pytest.mark.filterwarnings("ignore:This process .* is multi-threaded:DeprecationWarning")
def test_a_forked_child_runs_a_slab_transform_its_parent_ran():
    """A child forked after its parent ran a transform on slabs inherits the parent's pool
    object but none of its threads; it must start its own rather than wait forever (a
    pipeline or a user's multiprocessing pool forks after a solve)."""
    spec = empty((64, 64), np.complex128, "pyfftw")
    transform = SlabTransform(spec, spec, 0, threads=2, min_points=1)
    x = np.random.default_rng(5).random((64, 64)) + 0j
    spec[...] = x
    transform.execute()  # the parent's pool now exists, with its threads
    context = multiprocessing.get_context("fork")
    queue = context.Queue()
    child = context.Process(target=_transform_in_child, args=(transform, spec, x, queue))
    child.start()
    child.join(timeout=60)
    if child.is_alive():
        child.kill()
        pytest.fail("the forked child's slab transform did not finish in 60 s")
    assert child.exitcode == 0
    assert queue.get(timeout=5) <= RTOL


# The smallest grids on which the operators' own transforms (SLAB_POINTS per slab) run as
# two slabs: a 256² spectrum has 256 × 129 = 33024 points; 257 × 255 is odd on both axes; a
# 128² window pads to 256².
OPERATOR_CASES = [
    ((256, 256), True, None),
    ((257, 255), True, None),
    ((128, 128), False, True),
    ((128, 128), False, False),
]


def _slab_operators(shape, periodic, pruned):
    """The numpy-backed operator and a two-thread pyfftw one, whose transforms are checked
    to be slabs (on smaller grids threads=2 runs one whole-array plan)."""
    kw = {} if periodic else {"pruned": pruned}
    cls = PeriodicConvolution if periodic else NonPeriodicConvolution
    ref = cls(shape, 0.5, 2.0, backend="numpy", **kw)
    two = cls(shape, 0.5, 2.0, backend="pyfftw", threads=2, planner_effort="FFTW_ESTIMATE", **kw)
    if pruned:
        passes = (two._row_fwd, two._col_fwd, two._col_inv, two._row_inv)
    else:
        assert isinstance(two._fwd, TwoPassRealFFT2) and isinstance(two._inv, TwoPassRealFFT2)
        passes = (*two._fwd._passes, *two._inv._passes)
    assert all(len(one_pass._plans) == 2 for one_pass in passes)
    return ref, two


@pytest.mark.parametrize(("shape", "periodic", "pruned"), OPERATOR_CASES)
def test_operators_on_slabs_give_numpys_convolution(shape, periodic, pruned):
    """A two-thread operator on slabs gives the numpy backend's K*p to round-off (1e-12 of
    the peak) by every way the solver calls it, one after the other so that each rebinds
    the plans the last one moved: on the caller's aligned arrays (no copy), through its own
    arrays (a strided input), and in halves (forward, multiply_energy, inverse), whose
    energy is Σ p·(K*p) to 1e-12 relative."""
    ref, two = _slab_operators(shape, periodic, pruned)
    rng = np.random.default_rng(sum(shape))
    for _ in range(2):
        p = empty(shape, np.float64, "pyfftw")
        p[...] = rng.random(shape)
        expected = ref(p)
        out = empty(shape, np.float64, "pyfftw")
        assert _close(two(p, out), expected)
        strided = np.asfortranarray(p)
        assert _close(two(strided), expected)
        two.forward(p)
        energy = two.multiply_energy()
        assert _close(two.inverse(np.empty(shape)), expected)
        assert energy == pytest.approx(float(np.sum(p * expected)), rel=1e-12)


def test_hooks_run_around_each_slab_in_its_own_thread():
    """execute(before, after): ``before`` fills each slab's input and ``after`` takes its
    output, once per slab, in the slab's own thread, around its transform (the result is
    numpy's only if each ran on its side of it); together they cover the axis once. (Which
    pool thread takes which other slab is the pool's business: a quick slab's thread may
    take the next.)"""
    a = empty((32, 96), np.complex128, "pyfftw")
    transform = SlabTransform(a, a, 0, threads=3, min_points=1)
    rng = np.random.default_rng(9)
    x = rng.random(a.shape) + 1j * rng.random(a.shape)
    out = np.zeros_like(x)
    a[...] = 0.0
    seen = []

    def before(start, stop):
        a[:, start:stop] = x[:, start:stop]
        seen.append((start, stop, threading.current_thread().name))

    def after(start, stop):
        out[:, start:stop] = a[:, start:stop]
        seen.append((start, stop, threading.current_thread().name))

    transform.execute(before=before, after=after)
    assert _close(out, np.fft.fft(x, axis=0))
    slabs = sorted({(start, stop) for start, stop, _ in seen})
    assert len(seen) == 6 and len(slabs) == 3
    assert slabs[0][0] == 0 and slabs[-1][1] == 96
    assert all(stop == start for (_, stop), (start, _) in zip(slabs, slabs[1:], strict=False))
    threads = [{name for start, stop, name in seen if (start, stop) == e} for e in slabs]
    assert all(len(names) == 1 for names in threads)  # each slab's two hooks in one thread
    assert threads[0] == {threading.current_thread().name}  # the first: the caller's


def test_the_padded_operator_takes_what_one_assignment_would():
    """The window's rows are copied slab by slab, but the operator takes what one numpy
    assignment of the whole field took: a field that broadcasts to the window (a constant
    pressure) gives the numpy backend's answer on two slabs as on one, and a field or an
    ``out`` of another shape is refused, not cut to the window."""
    ref, two = _slab_operators((128, 128), False, True)
    assert _close(two(np.full((1, 128), 3.0)), ref(np.full((128, 128), 3.0)))
    with pytest.raises(ValueError, match="broadcast"):
        two(np.ones((130, 128)))
    with pytest.raises(ValueError, match=r"out has shape \(140, 128\); the window is"):
        two(np.ones((128, 128)), np.empty((140, 128)))


def test_a_row_of_a_taller_array_is_not_taken_as_the_plans_array():
    """numpy calls a one-row slice of a taller array C-contiguous, but its row stride is not
    the planned one (pyfftw would refuse it): it goes through the operator's own arrays."""
    tall = empty((2, 16), np.float64, "pyfftw")
    tall[...] = np.random.default_rng(3).random((2, 16))
    row, out = tall[::2], empty((2, 16), np.float64, "pyfftw")[::2]
    assert row.flags.c_contiguous and not aligned(row, (1, 16))
    expected = PeriodicConvolution((1, 16), 0.5, 2.0, backend="numpy")(row)
    got = PeriodicConvolution((1, 16), 0.5, 2.0, backend="pyfftw")(row, out)
    assert _close(got, expected)


def _slab_threads():
    prefix = f"amontons-fft-{os.getpid()}"
    return [t for t in threading.enumerate() if t.name.startswith(prefix)]


def test_one_pool_serves_transforms_of_every_width():
    """The slabs of every transform share one pool per process: after transforms on 8, then
    2 to 7 threads, the process holds no more slab threads than the widest needs (7, or an
    earlier test's wider pool), not a pool per width (1 + 2 + ... + 7 = 28 threads)."""
    spec = empty((64, 64), np.complex128, "pyfftw")
    for threads in (8, 2, 3, 4, 5, 6, 7):
        SlabTransform(spec, spec, 0, threads=threads, min_points=1).execute()
    room = fft._POOLS[os.getpid()][0]
    assert room >= 7
    # the threads of a narrower pool this one replaced end once idle: give them a moment
    deadline = time.monotonic() + 5.0
    while len(_slab_threads()) > room and time.monotonic() < deadline:
        time.sleep(0.05)
    assert len(_slab_threads()) <= room


class _SlowSlab:
    """A stand-in for a slab's plan that takes a while and says when it is done."""

    def __init__(self):
        self.done = False

    def execute(self):
        time.sleep(0.2)
        self.done = True


class _FailingSlab:
    def execute(self):
        raise RuntimeError("this slab failed")


def test_a_failing_slab_returns_only_once_every_slab_has_finished():
    """If the calling thread's slab raises, the others still run in the pool; execute waits
    for them before it raises, so that none writes into the arrays after the caller has
    them back."""
    spec = empty((64, 64), np.complex128, "pyfftw")
    transform = SlabTransform(spec, spec, 0, threads=3, min_points=1)
    slow = [_SlowSlab(), _SlowSlab()]
    transform._plans = [_FailingSlab(), *slow]
    with pytest.raises(RuntimeError, match="this slab failed"):
        transform.execute()
    assert all(slab.done for slab in slow)
