"""FFT backend: pyfftw plans built once and reused, with a numpy fallback.

``pyfftw`` is optional. When it cannot be imported, or when ``backend="numpy"`` is
requested, transforms go through :mod:`numpy.fft`. Plans are bound to aligned work arrays
owned by the convolution operators (see :mod:`amontons.contact.convolution`), which are
themselves cached per (shape, spacing, E*, backend, threads), so every FFTW plan is built
once per process and reused across iterations, solves and load steps.
"""

from __future__ import annotations

import os

import numpy as np

try:  # pyfftw is optional: numpy.fft is the fallback
    import pyfftw

    HAVE_PYFFTW = True
except ImportError:  # pragma: no cover - depends on the environment
    pyfftw = None
    HAVE_PYFFTW = False

BACKENDS = ("pyfftw", "numpy")

# Measured (benchmarks/README.md, 512²): FFTW_MEASURE plans in ~0.4-0.6 s and makes the
# pruned non-periodic convolution ~25 % faster than FFTW_ESTIMATE (periodic: ~5 %);
# FFTW_PATIENT plans for 4-12 s and gains nothing more, so MEASURE is the default.
# Override with the environment variable AMONTONS_FFTW_EFFORT (FFTW_ESTIMATE /
# FFTW_MEASURE / FFTW_PATIENT).
PLANNER_EFFORT = os.environ.get("AMONTONS_FFTW_EFFORT", "FFTW_MEASURE")


def resolve_backend(backend: str | None) -> str:
    """Return the backend name to use: ``"pyfftw"`` if available, else ``"numpy"``.

    Raises
    ------
    ValueError
        For an unknown name, or ``"pyfftw"`` requested but not importable.
    """
    if backend is None:
        return "pyfftw" if HAVE_PYFFTW else "numpy"
    if backend not in BACKENDS:
        raise ValueError(f"unknown FFT backend {backend!r}; expected one of {BACKENDS}")
    if backend == "pyfftw" and not HAVE_PYFFTW:
        raise ValueError("FFT backend 'pyfftw' requested but pyfftw is not importable")
    return backend


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


def fftw_plan(src, dst, axes, *, inverse: bool = False, threads: int = 1):
    """Build an FFTW plan ``src -> dst`` over ``axes`` (pyfftw only).

    The plan's kind (r2c, c2r, c2c) follows from the dtypes. Inverse transforms are
    normalised like :func:`numpy.fft.ifft` (divide by the transform length).
    Planning with FFTW_MEASURE overwrites ``src`` and ``dst``: callers fill the arrays
    after planning.
    """
    direction = "FFTW_BACKWARD" if inverse else "FFTW_FORWARD"
    # Inverse plans only ever read scratch spectra, so FFTW may overwrite them (faster c2r).
    # Forward plans must not: their inputs hold the permanent zero padding.
    flags = (PLANNER_EFFORT, "FFTW_DESTROY_INPUT") if inverse else (PLANNER_EFFORT,)
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
    """

    def __init__(self, shape, backend: str | None = None, threads: int = 1):
        self.backend = resolve_backend(backend)
        self.shape = tuple(shape)
        spec_shape = (shape[0], shape[1] // 2 + 1)
        self.real = empty(self.shape, np.float64, self.backend)
        self.spec = empty(spec_shape, np.complex128, self.backend)
        if self.backend == "pyfftw":
            self._fwd = fftw_plan(self.real, self.spec, (0, 1), threads=threads)
            self._inv = fftw_plan(self.spec, self.real, (0, 1), inverse=True, threads=threads)
        self.real[...] = 0.0

    def __call__(self) -> None:
        """Transform ``self.real`` forward into ``self.spec`` and back."""
        if self.backend == "pyfftw":
            self._fwd()
            self._inv()
        else:
            self.spec[...] = np.fft.rfft2(self.real)
            self.real[...] = np.fft.irfft2(self.spec, s=self.shape)
