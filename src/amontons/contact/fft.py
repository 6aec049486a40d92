"""FFT backend: pyfftw plans built once and reused, with a numpy fallback.

``pyfftw`` is optional. When it cannot be imported, or when ``backend="numpy"`` is
requested, transforms go through :mod:`numpy.fft`. Plans are bound to aligned work arrays
owned by the convolution operators (see :mod:`amontons.contact.convolution`), which are
themselves cached per (shape, spacing, E*, backend, threads, planner effort), so every FFTW
plan is built once per process and reused across iterations, solves and load steps.

Planner effort is an explicit argument (no environment variable). The default,
``FFTW_MEASURE``, times candidate algorithms while planning and keeps the fastest; its
choice is written to FFTW wisdom on disk (:mod:`amontons.contact.wisdom`), which every
later process on the machine imports, so the plan, the round-off and the output bytes are
the same from run to run, and planning is paid once per transform and machine.
``FFTW_ESTIMATE`` picks plans by heuristics without timing anything or
touching the disk; its pairs are slower (benchmarks/README.md, "FFTW planner effort").
``FFTW_PATIENT`` and ``FFTW_EXHAUSTIVE`` time more candidates (minutes of planning at 2048²).

On two threads or more a transform does not use FFTW's threaded plans. It is cut into
slabs, one per thread, along the axis it does not transform; a one-thread plan per slab
runs them all at once (:class:`SlabTransform`, :func:`real_fft2`, :func:`axis_fft`). That
wakes each thread once per pass. Many of the threaded plans MEASURE picks wake the threads
for every small block of columns, and those ran at one-thread speed for minutes at a time
on a virtual machine (benchmarks/README.md, "A second core").
"""

from __future__ import annotations

import contextlib
import functools
import itertools
import math
import os
from concurrent.futures import ThreadPoolExecutor, wait

import numpy as np

from .options import (  # noqa: F401 - re-exported: the backend's names, where users look
    BACKENDS,
    DEFAULT_PLANNER_EFFORT,
    HAVE_PYFFTW,
    PLANNER_EFFORTS,
    check_planner_effort,
    resolve_backend,
    resolve_planner_effort,
)
from .wisdom import shared_wisdom

if HAVE_PYFFTW:
    import pyfftw
else:  # pragma: no cover - depends on the environment
    pyfftw = None


def empty(shape, dtype, backend: str) -> np.ndarray:
    """Uninitialised work array, SIMD-aligned for pyfftw."""
    if backend == "pyfftw":
        return pyfftw.empty_aligned(shape, dtype=dtype)
    return np.empty(shape, dtype=dtype)


def zeros(shape, dtype, backend: str) -> np.ndarray:
    """Zeroed work array, SIMD-aligned for pyfftw."""
    if backend == "pyfftw":
        return pyfftw.zeros_aligned(shape, dtype=dtype)
    return np.zeros(shape, dtype=dtype)


def aligned(a: np.ndarray, shape) -> bool:
    """True if ``a`` is a C-contiguous float64 array of ``shape`` usable by FFTW in place of
    the arrays a plan was built on (same strides and SIMD alignment)."""
    return (
        a.dtype == np.float64
        and a.shape == tuple(shape)
        # numpy calls a one-row slice of a taller array C-contiguous whatever its row
        # stride; a plan takes only the strides it was made for
        and a.strides == _c_strides(a)
        and HAVE_PYFFTW
        and a.ctypes.data % pyfftw.simd_alignment == 0
    )


def _c_strides(a: np.ndarray) -> tuple[int, ...]:
    """The strides, bytes, of a C-ordered array of ``a``'s shape and item size."""
    return tuple(a.itemsize * math.prod(a.shape[k + 1 :]) for k in range(a.ndim))


