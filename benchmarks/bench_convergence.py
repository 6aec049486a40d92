"""Benchmark 3: iterations and time to converge a periodic self-affine surface.

Surface: Hurst 0.8, rms slope 0.1, mean pressure 0.005 E* (~10 % contact), tol 1e-8.
Three variants on the same surface:

* ``PK reset-on-violator``: Polonsky & Keer's original rule, conjugation reset to steepest
  descent whenever any unloaded point penetrates (RESET_FRACTION = 0);
* ``this solver``: reset only when the penetrating points exceed 1 % of the contact set
  (the default);
* ``+ coarse-to-fine``: the default plus a start from the solution on 2x, 4x, ... coarser
  grids (coarse levels solved to 1e-4; their iterations are listed separately).

Times are medians over ``--repeats`` runs (plans are built before timing, with
``planner_effort="FFTW_MEASURE"`` passed explicitly: see _common.TIMING_EFFORT).

    python benchmarks/bench_convergence.py           # 512², 1024², 2048²
    python benchmarks/bench_convergence.py --quick   # 128², 256²
"""

from __future__ import annotations

import statistics
import sys
import time

from _common import E_STAR, TIMING_EFFORT, header, parser, rough_load, rough_surface, table

import amontons.contact.cg_iteration as cg_iteration
from amontons.contact import solve


def timed_solve(h, load, repeats, threads, **kw):
    ts, res = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = solve(
            h,
            1.0,
            E_STAR,
            load=load,
            periodic=True,
            tol=1e-8,
            threads=threads,
            planner_effort=TIMING_EFFORT,
            **kw,
        )
        ts.append(time.perf_counter() - t0)
    return res, statistics.median(ts)


def main():
    args = parser(__doc__.splitlines()[0]).parse_args()
    sizes = args.sizes or ([128, 256] if args.quick else [512, 1024, 2048])
    repeats = args.repeats or 3
    header("Benchmark 3: iterations to convergence, periodic self-affine surface", args)
    rows = []
    default_fraction = cg_iteration.RESET_FRACTION
    for n in sizes:
        h, load = rough_surface(n), rough_load(n)
        # build plans for all levels once, outside the timings
        solve(
            h,
            1.0,
            E_STAR,
            load=load,
            periodic=True,
            tol=1e-2,
            coarse_to_fine=True,
            threads=args.threads,
            planner_effort=TIMING_EFFORT,
        )
        variants = [
            ("PK reset-on-violator", 0.0, False),
            ("this solver", default_fraction, False),
            ("this solver + coarse-to-fine", default_fraction, True),
        ]
        for name, fraction, c2f in variants:
            cg_iteration.RESET_FRACTION = fraction
            try:
                reps = 1 if (fraction == 0.0 and n >= 2048) else repeats
                res, t = timed_solve(h, load, reps, args.threads, coarse_to_fine=c2f)
            finally:
                cg_iteration.RESET_FRACTION = default_fraction
            levels = res.info.coarse_levels
            rows.append(
                {
                    "grid": f"{n}²",
                    "variant": name,
                    "iterations": res.iterations,
                    "convolutions": res.info.convolutions,
                    "steepest-descent resets": res.info.steepest_descent_resets,
                    "coarse-level iterations": "+".join(str(lv.iterations) for lv in levels) or "-",
                    "time s": t,
                    "contact fraction": res.contact_fraction,
                }
            )
            print(rows[-1], file=sys.stderr, flush=True)
    table(rows, list(rows[0]))


if __name__ == "__main__":
    main()
