"""Benchmark 2: pruned non-periodic convolution vs the plain 2n x 2n FFT convolution.

Both operators use pyfftw plans (FFTW_MEASURE, passed explicitly; same threads), the same
real kernel spectrum and the same multiply; they differ only in the transforms: the pruned
one does the row transforms on the n non-zero rows (forward) and on the n wanted rows
(inverse) only.
Ideal speed-up of the FFT work: 4/3. Calls alternate between the two operators, and the
median of the per-round ratios is quoted.

    python benchmarks/bench_pruned.py           # 1024², 2048²
    python benchmarks/bench_pruned.py --quick   # 256², 512²
"""

from __future__ import annotations

import statistics
import time

import numpy as np
from _common import E_STAR, TIMING_EFFORT, header, parser, table

from amontons.contact.convolution import NonPeriodicConvolution


def main():
    args = parser(__doc__.splitlines()[0]).parse_args()
    sizes = args.sizes or ([256, 512] if args.quick else [1024, 2048])
    repeats = args.repeats or (5 if args.quick else 9)
    header("Benchmark 2: pruned vs plain non-periodic convolution", args)
    rows = []
    for n in sizes:
        p = np.random.default_rng(0).random((n, n))
        kw = {"threads": args.threads, "planner_effort": TIMING_EFFORT}
        pruned = NonPeriodicConvolution((n, n), 1.0, E_STAR, pruned=True, **kw)
        plain = NonPeriodicConvolution((n, n), 1.0, E_STAR, pruned=False, **kw)
        out = np.empty((n, n))
        err = np.abs(pruned(p) - plain(p)).max() / np.abs(plain(p)).max()
        tp, tf = [], []
        for _ in range(repeats):
            for op, acc in ((pruned, tp), (plain, tf)):
                t0 = time.perf_counter()
                op(p, out=out)
                acc.append(time.perf_counter() - t0)
        ratios = [b / a for a, b in zip(tp, tf, strict=True)]
        rows.append(
            {
                "grid": f"{n}²",
                "padded": f"{2 * n}²",
                "pruned ms": statistics.median(tp) * 1e3,
                "plain ms": statistics.median(tf) * 1e3,
                "speed-up (median of ratios)": statistics.median(ratios),
                "min / max ratio": f"{min(ratios):.2f} / {max(ratios):.2f}",
                "max rel. difference": err,
            }
        )
    table(rows, list(rows[0]))


if __name__ == "__main__":
    main()