def fftw_plan(
    src,
    dst,
    axes,
    *,
    inverse: bool = False,
    planner_effort: str = DEFAULT_PLANNER_EFFORT,
):
    """Build a one-thread FFTW plan ``src -> dst`` over ``axes`` (pyfftw only).

    The plan's kind (r2c, c2r, c2c) follows from the dtypes. Inverse transforms are
    normalised like :func:`numpy.fft.ifft` (divide by the transform length) when called,
    not through ``execute()``. ``planner_effort`` is one of :data:`PLANNER_EFFORTS`; above
    FFTW_ESTIMATE the plan is built with the machine's wisdom on disk
    (:func:`amontons.contact.wisdom.shared_wisdom`). Planning with FFTW_MEASURE or more
    overwrites ``src`` and ``dst``: callers fill the arrays after planning.
    """
    effort = check_planner_effort(planner_effort)
    direction = "FFTW_BACKWARD" if inverse else "FFTW_FORWARD"
    # Inverse plans only ever read scratch spectra, so FFTW may overwrite them (faster c2r).
    # Forward plans must not: their inputs hold the permanent zero padding.
    flags = (effort, "FFTW_DESTROY_INPUT") if inverse else (effort,)
    # ESTIMATE times nothing: nothing to share between processes
    timed = effort != "FFTW_ESTIMATE"
    with shared_wisdom() if timed else contextlib.nullcontext():
        return pyfftw.FFTW(src, dst, axes=tuple(axes), direction=direction, flags=flags)


# A slab has about this many points or more (of the larger of its two arrays; the edges'
# alignment may take up to one step off): below it a second
# thread costs more to wake than it takes off the transform (2026-11-27, this 2-core VM: a
# 128² pair on two slabs per pass took 0.30 ms against 0.12 ms on one thread; 256², whose
# column pass is 33k points, gained 1.2×). The kernels' chunk is the same size.
SLAB_POINTS = 16384

# Slab edges fall on multiples of this many bytes of every array a slab transform touches:
# a cache line, so two threads never write one line, and a multiple of SIMD alignment, so
# every slab's plan is as aligned as a whole-array plan.
SLAB_ALIGNMENT = 64


def slab_edges(length: int, parts: int, step: int) -> list[tuple[int, int]]:
    """``[(start, stop), ...]``: ``range(length)`` cut into at most ``parts`` slabs of
    nearly equal size whose inner edges are multiples of ``step``; no slab is empty."""
    cuts = [0]
    for k in range(1, parts):
        edge = step * round(length * k / parts / step)
        if cuts[-1] < edge < length:
            cuts.append(edge)
    cuts.append(length)
    return list(itertools.pairwise(cuts))


