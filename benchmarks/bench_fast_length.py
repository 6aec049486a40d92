"""Fast FFT lengths: non-periodic convolution and CG iteration, padded to 2n vs to fast m >= 2n.

The Hockney-padded operator used to work on exactly 2n × 2n; it now pads each axis to
``fast_length(2n)`` (:func:`amontons.contact.fft.fast_length`), which gives the same field
to round-off. For each window n this times, on one thread with the solver's default
planner effort (FFTW_MEASURE since 2026-11-24, FFTW_ESTIMATE when the README's table was
measured; ``--effort`` to change it):

* one pruned convolution (ms), calls alternating between the 2n operator ("before") and
  the fast one ("after"), median of ``--repeats`` rounds of 3 calls each;
* one CG iteration (ms) of the elastic rough-sphere benchmark problem (``_common``, fused
  path, load control), from the first ``--iterations`` iterations of a cold-started solve
  (the two operators take the same steps, so the iteration mix is the same), alternating
  before / after, median of ``--repeats``.

It also prints the largest difference between the two operators' fields (relative to the
peak) and between the two truncated solves' pressures.

    python benchmarks/bench_fast_length.py                  # 428 461 922 1536 1844 1848
    python benchmarks/bench_fast_length.py --quick          # 107 212
    python benchmarks/bench_fast_length.py --sizes 428 1844 --repeats 5
"""

from __future__ import annotations

import statistics
import time

import numpy as np
from _common import E_STAR, header, parser, sphere_problem, table

from amontons.contact.cg import polonsky_keer
from amontons.contact.convolution import NonPeriodicConvolution
from amontons.contact.fft import DEFAULT_PLANNER_EFFORT
from amontons.contact.options import CGOptions
from amontons.contact.pools import solve_pools


def factorise(m: int) -> str:
    """``m`` as a product of primes, e.g. 3688 -> '2³·461'."""
    sup = str.maketrans("0123456789", "⁰¹²³⁴⁵⁶⁷⁸⁹")
    parts, f = [], 2
    while f * f <= m:
        k = 0
        while m % f == 0:
            m, k = m // f, k + 1
        if k:
            parts.append(f"{f}{str(k).translate(sup) if k > 1 else ''}")
        f += 1
    if m > 1:
        parts.append(str(m))
    return "·".join(parts)


def solve_time(op, h, load, iterations, threads):
    """Wall time per iteration (s) of the first ``iterations`` CG iterations, and the
    result."""
    t0 = time.perf_counter()
    with solve_pools(threads):  # as amontons.contact.solve does (run holds them too)
        out = polonsky_keer(
            op,
            h,
            CGOptions(tol=1e-8, max_iter=iterations, raise_on_failure=False, threads=threads),
            pixel_area=1.0,
            h_scale=h.std(),
            p_init=np.ones_like(h),
            load=load,
        )
    return (time.perf_counter() - t0) / out.iterations, out


def run(n, args):
    """One row, planned and timed under the pools a solve on ``args.threads`` holds."""
    with solve_pools(args.threads):
        return _measure(n, args)


def _measure(n, args):
    kw = {"threads": args.threads, "planner_effort": args.effort}
    before = NonPeriodicConvolution((n, n), 1.0, E_STAR, padded_shape=(2 * n, 2 * n), **kw)
    after = NonPeriodicConvolution((n, n), 1.0, E_STAR, **kw)
    p = np.random.default_rng(0).random((n, n))
    out = np.empty((n, n))
    ub, ua = before(p), after(p)
    field_diff = np.abs(ua - ub).max() / np.abs(ub).max()
    conv = {before: [], after: []}
    for _ in range(args.repeats):
        for op in (before, after):
            t0 = time.perf_counter()
            for _ in range(3):
                op(p, out=out)
            conv[op].append((time.perf_counter() - t0) / 3)
    h, load = sphere_problem(n)
    iters = {before: [], after: []}
    results = {}
    for _ in range(args.repeats):
        for op in (before, after):
            dt, res = solve_time(op, h, load, args.iterations, args.threads)
            iters[op].append(dt)
            results[op] = res
    pb, pa = results[before].pressure, results[after].pressure
    m = after.padded_shape[0]
    tb, ta = statistics.median(conv[before]), statistics.median(conv[after])
    ib, ia = statistics.median(iters[before]), statistics.median(iters[after])
    return {
        "window": f"{n}²",
        "2n": f"{2 * n} = {factorise(2 * n)}",
        "fast m": f"{m} = {factorise(m)}",
        "conv. 2n ms": tb * 1e3,
        "conv. m ms": ta * 1e3,
        "conv. speed-up": tb / ta,
        "CG it. 2n ms": ib * 1e3,
        "CG it. m ms": ia * 1e3,
        "CG speed-up": ib / ia,
        "iterations": results[after].iterations,
        "field rel. diff": field_diff,
        "pressure rel. diff": float(np.abs(pa - pb).max() / np.abs(pb).max()),
    }


def main():
    ap = parser(__doc__.splitlines()[0])
    ap.add_argument("--iterations", type=int, default=None, help="CG iterations timed")
    ap.add_argument("--effort", default=DEFAULT_PLANNER_EFFORT, help="FFTW planner effort")
    args = ap.parse_args()
    args.sizes = args.sizes or ([107, 212] if args.quick else [428, 461, 922, 1536, 1844, 1848])
    args.repeats = args.repeats or (3 if args.quick else 5)
    args.iterations = args.iterations or (10 if args.quick else 8)
    header(f"Fast FFT lengths, planner {args.effort}", args)
    rows = []
    for n in args.sizes:
        rows.append(run(n, args))
        print(rows[-1], flush=True)
    table(rows, list(rows[0]))


if __name__ == "__main__":
    main()
