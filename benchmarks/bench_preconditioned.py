"""Benchmark 3b: the preconditioned bound-constrained CG against Polonsky and Keer's.

The periodic self-affine surface of benchmark 3 (Hurst 0.8, rms slope 0.1, mean pressure
0.005 E*, ~10 % contact), tol 1e-8, one thread, elastic and penetration hardness at
p_Y = 0.1 E*. Per size and law the two iterations run alternately (PK, preconditioned, PK,
...) after one untimed solve each that builds the plans; the table gives each one's
iterations, FFT pairs (``info.convolutions``), median time, the time ratio, and how far the
two answers lie apart (contact pixels that differ, largest pressure difference over the
peak). ``--near-full`` adds the surface pressed to 50, 80 and 95 % contact.

    python benchmarks/bench_preconditioned.py                      # 512² ... 2048²
    python benchmarks/bench_preconditioned.py --sizes 4096 --repeats 1
    python benchmarks/bench_preconditioned.py --quick --near-full  # 128², 256²
"""

from __future__ import annotations

import statistics
import time

import numpy as np
from _common import E_STAR, TIMING_EFFORT, header, parser, rough_load, rough_surface, table

from amontons.contact import PenetrationHardness, solve

ITERATIONS = ("polonsky-keer", "preconditioned")
# Mean pressure / (E* h'_rms) that presses the 512² surface to 50, 80 and 95 % contact
# (measured with this script's --near-full; the fraction each reached is printed).
NEAR_FULL = {"50 %": 0.25, "80 %": 0.55, "95 %": 0.9}


def _solve(h, load, iteration, law, threads):
    return solve(
        h,
        1.0,
        E_STAR,
        load=load,
        periodic=True,
        tol=1e-8,
        threads=threads,
        planner_effort=TIMING_EFFORT,
        plasticity=law,
        iteration=iteration,
    )


def _alternated(h, load, law, repeats, threads):
    """Each iteration's last result and median time, run alternately."""
    times = {name: [] for name in ITERATIONS}
    results = {name: _solve(h, load, name, law, threads) for name in ITERATIONS}  # plans
    for _ in range(repeats):
        for name in ITERATIONS:
            t0 = time.perf_counter()
            results[name] = _solve(h, load, name, law, threads)
            times[name].append(time.perf_counter() - t0)
    return results, {name: statistics.median(ts) for name, ts in times.items()}


def _row(n, what, results, medians):
    pk, pc = results["polonsky-keer"], results["preconditioned"]
    peak = float(pk.pressure.max())
    return {
        "n": n,
        "case": what,
        "contact": round(pk.contact_fraction, 3),
        "PK it": pk.iterations,
        "PC it": pc.iterations,
        "PK pairs": pk.info.convolutions,
        "PC pairs": pc.info.convolutions,
        "PK s": medians["polonsky-keer"],
        "PC s": medians["preconditioned"],
        "PK/PC time": medians["polonsky-keer"] / medians["preconditioned"],
        "set diff px": int(np.count_nonzero(pk.contact != pc.contact)),
        "max |dp|/peak": f"{float(np.abs(pk.pressure - pc.pressure).max()) / peak:.1e}",
    }


def main():
    ap = parser(__doc__.splitlines()[0])
    ap.add_argument("--near-full", action="store_true", help="add 50/80/95 %% contact")
    args = ap.parse_args()
    sizes = args.sizes or ([128, 256] if args.quick else [512, 1024, 2048])
    repeats = args.repeats or 3
    header("Benchmark 3b: preconditioned CG against Polonsky-Keer, periodic rough", args)
    rows = []
    for n in sizes:
        h, load = rough_surface(n), rough_load(n)
        for what, law in (("elastic", None), ("p_Y 0.1 E*", PenetrationHardness(0.1 * E_STAR))):
            results, medians = _alternated(h, load, law, repeats, args.threads)
            rows.append(_row(n, what, results, medians))
            print(rows[-1], flush=True)
        if args.near_full:
            for what, ratio in NEAR_FULL.items():
                near = ratio * E_STAR * 0.1 * h.size
                results, medians = _alternated(h, near, None, repeats, args.threads)
                rows.append(_row(n, f"elastic {what}", results, medians))
                print(rows[-1], flush=True)
    table(rows, list(rows[0]))


if __name__ == "__main__":
    main()
