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
"""

from __future__ import annotations

import contextlib

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
    the arrays a plan was built on (same SIMD alignment)."""
    return (
        a.dtype == np.float64
        and a.shape == tuple(shape)
        and a.flags.c_contiguous
        and HAVE_PYFFTW
        and a.ctypes.data % pyfftw.simd_alignment == 0
    )


def fftw_plan(
    src,
    dst,
    axes,
    *,
    inverse: bool = False,
    threads: int = 1,
    planner_effort: str = DEFAULT_PLANNER_EFFORT,
):
    """Build an FFTW plan ``src -> dst`` over ``axes`` (pyfftw only).

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
        return pyfftw.FFTW(
            src, dst, axes=tuple(axes), direction=direction, flags=flags, threads=int(threads)
        )


class RealFFT2Pair:
    """One forward + one inverse real 2-D FFT of a fixed shape (the benchmark floor).

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
            self._fwd = fftw_plan(self.real, self.spec, (0, 1), **kw)
            self._inv = fftw_plan(self.spec, self.real, (0, 1), inverse=True, **kw)
        self.real[...] = 0.0

    def __call__(self) -> None:
        """Transform ``self.real`` forward into ``self.spec`` and back."""
        if self.backend == "pyfftw":
            self._fwd()
            self._inv()
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
