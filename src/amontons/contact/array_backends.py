"""The array namespaces the array kernel set runs on (:mod:`.array_kernels`): CuPy on a GPU
(``backend="cupy"``, the optional extra ``pip install amontons[gpu]``), or numpy, which runs
the same array code on the CPU so that CI, without a GPU, tests its logic.

``ARRAY_BACKENDS`` are the ``backend`` names of :func:`amontons.contact.solve` that select
the array set: ``"cupy"``, ``"numpy-array"`` (for tests: the GPU route's code on numpy
arrays, which the numba set outruns on a CPU) and ``"cupy-array"`` (for benchmarks: the
array code on the GPU without its CUDA kernels, the baseline those kernels are timed
against on the same device).

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
ARRAY_BACKENDS = (CUPY, NUMPY_ARRAY, CUPY_ARRAY)
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
    namespace runs no CUDA source (numpy: the array set then runs its array code).
    """

    name: str
    xp: object
    to_host: object
    add_at: object
    fuse: object
    compile: object = None


def _identity(fn):
    return fn


NUMPY = ArrayModule(NUMPY_ARRAY, np, np.asarray, np.add.at, _identity)


def array_module(name: str) -> ArrayModule:
    """The :class:`ArrayModule` of backend ``name`` (one of :data:`ARRAY_BACKENDS`).

    Raises
    ------
    BackendUnavailableError
        ``"cupy"`` or ``"cupy-array"`` without CuPy or without a CUDA device.
    ValueError
        Another name.
    """
    if name == NUMPY_ARRAY:
        return NUMPY
    if name == CUPY:
        return _load_cupy()
    if name == CUPY_ARRAY:
        return replace(_load_cupy(), name=CUPY_ARRAY, compile=None)
    raise ValueError(f"unknown array backend {name!r}; expected one of {ARRAY_BACKENDS}")


@lru_cache(maxsize=1)
def _load_cupy() -> ArrayModule:
    try:
        # the optional dependency, imported only when a solve asks for it (module docstring)
        import cupy
        import cupyx
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
        CUPY, cupy, cupy.asnumpy, cupyx.scatter_add, cupy.fuse, partial(_cupy_kernel, cupy)
    )


def _cupy_kernel(cupy, source):
    """CuPy's element-wise kernel of ``source`` (a .device_sources.KernelSource)."""
    return cupy.ElementwiseKernel(
        source.in_params, source.out_params, source.body, source.name, preamble=source.preamble
    )
