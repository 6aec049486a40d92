"""Benchmark 1: time per CG iteration as a multiple of one FFT pair of the padded grid.

The floor is one forward + one inverse real 2-D FFT (pyfftw, same threads) of the grid the
convolution works on: n² periodic, (2n)² non-periodic (Hockney padding). Floor and
convolutions are planned with FFTW_MEASURE, passed explicitly (planner_effort=). Both are
measured in the same run, alternating, and the median of several runs
is quoted. The CG runs a fixed number of iterations on a realistic problem (rough periodic
surface at ~10 % contact; rough sphere for the non-periodic case), and the time spent inside
the convolutions is measured separately to say where the rest goes.

    python benchmarks/bench_iteration.py            # 1024², 2048²
    python benchmarks/bench_iteration.py --quick     # 256², 512²
"""

from __future__ import annotations

import statistics
import sys
import time

import numpy as np
from _common import (
    E_STAR,
    TIMING_EFFORT,
    header,
    parser,
    rough_load,
    rough_surface,
    sphere_problem,
    table,
)

from amontons.contact.cg import polonsky_keer
from amontons.contact.convolution import get_operator
from amontons.contact.fft import RealFFT2Pair


class TimedOperator:
    """Wraps a convolution operator and accumulates the time spent in it."""

    def __init__(self, op):
        self.op, self.seconds, self.periodic = op, 0.0, op.periodic

    def __call__(self, x, out=None):
        t0 = time.perf_counter()
        r = self.op(x, out=out)
        self.seconds += time.perf_counter() - t0
        return r


def run(n, periodic, iterations, repeats, threads):
    if periodic:
        h, load = rough_surface(n), rough_load(n)
    else:
        h, load = sphere_problem(n)
    op = get_operator(
        h.shape, 1.0, E_STAR, periodic=periodic, threads=threads, planner_effort=TIMING_EFFORT
    )
    fft_shape = h.shape if periodic else (2 * n, 2 * n)
    pair = RealFFT2Pair(fft_shape, threads=threads, planner_effort=TIMING_EFFORT)
    pair.real[...] = np.random.default_rng(0).random(pair.shape)
    # warm start: a few iterations first, so the timed ones are mid-solve iterations
    warm = polonsky_keer(
        op,
        h,
        pixel_area=1.0,
        h_scale=h.std(),
        p_init=np.ones_like(h),
        load=load,
        tol=1e-30,
        max_iter=20,
        raise_on_failure=False,
    )
    per_iter, pair_t, conv_share, conv_per_it = [], [], [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(5):
            pair()
        pair_t.append((time.perf_counter() - t0) / 5)
        timed = TimedOperator(op)
        t0 = time.perf_counter()
        out = polonsky_keer(
            timed,
            h,
            pixel_area=1.0,
            h_scale=h.std(),
            p_init=warm.pressure,
            load=load,
            tol=1e-30,
            max_iter=iterations,
            raise_on_failure=False,
        )
        dt = time.perf_counter() - t0
        per_iter.append(dt / iterations)
        conv_share.append(timed.seconds / dt)
        conv_per_it.append(out.convolutions / iterations)
    it_t, fl_t = statistics.median(per_iter), statistics.median(pair_t)
    ratios = [a / b for a, b in zip(per_iter, pair_t, strict=True)]
    return {
        "grid": f"{n}²",
        "bc": "periodic" if periodic else "non-periodic",
        "FFT grid": f"{h.shape[0] * (1 if periodic else 2)}²",
        "iteration ms": it_t * 1e3,
        "FFT pair ms": fl_t * 1e3,
        "ratio (median of per-run ratios)": statistics.median(ratios),
        "convolutions / iteration": statistics.median(conv_per_it),
        "share in convolutions": statistics.median(conv_share),
    }


def main():
    args = parser(__doc__.splitlines()[0]).parse_args()
    sizes = args.sizes or ([256, 512] if args.quick else [1024, 2048])
    repeats = args.repeats or (3 if args.quick else 5)
    header("Benchmark 1: CG iteration time / FFT pair", args)
    rows = []
    for n in sizes:
        for periodic in (True, False):
            iterations = 20 if n <= 1024 else 10
            rows.append(run(n, periodic, iterations, repeats, args.threads))
            print(rows[-1], file=sys.stderr, flush=True)
    cols = list(rows[0])
    table(rows, cols)


if __name__ == "__main__":
    main()
