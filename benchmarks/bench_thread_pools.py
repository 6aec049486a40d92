"""Speed as a user gets it: a plain fresh process with no thread environment variables, against
the same process with every pool pinned to one thread by the environment (issue 21).

Each figure is the median over --repeats fresh processes of the second solve in the process
(the first builds FFT plans). Run: `.venv/bin/python benchmarks/bench_thread_pools.py`.
It sets each child's environment itself, so it does not import benchmarks/_common.py.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys

PINNED = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
THREAD_VARIABLES = (*PINNED, "NUMEXPR_NUM_THREADS", "VECLIB_MAXIMUM_THREADS")

# The periodic benchmark problem of benchmarks/README.md: Hurst 0.8, rms slope 0.1, mean
# pressure 0.005 E* (about 10 % contact), spacing 1, E* = 1.
CHILD = """
import sys, time
from amontons.contact import self_affine, solve
n, threads = int(sys.argv[1]), int(sys.argv[2])
h = self_affine((n, n), 1.0, 0.8, rms_slope=0.1, rng=1)
load = 0.005 * n * n
solve(h, 1.0, 1.0, load=load, periodic=True, threads=threads)
t0 = time.perf_counter()
solve(h, 1.0, 1.0, load=load, periodic=True, threads=threads)
print(time.perf_counter() - t0)
"""


def child_time(n: int, threads: int, pinned: bool) -> float:
    env = {k: v for k, v in os.environ.items() if k not in THREAD_VARIABLES}
    if pinned:
        env.update(PINNED)
    out = subprocess.run(
        [sys.executable, "-c", CHILD, str(n), str(threads)],
        env=env,
        capture_output=True,
        text=True,
        check=True,
    )
    return float(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="*", default=[512, 1024])
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    print(f"# plain vs pinned process, {os.cpu_count()} cores, medians of {args.repeats}")
    print(
        "| grid | plain, threads=1 (s) | pinned by env, threads=1 (s) | plain/pinned |"
        " plain, threads=2 (s) | threads=1 / threads=2 |"
    )
    print("|---|---|---|---|---|---|")
    for n in args.sizes:
        runs = {
            key: statistics.median(child_time(n, t, p) for _ in range(args.repeats))
            for key, (t, p) in {"plain": (1, False), "pinned": (1, True), "two": (2, False)}.items()
        }
        print(
            f"| {n}² | {runs['plain']:.3f} | {runs['pinned']:.3f} | "
            f"{runs['plain'] / runs['pinned']:.2f} | {runs['two']:.3f} | "
            f"{runs['plain'] / runs['two']:.2f} |"
        )


if __name__ == "__main__":
    main()
