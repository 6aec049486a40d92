"""The GPU kernel set's CUDA sources (amontons.contact.device_sources) compiled as C++ on the
CPU, so that CI, without a GPU, runs the kernels' arithmetic against the array code.

:func:`harness_module` is an :class:`~amontons.contact.array_backends.ArrayModule` on numpy
whose ``compile`` builds each source into a C++ function (g++) called as CuPy calls its
element-wise kernels: inputs, then outputs; a scalar or a length-1 array broadcasts; the
function loops over the points with each parameter bound to its element by reference
(``const`` for the inputs), as CuPy binds them, so an input that is also an output reads
what the body wrote. Array arguments must have the declared dtype exactly, as CuPy's kernels
with concrete types require; Python numbers are converted. Compiled with
``-ffp-contract=off``: no multiply-add is fused on any CPU, so the C++ evaluates each
expression as numpy does. Its ``compile_reducing`` builds each reducing kernel into a
function that folds the sums in the order its CUDA launch does (:func:`c_reducing_function`).
"""

from __future__ import annotations

import ctypes
import hashlib
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from amontons.contact.array_backends import SCALAR_TYPES, ArrayModule
from amontons.contact.device_sources import MAX_HELPER, REDUCE_BLOCK, reduce_blocks

TYPES = {
    "float64": ("double", np.float64),
    "uint8": ("unsigned char", np.uint8),
    "int8": ("signed char", np.int8),
    "int32": ("int", np.int32),
    "int64": ("long long", np.int64),
}
PRELUDE = """
#include <cmath>
#define __device__
using std::fabs;
using std::fmax;
using std::fmin;
"""
COMPILER = shutil.which("g++")


def _params(text: str) -> list[tuple[str, str]]:
    """``(type, name)`` per parameter; a ``raw`` one (a whole array) as ``("raw float64",
    name)``."""
    return [(" ".join(p.split()[:-1]), p.split()[-1]) for p in text.split(",")]


def _raw(type_name: str) -> str | None:
    """The element type of a ``raw`` parameter, else None."""
    return type_name.split()[1] if type_name.startswith("raw ") else None


def c_function(source) -> str:
    """The C++ function of a ``KernelSource``: ``name(n, inputs..., outputs...)``; a ``raw``
    input is the whole array, indexed by the body (with ``i``, the point's index)."""
    ins, outs = _params(source.in_params), _params(source.out_params)
    args = ["long long n"] + [f"const {TYPES[_raw(t) or t][0]}* {n}{'' if _raw(t) else '_'}"
                              for t, n in ins]  # fmt: skip
    args += [f"{TYPES[t][0]}* {n}_" for t, n in outs]
    loads = " ".join(f"const {TYPES[t][0]}& {n} = {n}_[i];" for t, n in ins if not _raw(t))
    refs = " ".join(f"{TYPES[t][0]}& {n} = {n}_[i];" for t, n in outs)
    loop = f"for (long long i = 0; i < n; ++i) {{ {loads} {refs} {source.body} }}"
    return f'extern "C" void {source.name}({", ".join(args)}) {{ {loop} }}'


class HarnessKernel:
    """A compiled source, called as CuPy's kernel of it."""

    def __init__(self, library: ctypes.CDLL, source):
        self.source = source
        self.ins = _params(source.in_params)
        self.outs = _params(source.out_params)
        self.fn = getattr(library, source.name)

    def __call__(self, *args):
        n_in = len(self.ins)
        inputs, outputs = args[:n_in], args[n_in:]
        assert len(outputs) == len(self.outs), self.source.name
        n = max(
            np.size(a) for (t, _), a in zip(self.ins + self.outs, args, strict=True) if not _raw(t)
        )
        arrays = [
            self._whole(a, _raw(t)) if _raw(t) else self._input(a, t, n)
            for (t, _), a in zip(self.ins, inputs, strict=True)
        ]
        for (t, name), out in zip(self.outs, outputs, strict=True):
            assert out.dtype == TYPES[t][1] and out.size == n, (self.source.name, name)
            assert out.flags.c_contiguous, (self.source.name, name)
        pointers = [a.ctypes.data_as(ctypes.c_void_p) for a in (*arrays, *outputs)]
        self.fn(ctypes.c_longlong(n), *pointers)
        return outputs

    def _whole(self, value, type_name: str) -> np.ndarray:
        """A ``raw`` input: the array as it is, of the declared type and contiguous."""
        assert value.dtype == TYPES[type_name][1] and value.flags.c_contiguous, self.source.name
        return value

    def _input(self, value, type_name: str, n: int) -> np.ndarray:
        dtype = TYPES[type_name][1]
        if isinstance(value, np.ndarray):
            assert value.dtype == dtype, (self.source.name, value.dtype, type_name)
        else:
            assert isinstance(value, int | float), (self.source.name, type(value))
        return np.ascontiguousarray(np.broadcast_to(np.asarray(value, dtype=dtype), (n,)))


