"""Benchmark 5: peak memory per grid point of one solve.

Each case runs in a fresh subprocess; the peak resident set size (``ru_maxrss``) of that
process minus the baseline of an identical process that only imports the solver and builds
the height field gives the memory the solve itself needs. tracemalloc peaks (numpy
allocations only; FFTW work arrays from pyfftw are numpy arrays too) are quoted alongside.
Nothing is timed, so the solve uses the solver's default planner effort (FFTW_ESTIMATE until
2026-11-24, FFTW_MEASURE since), as the pipeline does.

    python benchmarks/bench_memory.py           # 1024², 2048²
    python benchmarks/bench_memory.py --quick   # 256², 512²
"""

from __future__ import annotations

import json
import subprocess
import sys

from _common import header, parser, table

CHILD = r"""
import json, resource, sys, tracemalloc
sys.path.insert(0, {bench!r})
from _common import rough_surface, rough_load, sphere_problem, E_STAR
from amontons.contact import solve
n, periodic, do_solve = {n}, {periodic}, {do_solve}
if periodic:
    h, load = rough_surface(n), rough_load(n)
else:
    h, load = sphere_problem(n)
tracemalloc.start()
base = tracemalloc.get_traced_memory()[0]
if do_solve:
    res = solve(h, 1.0, E_STAR, load=load, periodic=periodic, tol=1e-6, threads={threads})
peak = tracemalloc.get_traced_memory()[1] - base
print(json.dumps({{"maxrss_kb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss,
                  "tracemalloc_peak": peak}}))
"""


def child(n, periodic, do_solve, threads, bench_dir):
    code = CHILD.format(bench=bench_dir, n=n, periodic=periodic, do_solve=do_solve, threads=threads)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main():
    import os

    args = parser(__doc__.splitlines()[0]).parse_args()
    sizes = args.sizes or ([256, 512] if args.quick else [1024, 2048])
    header("Benchmark 5: peak memory per grid point", args)
    bench_dir = os.path.dirname(os.path.abspath(__file__))
    rows = []
    for n in sizes:
        for periodic in (True, False):
            base = child(n, periodic, False, args.threads, bench_dir)
            run = child(n, periodic, True, args.threads, bench_dir)
            rss = (run["maxrss_kb"] - base["maxrss_kb"]) * 1024
            rows.append(
                {
                    "grid": f"{n}²",
                    "bc": "periodic" if periodic else "non-periodic",
                    "peak RSS increase MB": rss / 2**20,
                    "bytes / grid point (RSS)": rss / n**2,
                    "tracemalloc peak MB": run["tracemalloc_peak"] / 2**20,
                    "bytes / grid point (tracemalloc)": run["tracemalloc_peak"] / n**2,
                    "float64 arrays / point": run["tracemalloc_peak"] / n**2 / 8,
                }
            )
    table(rows, list(rows[0]))


if __name__ == "__main__":
    main()
