"""What a pass of slabs costs besides its transforms: the pool's dispatch (benchmarks/README.md,
"A second core").

A :class:`amontons.contact.fft.SlabTransform` on ``t`` threads runs its first slab on the
calling thread and hands the other ``t - 1`` to a pool of Python threads, each woken once
per pass. Here every slab is a tiny one-thread plan (8 columns of length 16, about 0.1 µs
of work), so a pass's time is its dispatch: hand-offs, wake-ups and the GIL the pool's
threads take in turn. Prints, per thread count, the median and 90th percentile of
``--calls`` passes, µs, and the dispatch per extra slab over the one-slab pass. Multiplied
by the passes of an iteration (four per convolution), it is what slabs add to a solve on
``t`` threads.

    python benchmarks/bench_slab_dispatch.py --thread-counts 1 2 4 8 16
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
from _common import header, table

from amontons.contact.fft import SlabTransform, empty

COLUMNS_PER_SLAB, LENGTH = 8, 16


def pass_times(threads: int, calls: int) -> list[float]:
    """Wall times, s, of ``calls`` passes of a tiny transform on ``threads`` slabs."""
    a = empty((LENGTH, COLUMNS_PER_SLAB * threads), np.complex128, "pyfftw")
    transform = SlabTransform(
        a, a, 0, threads=threads, min_points=1, planner_effort="FFTW_ESTIMATE"
    )
    if len(transform._plans) != threads:
        raise RuntimeError(f"{threads} threads made {len(transform._plans)} slabs")
    for _ in range(calls // 10):  # the pool's threads started and warm
        transform.execute()
    times = []
    for _ in range(calls):
        t0 = time.perf_counter()
        transform.execute()
        times.append(time.perf_counter() - t0)
    return times


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--thread-counts", type=int, nargs="*", default=[1, 2, 4, 8, 16])
    ap.add_argument("--calls", type=int, default=2000, help="passes timed per thread count")
    args = ap.parse_args()
    args.threads = "/".join(str(t) for t in args.thread_counts)
    header("Slab dispatch: one pass of tiny slabs", args)
    rows, one = [], None
    for threads in args.thread_counts:
        times = pass_times(threads, args.calls)
        median = statistics.median(times) * 1e6
        one = median if threads == 1 else one
        rows.append(
            {
                "threads": threads,
                "pass µs (median)": median,
                "pass µs (p90)": float(np.percentile(times, 90)) * 1e6,
                "µs per extra slab": (median - one) / (threads - 1)
                if one is not None and threads > 1
                else "",
            }
        )
    table(rows, list(rows[0]))


if __name__ == "__main__":
    main()