def _slab_step(arrays, axis: int) -> int:
    """The smallest number of indices along ``axis`` that spans a multiple of
    :data:`SLAB_ALIGNMENT` bytes in each of ``arrays``."""
    step = 1
    for a in arrays:
        stride = abs(a.strides[axis])
        step = math.lcm(step, SLAB_ALIGNMENT // math.gcd(stride, SLAB_ALIGNMENT))
    return step


def slab_count(arrays, threads: int, min_points: int = SLAB_POINTS) -> int:
    """How many slabs a transform touching ``arrays`` runs as on ``threads`` threads: one
    per thread, fewer if a slab would hold less than ``min_points`` points of the largest
    array; 1 means one whole-array plan."""
    largest = max(a.size for a in arrays)
    return min(int(threads), max(1, largest // int(min_points)))


def _workers(count: int) -> ThreadPoolExecutor:
    """This process's pool of threads that run slabs beside the calling thread, with room
    for ``count`` at once. One pool serves every transform: it starts a thread only when
    none is idle, so it holds as many as the widest transform has needed."""
    # keyed by process: a child forked after a threaded transform inherits the pool object
    # but none of its threads, and would wait forever on it
    pid = os.getpid()
    size, pool = _POOLS.get(pid, (0, None))
    if size < count:
        # a wider pool takes over; the old one is dropped, not shut down, as a transform on
        # another thread may still be submitting to it. Its threads end once it is collected.
        pool = ThreadPoolExecutor(max_workers=count, thread_name_prefix=f"amontons-fft-{pid}")
        _POOLS[pid] = (count, pool)
    return pool


# process id -> (room, pool) of :func:`_workers`
_POOLS: dict[int, tuple[int, ThreadPoolExecutor]] = {}


class SlabTransform:
    """One FFTW transform along ``axis`` of a 2-D array, on ``threads`` threads.

    The other axis is cut into ``threads`` slabs (:func:`slab_edges`), fewer if a slab would
    have less than ``min_points`` points (default :data:`SLAB_POINTS`); each slab has a
    one-thread plan (:func:`fftw_plan`), and :meth:`execute` runs the first in the calling
    thread and the others in a pool at the same time (pyfftw lets go of the GIL while a plan
    runs). Every slab's 1-D transforms are the ones a whole-array plan computes, so the
    result is the same to round-off. ``src`` and ``dst`` have the same length along the
    other axis (they may be one array: an in-place transform).
    """

    def __init__(
        self,
        src,
        dst,
        axis: int,
        *,
        inverse: bool = False,
        threads: int = 2,
        planner_effort: str = DEFAULT_PLANNER_EFFORT,
        min_points: int = SLAB_POINTS,
    ):
        other = 1 - axis
        if src.shape[other] != dst.shape[other]:
            raise ValueError(
                f"a slab transform along axis {axis} needs arrays of one length along axis "
                f"{other}, got shapes {src.shape} and {dst.shape}"
            )
        self._other = other
        step = _slab_step((src, dst), other)
        parts = slab_count((src, dst), threads, min_points)
        self._edges = slab_edges(src.shape[other], parts, step)
        self._plans = [
            fftw_plan(
                self._slab(src, edge),
                self._slab(dst, edge),
                (axis,),
                inverse=inverse,
                planner_effort=planner_effort,
            )
            for edge in self._edges
        ]

    def _slab(self, a, edge):
        start, stop = edge
        return a[start:stop] if self._other == 0 else a[:, start:stop]

    def execute(self, before=None, after=None) -> None:
        """Transform every slab; returns when all are done.

        ``before(start, stop)`` and ``after(start, stop)``, when given, run in a slab's
        thread just before and just after its transform, with the slab's index range along
        the axis not transformed. An operator's copies into and out of its work arrays then
        run on the solve's threads, each beside the slab it feeds, not as a serial pass
        between transforms.
        """
        first, *others = [
            functools.partial(_slab_with_hooks, plan, edge, before, after)
            for plan, edge in zip(self._plans, self._edges, strict=True)
        ]
        pool = _workers(len(others)) if others else None
        running = [pool.submit(task) for task in others]
        try:
            first()
        finally:
            # every slab has finished before this returns or raises: none writes into the
            # arrays after the caller has them back
            wait(running)
        for slab in running:
            slab.result()

    def update_arrays(self, src, dst) -> None:
        """Run on ``src`` and ``dst`` from now on: arrays like the planned ones (shape,
        strides, alignment; pyfftw checks)."""
        for plan, edge in zip(self._plans, self._edges, strict=True):
            plan.update_arrays(self._slab(src, edge), self._slab(dst, edge))


def _slab_with_hooks(plan, edge, before, after) -> None:
    """One slab of :meth:`SlabTransform.execute` with its hooks."""
    if before is not None:
        before(*edge)
    plan.execute()
    if after is not None:
        after(*edge)


class TwoPassRealFFT2:
    """A real 2-D FFT as two passes of :class:`SlabTransform`: forward, r2c along the rows
    (axis 1) into ``dst`` and c2c along its columns in place; inverse, c2c along the
    columns of ``src`` in place (``src`` is scratch, as for an inverse plan) and c2r along
    the rows into ``dst``. The same 1-D transforms as a 2-D plan, in the same order;
    ``min_points`` as :class:`SlabTransform`'s."""

    def __init__(
        self,
        src,
        dst,
        *,
        inverse: bool = False,
        threads: int = 2,
        planner_effort: str = DEFAULT_PLANNER_EFFORT,
        min_points: int = SLAB_POINTS,
    ):
        kw = {
            "inverse": inverse,
            "threads": threads,
            "planner_effort": planner_effort,
            "min_points": min_points,
        }
        self._inverse = inverse
        if inverse:
            self._passes = (SlabTransform(src, src, 0, **kw), SlabTransform(src, dst, 1, **kw))
        else:
            self._passes = (SlabTransform(src, dst, 1, **kw), SlabTransform(dst, dst, 0, **kw))

    def execute(self) -> None:
        """Both passes, one after the other."""
        for step in self._passes:
            step.execute()

    def update_arrays(self, src, dst) -> None:
        """Run on ``src`` and ``dst`` from now on (as :meth:`SlabTransform.update_arrays`)."""
        first, second = self._passes
        if self._inverse:
            first.update_arrays(src, src)
            second.update_arrays(src, dst)
        else:
            first.update_arrays(src, dst)
            second.update_arrays(dst, dst)


def real_fft2(
    src,
    dst,
    *,
    inverse: bool = False,
    threads: int = 1,
    planner_effort: str = DEFAULT_PLANNER_EFFORT,
):
    """A real 2-D FFT ``src -> dst`` (r2c forward, c2r inverse; not normalised) with
    ``execute()`` and ``update_arrays()``: :class:`TwoPassRealFFT2` on two threads or more
    (module doc), one FFTW plan on one thread or when the spectrum is too small for two
    slabs (:func:`slab_count`; its column pass would run on one thread)."""
    spectrum = src if inverse else dst
    if slab_count((spectrum,), threads) == 1:
        return fftw_plan(src, dst, (0, 1), inverse=inverse, planner_effort=planner_effort)
    return TwoPassRealFFT2(
        src, dst, inverse=inverse, threads=threads, planner_effort=planner_effort
    )


def axis_fft(
    src,
    dst,
    axis: int,
    *,
    inverse: bool = False,
    threads: int = 1,
    planner_effort: str = DEFAULT_PLANNER_EFFORT,
):
    """A 1-D FFT along ``axis`` of 2-D arrays: a :class:`SlabTransform`, a slab per thread
    (module doc), or one slab, the whole-array FFTW plan, on one thread or where a second
    slab would be too small (:func:`slab_count`)."""
    return SlabTransform(
        src, dst, axis, inverse=inverse, threads=threads, planner_effort=planner_effort
    )


class RealFFT2Pair:
    """One forward + one inverse real 2-D FFT of a fixed shape, as the periodic operator
    runs them (:func:`real_fft2`): the benchmark floor.

    Parameters
    ----------
    shape : (n0, n1)
        Real array shape.
    backend : {"pyfftw", "numpy", None}
    threads : int
    planner_effort : str
        One of :data:`PLANNER_EFFORTS` (pyfftw only).
    """

    def __init__(
        self,
        shape,
        backend: str | None = None,
        threads: int = 1,
        planner_effort: str = DEFAULT_PLANNER_EFFORT,
    ):
        self.backend = resolve_backend(backend)
        self.shape = tuple(shape)
        spec_shape = (shape[0], shape[1] // 2 + 1)
        self.real = empty(self.shape, np.float64, self.backend)
        self.spec = empty(spec_shape, np.complex128, self.backend)
        if self.backend == "pyfftw":
            kw = {"threads": threads, "planner_effort": planner_effort}
            self._fwd = real_fft2(self.real, self.spec, **kw)
            self._inv = real_fft2(self.spec, self.real, inverse=True, **kw)
        self.real[...] = 0.0

    def __call__(self) -> None:
        """Transform ``self.real`` forward into ``self.spec`` and back (with pyfftw not
        normalised, as the operators run it: ``self.real`` comes back times its size)."""
        if self.backend == "pyfftw":
            self._fwd.execute()
            self._inv.execute()
        else:
            self.spec[...] = np.fft.rfft2(self.real)
            self.real[...] = np.fft.irfft2(self.spec, s=self.shape)


# FFT lengths of the Hockney-padded operator (contact.convolution): FFTW has hard-coded
# codelets for small factors and is best at sizes 2^a 3^b 5^c 7^d 11^e 13^f with e + f = 0
# or 1 (its manual, "Complex One-Dimensional DFTs"); even sizes only. Measurements and the
# choice of the rule, odd sizes included: benchmarks/README.md, "Fast FFT lengths".
FAST_PRIMES = (2, 3, 5, 7)
FAST_EXTRA = (1, 11, 13)  # at most one factor 11 or 13


def smooth_length(target: int, primes=FAST_PRIMES) -> int:
    """The smallest integer ``>= target`` whose prime factors are all in ``primes``."""
    target = int(target)
    if target <= 1:
        return 1
    best = None
    # depth-first over the products of the primes (non-decreasing prime order, so each
    # product once), stopping at the first one >= target: a few hundred for target ~ 10⁴
    stack = [(1, 0)]
    while stack and best != target:
        value, first = stack.pop()
        if value >= target:
            best = value if best is None else min(best, value)
            continue
        for k in range(first, len(primes)):
            stack.append((value * primes[k], k))
    return best


def fast_length(n: int) -> int:
    """The smallest even length ``>= n`` of the form ``2^a 3^b 5^c 7^d 11^e 13^f`` with
    ``e + f <= 1`` (FFTW's fast sizes, see the comment above :data:`FAST_PRIMES`)."""
    half = (int(n) + 1) // 2  # even m = 2k, k >= ceil(n / 2)
    return 2 * min(f * smooth_length(-(-half // f)) for f in FAST_EXTRA)
