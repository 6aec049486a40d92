"""Shared helpers for the solver benchmarks (timing, problems, table printing).

Benchmarks print tables; they are not tests. The machine is shared and noisy, so every
timing is the median of several runs and compared with a floor measured in the same run.
"""

from __future__ import annotations

import os
import sys

# The benchmarks time a plain process, as a user runs the solver (no thread environment
# variables): solve() bounds the native pools itself (threadpoolctl). `--pinned` pins
# OpenBLAS/OpenMP to one thread through the environment instead, before numpy is imported,
# for comparison with the tables measured that way (README); tables say which they are.
os.environ.update(
    dict.fromkeys(("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"), "1")
    if "--pinned" in sys.argv
    else {}
)

import argparse
import datetime
import platform
import statistics
import time

import numpy as np
import psutil

from amontons.contact import self_affine, sphere

PINNED = "--pinned" in sys.argv

# The periodic benchmark surface: Hurst 0.8, rms slope 0.1, mean pressure 0.005 E*
# (about 10 % contact by the κ ≈ 2 law, A/A0 = κ p̄ / (E* h')).
HURST, RMS_SLOPE, PBAR = 0.8, 0.1, 0.005
E_STAR = 1.0  # units are arbitrary but consistent; the solver is SI-agnostic in scale

# The benchmarks time the solver with measured FFT plans, passed explicitly as
# planner_effort=TIMING_EFFORT (the solver's default since 2026-11-24, FFTW_ESTIMATE before:
# tables measured before then ran the solver's own default on the explicit effort anyway).
# Plans are built before the timings.
TIMING_EFFORT = "FFTW_MEASURE"


def parser(description: str) -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--quick", action="store_true", help="small grids, a few seconds")
    ap.add_argument("--repeats", type=int, default=None, help="timing repeats (median)")
    ap.add_argument("--threads", type=int, default=1, help="FFTW threads")
    ap.add_argument("--sizes", type=int, nargs="*", default=None, help="grid sizes n (n x n)")
    ap.add_argument(
        "--pinned",
        action="store_true",
        help="pin OpenBLAS/OpenMP to 1 thread by the environment (default: a plain process)",
    )
    return ap


def header(title: str, args) -> None:
    print(f"# {title}")
    print(
        f"# {datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M UTC}, {platform.node()}, "
        f"{os.cpu_count()} cores, python {platform.python_version()}, numpy {np.__version__}, "
        f"threads={args.threads}, "
        + ("PINNED by environment (OPENBLAS/OMP/MKL_NUM_THREADS=1)" if PINNED else "plain process")
    )


# larger than the last-level cache (32 MB here): swept before a "cold" call
_FLUSH = np.zeros(128 * 2**20 // 8)


def evict_caches() -> None:
    """Sweep a 128 MB array, so that the next call meets its data in memory, as the
    transforms and sweeps inside a CG iteration do."""
    np.add(_FLUSH, 1.0, out=_FLUSH)


def median_time(fn, repeats: int, warmup: int = 1, cold: bool = False) -> float:
    """Median wall time of ``fn()`` over ``repeats`` calls after ``warmup`` calls, s;
    ``cold`` evicts the caches before each timed call (untimed)."""
    for _ in range(warmup):
        fn()
    ts = []
    for _ in range(repeats):
        if cold:
            evict_caches()
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


class HostSteal:
    """Share of this machine's CPU time the host took while a block ran, %: the steal time
    of a virtual machine (Linux's ``/proc/stat``, through psutil; 0 where the system does not
    count it), over all cores. A virtual CPU that is runnable while the host runs something
    else on it is stolen: a benchmark round with steal in it timed a smaller machine.

    ``with HostSteal() as steal: ...`` then ``steal.percent``.
    """

    percent = float("nan")

    def __enter__(self):
        self._before = psutil.cpu_times()
        return self

    def __exit__(self, *exc):
        after = psutil.cpu_times()
        total = sum(after) - sum(self._before)
        stolen = getattr(after, "steal", 0.0) - getattr(self._before, "steal", 0.0)
        self.percent = 100.0 * stolen / total if total > 0 else 0.0
        return False


def rough_surface(n: int, seed: int = 1) -> np.ndarray:
    """Periodic self-affine benchmark surface on n², spacing 1."""
    return self_affine((n, n), 1.0, HURST, rms_slope=RMS_SLOPE, rng=seed)


def rough_load(n: int) -> float:
    return PBAR * E_STAR * n * n


def sphere_problem(n: int, seed: int = 1):
    """Non-periodic rough sphere on n², spacing 1: contact radius ~n/5, edge-free."""
    radius = 4.0 * n
    a = n / 5
    h = sphere((n, n), 1.0, radius) + self_affine((n, n), 1.0, HURST, rms_height=0.5, rng=seed)
    return h, 4 * E_STAR * a**3 / (3 * radius)


def table(rows, columns) -> None:
    """Print a GitHub-markdown table."""
    print("| " + " | ".join(columns) + " |")
    print("|" + "|".join("---" for _ in columns) + "|")
    for r in rows:
        print("| " + " | ".join(_fmt(r.get(c, "")) for c in columns) + " |")


def _fmt(v):
    if isinstance(v, float):
        if v == 0 or 1e-3 <= abs(v) < 1e5:
            return f"{v:.3g}" if abs(v) < 100 else f"{v:.0f}"
        return f"{v:.2e}"
    return str(v)
