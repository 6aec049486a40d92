"""The GPU route (backend="cupy", issue 39) against the CPU solver: time to solution.

For each grid, a load-controlled elastic solve (tol 1e-8, cold start) of the periodic
benchmark surface and of the non-periodic rough sphere (Hockney padding), on the CPU solver
(numba kernels, pyfftw, ``--threads``) and on the array kernel set of ``--backend``
(``cupy``: the GPU; ``numpy-array``: the same code on numpy, to try this script without a
GPU). Per solve: wall time (median of ``--repeats``, after one untimed solve that builds the
plans and compiles the fused kernels), iterations, ms per iteration, the speed-up, and the
largest pressure difference over the peak pressure with the contact sets compared. The
solve returns numpy arrays, so each timing includes the transfers to and from the device.

    python benchmarks/bench_gpu.py --sizes 1024 2048 4096           # on a GPU machine
    python benchmarks/bench_gpu.py --sizes 128 --backend numpy-array --repeats 1
"""

from __future__ import annotations

import time

import numpy as np
from _common import E_STAR, header, parser, rough_load, rough_surface, sphere_problem, table

from amontons.contact import solve


def _timed(repeats, **kw):
    """(median wall time s, the last result) of ``repeats`` solves after an untimed one."""
    result = solve(**kw)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = solve(**kw)
        times.append(time.perf_counter() - t0)
    return float(np.median(times)), result


def main() -> None:
    ap = parser(__doc__.splitlines()[0])
    ap.add_argument("--backend", default="cupy", choices=("cupy", "numpy-array"))
    args = ap.parse_args()
    sizes = args.sizes or ([128, 256] if args.quick else [1024, 2048])
    repeats = args.repeats or 3
    header(f"GPU route ({args.backend}) vs the CPU solver", args)
    rows = []
    for n in sizes:
        for bc in ("periodic", "padded"):
            if bc == "periodic":
                h, load = rough_surface(n), rough_load(n)
            else:
                h, load = sphere_problem(n)
            kw = {"heights": h, "spacing": 1.0, "e_star": E_STAR, "load": load}
            kw["periodic"] = bc == "periodic"
            t_cpu, cpu = _timed(repeats, threads=args.threads, **kw)
            t_dev, dev = _timed(repeats, backend=args.backend, **kw)
            peak = float(np.abs(cpu.pressure).max())
            rows.append(
                {
                    "grid": f"{n}²",
                    "bc": bc,
                    "CPU s": t_cpu,
                    "CPU iterations": cpu.iterations,
                    "CPU ms / it": 1e3 * t_cpu / cpu.iterations,
                    f"{args.backend} s": t_dev,
                    f"{args.backend} iterations": dev.iterations,
                    f"{args.backend} ms / it": 1e3 * t_dev / dev.iterations,
                    "speed-up": t_cpu / t_dev,
                    "max |Δp| / p_max": float(np.abs(dev.pressure - cpu.pressure).max()) / peak,
                    "same contact": bool(np.array_equal(cpu.pressure > 0, dev.pressure > 0)),
                }
            )
            print(rows[-1], flush=True)
    table(rows, list(rows[0]))


if __name__ == "__main__":
    main()
