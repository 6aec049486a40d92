"""The array namespaces the array kernel set runs on (:mod:`.array_kernels`): CuPy on a GPU
(``backend="cupy"``, the optional extra ``pip install amontons[gpu]``), or numpy, which runs
the same array code on the CPU so that CI, without a GPU, tests its logic.

``ARRAY_BACKENDS`` are the ``backend`` names of :func:`amontons.contact.solve` that select
the array set: ``"cupy"``, ``"numpy-array"`` (for tests: the GPU route's code on numpy
arrays, which the numba set outruns on a CPU) and ``"cupy-array"`` (for benchmarks: the
array code on the GPU without its CUDA kernels, the baseline those kernels are timed
against on the same device) and ``"cupy-terms"`` (for benchmarks: the CUDA kernels that
write their terms to memory and sum them with CuPy, one launch per sum, with ``cupy.fft``:
the route's second version, the baseline of the reducing kernels that ``"cupy"`` runs; its
point responses are the one-kernel ones of the current version).

This is the one module that imports CuPy, and it does so lazily, inside
:func:`_load_cupy`: CuPy is an optional dependency that most installations lack, and its
import initialises CUDA; importing it at the top of a module would make every solve (and a
Snakemake dry run, which never solves) need it. A missing CuPy or device raises
:class:`~.errors.BackendUnavailableError` when a solve asks for it, naming the backend.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache, partial

import numpy as np

from .errors import BackendUnavailableError

CUPY = "cupy"
NUMPY_ARRAY = "numpy-array"
CUPY_ARRAY = "cupy-array"
CUPY_TERMS = "cupy-terms"
ARRAY_BACKENDS = (CUPY, NUMPY_ARRAY, CUPY_ARRAY, CUPY_TERMS)
# a reducing kernel's scalar parameters as the device reads them (.device_sources.TYPES)
SCALAR_TYPES = {"float64": np.float64, "int32": np.int32, "uint8": np.uint8, "int8": np.int8}
INSTALL_HINT = "pip install 'amontons[gpu]' (CuPy for CUDA 12, cupy-cuda12x)"


@dataclass(frozen=True)
class ArrayModule:
    """An array namespace and the few things the array kernel set needs beside it.

    ``xp``: the namespace (``numpy`` or ``cupy``); ``to_host``: an array of it as a numpy
    array; ``add_at(a, idx, values)``: ``a[idx] += values`` with repeated indices summed
    (``np.add.at``, ``cupyx.scatter_add``); ``fuse``: compiles an element-wise function of
    arrays and scalars into one kernel (``cupy.fuse``; identity on numpy); ``compile``:
    builds an element-wise kernel from its source (a :class:`.device_sources.KernelSource`),
    callable as CuPy's are (inputs, then outputs), or None where the
    namespace runs no CUDA source (numpy: the array set then runs its array code);
    ``compile_reducing``: builds a :class:`.device_sources.ReducingKernel`, called with its
    arguments in the order of ``ReducingKernel.arguments`` and returning its ``(blocks, K)``
    partials as an array of the namespace, or None (the set then sums the terms its
    element-wise kernels write); ``fft_pair(shape)``: the :class:`RealFFTPair` of a real grid
    of ``shape``, or None (the convolution then calls ``xp.fft``).
    """

    name: str
    xp: object
    to_host: object
    add_at: object
    fuse: object
    compile: object = None
    compile_reducing: object = None
    fft_pair: object = None


@dataclass(frozen=True)
class RealFFTPair:
    """The real 2-D transforms of one grid shape, made once and run on given arrays:
    ``forward(a, spectrum)`` (``a`` real, C-contiguous, of the shape; ``spectrum`` complex,
    ``(n0, n1 // 2 + 1)``) and ``inverse(spectrum, out)`` (``out`` real, C-contiguous, of
    the shape; ``spectrum`` may be overwritten), neither normalised: ``inverse(forward(a))``
    is ``n0·n1·a``. On CuPy, cuFFT's plans executed directly, without the per-call shape
    checks, plan-cache look-ups, copies and normalising pass of ``cupy.fft``; on numpy,
    ``numpy.fft``, so the tests run the code that uses them."""

    forward: object
    inverse: object


def numpy_fft_pair(shape) -> RealFFTPair:
    """:class:`RealFFTPair` of ``numpy.fft`` (``norm="forward"`` leaves the inverse
    unnormalised)."""
    shape = tuple(int(s) for s in shape)

    def forward(a, spectrum):
        spectrum[...] = np.fft.rfft2(a)

    def inverse(spectrum, out):
        out[...] = np.fft.irfft2(spectrum, s=shape, norm="forward")

    return RealFFTPair(forward, inverse)


def _identity(fn):
    return fn


NUMPY = ArrayModule(NUMPY_ARRAY, np, np.asarray, np.add.at, _identity, fft_pair=numpy_fft_pair)


def array_module(name: str) -> ArrayModule:
    """The :class:`ArrayModule` of backend ``name`` (one of :data:`ARRAY_BACKENDS`).

    Raises
    ------
    BackendUnavailableError
        ``"cupy"``, ``"cupy-array"`` or ``"cupy-terms"`` without CuPy or a CUDA device.
    ValueError
        Another name.
    """
    if name == NUMPY_ARRAY:
        return NUMPY
    if name == CUPY:
        return _load_cupy()
    # the baselines are the route's earlier versions, cupy.fft's transforms included
    if name == CUPY_ARRAY:
        return replace(
            _load_cupy(), name=CUPY_ARRAY, compile=None, compile_reducing=None, fft_pair=None
        )
    if name == CUPY_TERMS:
        return replace(_load_cupy(), name=CUPY_TERMS, compile_reducing=None, fft_pair=None)
    raise ValueError(f"unknown array backend {name!r}; expected one of {ARRAY_BACKENDS}")


@lru_cache(maxsize=1)
def _load_cupy() -> ArrayModule:
    try:
        # the optional dependency, imported only when a solve asks for it (module docstring)
        import cupy
        import cupyx
        import cupyx.scipy.fft
    except ImportError as exc:
        raise BackendUnavailableError(
            f"backend='cupy' needs CuPy, which is not importable here ({exc}); install the "
            f"GPU extra: {INSTALL_HINT}, or use backend=None for the CPU solver"
        ) from exc
    try:
        devices = cupy.cuda.runtime.getDeviceCount()
    except Exception as exc:  # CUDARuntimeError: no driver, no device
        raise BackendUnavailableError(
            f"backend='cupy': CuPy is installed but no CUDA device is usable ({exc}); run on "
            "a machine with an NVIDIA GPU, or use backend=None for the CPU solver"
        ) from exc
    if devices < 1:
        raise BackendUnavailableError(
            "backend='cupy': CuPy is installed but finds no CUDA device; run on a machine "
            "with an NVIDIA GPU, or use backend=None for the CPU solver"
        )
    return ArrayModule(
        CUPY,
        cupy,
        cupy.asnumpy,
        cupyx.scatter_add,
        cupy.fuse,
        partial(_cupy_kernel, cupy),
        partial(_cupy_reducing_kernel, cupy),
        partial(_cufft_pair, cupy, cupyx.scipy.fft.get_fft_plan),
    )


def _cufft_pair(cupy, get_fft_plan, shape) -> RealFFTPair:
    """:class:`RealFFTPair` of cuFFT plans (D2Z and Z2D) for a float64 grid of ``shape``."""
    shape = tuple(int(s) for s in shape)
    real = cupy.empty(shape)
    spectrum = cupy.empty((shape[0], shape[1] // 2 + 1), dtype=np.complex128)
    forward_plan = get_fft_plan(real, value_type="R2C")
    inverse_plan = get_fft_plan(spectrum, shape=shape, value_type="C2R")
    cufft = cupy.cuda.cufft

    def forward(a, out):
        forward_plan.fft(a, out, cufft.CUFFT_FORWARD)

    def inverse(spec, out):
        inverse_plan.fft(spec, out, cufft.CUFFT_INVERSE)

    return RealFFTPair(forward, inverse)


def _cupy_kernel(cupy, source):
    """CuPy's element-wise kernel of ``source`` (a .device_sources.KernelSource)."""
    return cupy.ElementwiseKernel(
        source.in_params, source.out_params, source.body, source.name, preamble=source.preamble
    )


def _cupy_reducing_kernel(cupy, kernel):
    """The launcher of ``kernel`` (a .device_sources.ReducingKernel) on CuPy: its arguments
    in ``kernel.arguments()`` order (scalars as Python numbers, arrays flat and contiguous of
    the declared types and of one size, a broadcast one also a number or of one value);
    returns the ``(blocks, K)`` partials."""
    raw = cupy.RawKernel(kernel.cuda_source(), kernel.name)
    spec = kernel.arguments()
    count = len(kernel.reduced)
    ones = {}  # a broadcast number as a one-value device array, made once per value

    def broadcast(value, n):
        if not isinstance(value, cupy.ndarray):
            if float(value) not in ones:
                ones[float(value)] = cupy.full(1, float(value))
            value = ones[float(value)]
        return [value, np.int64(0 if value.size == 1 else 1)]

    def checked(a, t, name, sizes):
        # the kernel reads raw pointers: a wrong type, layout or size would read past the
        # array without an error
        if a.dtype != SCALAR_TYPES[t] or not a.flags.c_contiguous or a.size not in sizes:
            raise ValueError(
                f"{kernel.name}: {name} must be a C-contiguous {t} array of {sizes} "
                f"values, got {a.dtype} of {a.size} (contiguous: {a.flags.c_contiguous})"
            )
        return a

    def launch(*args):
        pairs = zip(spec, args, strict=True)
        n = next(a.size for (kind, _, _), a in pairs if kind in ("in", "out"))
        blocks = kernel.blocks(n)
        partials = cupy.empty((blocks, count))
        typed = []
        for (kind, t, name), a in zip(spec, args, strict=True):
            if kind == "scalar":
                typed.append(SCALAR_TYPES[t](a))
            elif kind == "broadcast":
                value, step = broadcast(a, n)
                typed += [checked(value, t, name, (1, n)), step]
            else:
                typed.append(checked(a, t, name, (n,)))
        raw((blocks,), (kernel.threads,), (np.int64(n), *typed, partials))
        return partials

    return launch