_LIBRARIES: dict[str, ctypes.CDLL] = {}


def _library(code: str) -> ctypes.CDLL:
    """``code`` compiled with g++ (cached per text for the session)."""
    key = hashlib.sha256(code.encode()).hexdigest()[:16]
    if key not in _LIBRARIES:
        folder = Path(tempfile.mkdtemp(prefix="amontons-harness-"))
        (folder / "k.cpp").write_text(code)
        subprocess.run(
            [COMPILER, "-O2", "-ffp-contract=off", "-shared", "-fPIC", "-o", "k.so", "k.cpp"],
            cwd=folder,
            check=True,
            capture_output=True,
        )
        _LIBRARIES[key] = ctypes.CDLL(str(folder / "k.so"))
    return _LIBRARIES[key]


def compile_source(source) -> HarnessKernel:
    """``source`` compiled with g++."""
    return HarnessKernel(_library(PRELUDE + source.preamble + c_function(source) + "\n"), source)


def c_reducing_function(kernel) -> str:
    """The C++ function of a ``ReducingKernel`` that computes what its CUDA launch does
    (amontons.contact.device_sources.cuda_source), the threads of each block in turn: each
    thread ``tid`` of block ``b`` folds its points ``b·B + tid + k·blocks·B`` in order, then
    the block's tree folds the slots level by level, as the barriers order them on a GPU.
    The points' bodies are independent, so running them in another order changes nothing."""
    b = REDUCE_BLOCK
    return f"""
extern "C" void {kernel.name}({kernel.signature(extra="const long long blocks")}) {{
    static double shared[{len(kernel.reduced) * b}];
    for (long long block = 0; block < blocks; ++block) {{
        for (unsigned int tid = 0; tid < {b}; ++tid) {{
            {kernel.initial()}
            for (long long i = block * {b} + tid; i < n; i += blocks * {b}) {{
{kernel.point_code()}
            }}
            {kernel.block_store()}
        }}
        for (unsigned int s = {b // 2}; s > 0; s >>= 1) {{
            for (unsigned int tid = 0; tid < s; ++tid) {{ {kernel.tree_step()} }}
        }}
        {kernel.block_result("block")}
    }}
}}
"""


CTYPES = {"float64": ctypes.c_double, "int32": ctypes.c_int, "uint8": ctypes.c_ubyte,
          "int8": ctypes.c_byte}  # fmt: skip


def compile_reducing(kernel):
    """A ``ReducingKernel`` compiled with g++, called as the CuPy launcher is
    (amontons.contact.array_backends): its arguments, then its ``(blocks, K)`` partials back."""
    code = PRELUDE + kernel.source.preamble + MAX_HELPER + c_reducing_function(kernel)
    fn = getattr(_library(code), kernel.name)
    spec = kernel.arguments()

    def launch(*args):
        arrays = [a for (kind, _, _), a in zip(spec, args, strict=True) if kind in ("in", "out")]
        n = arrays[0].size
        converted, held = [], []  # held: the arrays made here, alive through the call
        for (kind, t, name), a in zip(spec, args, strict=True):
            if kind == "scalar":
                assert isinstance(a, int | float), (kernel.name, name, type(a))
                converted.append(CTYPES[t](SCALAR_TYPES[t](a)))
                continue
            if kind == "broadcast":
                a = np.full(1, float(a)) if isinstance(a, int | float) else a
                held.append(a)
                step = 0 if a.size == 1 else 1
                assert a.dtype == TYPES[t][1] and a.size in (1, n), (kernel.name, name)
                converted += [a.ctypes.data_as(ctypes.c_void_p), ctypes.c_longlong(step)]
                continue
            assert a.dtype == TYPES[t][1] and a.size == n, (kernel.name, name)
            assert a.flags.c_contiguous, (kernel.name, name)
            converted.append(a.ctypes.data_as(ctypes.c_void_p))
        blocks = reduce_blocks(n)
        partials = np.empty((blocks, len(kernel.reduced)))
        fn(ctypes.c_longlong(n), ctypes.c_longlong(blocks), *converted,
           partials.ctypes.data_as(ctypes.c_void_p))  # fmt: skip
        return partials

    return launch


def harness_module() -> ArrayModule:
    """numpy, with the CUDA sources compiled as C++ (module docstring)."""
    return ArrayModule(
        "numpy-harness",
        np,
        np.asarray,
        np.add.at,
        lambda fn: fn,
        compile_source,
        compile_reducing,
    )
