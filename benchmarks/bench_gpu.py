"""The GPU route (backend="cupy", issue 39) against the CPU solver: time to solution.

For each grid and each law of ``--laws``, a load-controlled solve (tol 1e-8, cold start) of
the periodic benchmark surface and of the non-periodic rough sphere (Hockney padding):
``elastic``, or ``hardness``, penetration hardness p_y = HARDNESS·E* (a share of the
contact then sits at p_y: the row's "at p_y" column), on the CPU solver
(numba kernels, pyfftw, ``--threads``) and on the array kernel set of ``--backend``
(``cupy``: the GPU, its iteration's kernels as CUDA kernels that take their sums;
``cupy-terms``: the previous kernels, their terms summed by CuPy; ``cupy-array``: the GPU,
the array code alone; ``numpy-array``: the array code on numpy, to try this script without
a GPU). Per solve: wall time (median of ``--repeats``, after
one untimed solve that builds the plans and compiles the fused kernels), iterations, ms per
iteration and its ratio to one
forward + inverse real FFT of the convolution's grid on the same backend (a cuFFT pair on a
GPU: n² periodic, the Hockney grid padded), the speed-up, and the
largest pressure difference over the peak pressure with the contact sets compared. The
solve returns numpy arrays, so each timing includes the transfers to and from the device.
``--device-only`` times the device alone (for grids whose CPU solve would take minutes).

    python benchmarks/bench_gpu.py --sizes 1024 2048 4096           # on a GPU machine
    python benchmarks/bench_gpu.py --sizes 512 2048 --laws elastic hardness
    python benchmarks/bench_gpu.py --sizes 4096 --device-only
    python benchmarks/bench_gpu.py --sizes 128 --backend numpy-array --repeats 1
"""

from __future__ import annotations

import itertools
import time
from pathlib import Path

import numpy as np
from _common import E_STAR, header, parser, rough_load, rough_surface, sphere_problem, table

import amontons
from amontons.contact import PenetrationHardness, solve
from amontons.contact.array_backends import array_module
from amontons.contact.convolution import fast_padded_shape

# Penetration hardness of the "hardness" rows, in E*: above the periodic surface's mean
# pressure (0.005 E*) and the sphere's Hertz peak (2a/(πR) E* = 0.032 E*), below the local
# peaks that the roughness raises, so that part of the contact, not all of it, is plastic.
HARDNESS = 0.05


def _timed(repeats, **kw):
    """(median wall time s, the last result) of ``repeats`` solves after an untimed one."""
    result = solve(**kw)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = solve(**kw)
        times.append(time.perf_counter() - t0)
    return float(np.median(times)), result


def fft_pair_seconds(backend: str, shape, repeats: int) -> float:
    """Median wall time (s) of one real forward + inverse 2-D FFT of ``shape`` on the array
    backend, the device synchronised after each: the backend's planned transforms where it
    has them (``ArrayModule.fft_pair``: cuFFT's plans run directly, what its convolution
    calls), else ``xp.fft``."""
    module = array_module(backend)
    xp = module.xp
    runtime = getattr(getattr(xp, "cuda", None), "runtime", None)  # CuPy's; none on numpy
    a = xp.asarray(np.random.default_rng(0).random(shape))
    planned = getattr(module, "fft_pair", None)  # None too in a tree from before it
    if planned is not None:
        fft = planned(shape)
        spectrum = xp.empty((shape[0], shape[1] // 2 + 1), dtype=np.complex128)
        back = xp.empty(shape)

        def transforms():
            fft.forward(a, spectrum)
            fft.inverse(spectrum, back)
    else:

        def transforms():
            xp.fft.irfft2(xp.fft.rfft2(a), s=shape)

    def pair():
        transforms()
        if runtime is not None:
            runtime.deviceSynchronize()

    pair()  # plans
    times = []
    for _ in range(max(repeats, 5)):
        t0 = time.perf_counter()
        pair()
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def main() -> None:
    ap = parser(__doc__.splitlines()[0])
    # cupy-terms, cupy-array: the route's earlier versions on the GPU, its baselines
    ap.add_argument(
        "--backend", default="cupy", choices=("cupy", "cupy-terms", "cupy-array", "numpy-array")
    )
    ap.add_argument("--device-only", action="store_true", help="no CPU solve to compare with")
    ap.add_argument(
        "--cpu-repeats", type=int, default=None, help="CPU solves timed (default: --repeats)"
    )
    ap.add_argument(
        "--laws", nargs="*", default=["elastic"], choices=("elastic", "hardness"), help="laws"
    )
    args = ap.parse_args()
    sizes = args.sizes or ([128, 256] if args.quick else [1024, 2048])
    repeats = args.repeats or 3
    header(f"GPU route ({args.backend}) vs the CPU solver", args)
    print(f"# amontons from {Path(amontons.__file__).parent}")  # the tree measured
    rows = []
    for n in sizes:
        for bc, law in itertools.product(("periodic", "padded"), args.laws):
            if bc == "periodic":
                h, load = rough_surface(n), rough_load(n)
            else:
                h, load = sphere_problem(n)
            kw = {"heights": h, "spacing": 1.0, "e_star": E_STAR, "load": load}
            kw["periodic"] = bc == "periodic"
            if law == "hardness":
                kw["plasticity"] = PenetrationHardness(p_y=HARDNESS * E_STAR)
            t_dev, dev = _timed(repeats, backend=args.backend, **kw)
            fft_shape = (n, n) if bc == "periodic" else fast_padded_shape((n, n))
            t_pair = fft_pair_seconds(args.backend, fft_shape, repeats)
            row = {
                "grid": f"{n}²",
                "bc": bc,
                "law": law,
                "at p_y": _share_at_hardness(dev.pressure) if law == "hardness" else "-",
                f"{args.backend} s": t_dev,
                f"{args.backend} iterations": dev.iterations,
                f"{args.backend} ms / it": 1e3 * t_dev / dev.iterations,
                "FFT pair ms": 1e3 * t_pair,
                "it / pair": t_dev / dev.iterations / t_pair,
            }
            if not args.device_only:
                row.update(_against_cpu(args.cpu_repeats or repeats, args.threads, kw, t_dev, dev))
            rows.append(row)
            print(rows[-1], flush=True)
    table(rows, list(rows[0]))


def _share_at_hardness(pressure: np.ndarray) -> float:
    """The share of the contact whose pressure is at the hardness (to 1e-9 of it)."""
    contact = pressure > 0
    return float(np.mean(pressure[contact] >= HARDNESS * E_STAR * (1 - 1e-9)))


def _against_cpu(repeats, threads, kw, t_dev, dev) -> dict:
    """The CPU solve's time (s) and iterations, the speed-up (CPU time over ``t_dev``, s) and
    the answers' difference (over the CPU's peak pressure)."""
    t_cpu, cpu = _timed(repeats, threads=threads, **kw)
    peak = float(np.abs(cpu.pressure).max())
    return {
        "CPU s": t_cpu,
        "CPU iterations": cpu.iterations,
        "CPU ms / it": 1e3 * t_cpu / cpu.iterations,
        "speed-up": t_cpu / t_dev,
        "max |Δp| / p_max": float(np.abs(dev.pressure - cpu.pressure).max()) / peak,
        "same contact": bool(np.array_equal(cpu.pressure > 0, dev.pressure > 0)),
    }


if __name__ == "__main__":
    main()
