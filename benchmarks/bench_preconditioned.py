"""Benchmark 3b: the preconditioned bound-constrained CG against Polonsky and Keer's.

The periodic self-affine surface of benchmark 3 (Hurst 0.8, rms slope 0.1, mean pressure
0.005 E*, ~10 % contact), tol 1e-8, one thread, elastic and penetration hardness at
p_Y = 0.1 E*. Per size and law the two iterations run alternately (PK, preconditioned,
PK, ...) after one loose untimed solve each (tol 1e-2) that builds the plans; the table
gives each one's iterations, FFT pairs (``info.convolutions``), median time, the time
ratio, and how far the two answers lie apart (contact pixels that differ, largest pressure
difference over the peak). ``--near-full`` adds the surface pressed to 50, 80 and 95 %
contact; ``--spheres`` times instead what the pipeline solves: a rough sphere on a free
(padded) window, contact radius ~n/5, five loads from 5 % to the full load warm-started
along the series (``solve_load_series``), elastic, penetration hardness (p_Y = 0.05 E*) and
contact hardening (k = 0.2 E* per pixel).

    python benchmarks/bench_preconditioned.py                      # 512² ... 2048²
    python benchmarks/bench_preconditioned.py --sizes 4096 --repeats 1
    python benchmarks/bench_preconditioned.py --quick --near-full  # 128², 256²
    python benchmarks/bench_preconditioned.py --spheres --sizes 256 512 1024
"""

from __future__ import annotations

import statistics
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

from amontons.contact import ContactHardening, PenetrationHardness, solve, solve_load_series

ITERATIONS = ("polonsky-keer", "preconditioned")
# Mean pressure / (E* h'_rms) that presses the 512² surface to 50, 80 and 95 % contact
# (measured with this script's --near-full; the fraction each reached is printed).
NEAR_FULL = {"50 %": 0.25, "80 %": 0.55, "95 %": 0.9}


def _solve(h, load, iteration, law, threads, tol):
    return solve(
        h,
        1.0,
        E_STAR,
        load=load,
        periodic=True,
        tol=tol,
        threads=threads,
        planner_effort=TIMING_EFFORT,
        plasticity=law,
        iteration=iteration,
    )


def _series(h, loads, iteration, law, threads, tol):
    return solve_load_series(
        h,
        1.0,
        E_STAR,
        loads,
        tol=tol,
        threads=threads,
        planner_effort=TIMING_EFFORT,
        plasticity=law,
        iteration=iteration,
    )


def _alternated(run, repeats):
    """Each iteration's last result and median time, ``run(iteration, tol)`` alternately
    at tol 1e-8, after one loose solve each (tol 1e-2) that builds the plans."""
    times = {name: [] for name in ITERATIONS}
    results = {name: run(name, 1e-2) for name in ITERATIONS}
    for _ in range(repeats):
        for name in ITERATIONS:
            t0 = time.perf_counter()
            results[name] = run(name, 1e-8)
            times[name].append(time.perf_counter() - t0)
    return results, {name: statistics.median(ts) for name, ts in times.items()}


def _row(n, what, results, medians):
    """One table row; a load series' results summed (iterations, pairs) or its last load's
    (contact, fields)."""
    pk, pc = (_as_list(results[name]) for name in ITERATIONS)
    peak = float(pk[-1].pressure.max())
    return {
        "n": n,
        "case": what,
        "contact": round(pk[-1].contact_fraction, 3),
        "PK it": sum(r.iterations for r in pk),
        "PC it": sum(r.iterations for r in pc),
        "PK pairs": sum(r.info.convolutions for r in pk),
        "PC pairs": sum(r.info.convolutions for r in pc),
        "PK s": medians["polonsky-keer"],
        "PC s": medians["preconditioned"],
        "PK/PC time": medians["polonsky-keer"] / medians["preconditioned"],
        "set diff px": sum(
            int(np.count_nonzero(a.contact != b.contact)) for a, b in zip(pk, pc, strict=True)
        ),
        "max |dp|/peak": f"{float(np.abs(pk[-1].pressure - pc[-1].pressure).max()) / peak:.1e}",
    }


def _as_list(result):
    return result if isinstance(result, list) else [result]


def _periodic_rows(n, args, repeats):
    h, load = rough_surface(n), rough_load(n)
    cases = [("elastic", load, None), ("p_Y 0.1 E*", load, PenetrationHardness(0.1 * E_STAR))]
    if args.near_full:
        cases += [
            (f"elastic {what}", ratio * E_STAR * 0.1 * h.size, None)
            for what, ratio in NEAR_FULL.items()
        ]
    for what, w, law in cases:
        results, medians = _alternated(
            lambda name, tol, w=w, law=law: _solve(h, w, name, law, args.threads, tol),
            repeats,
        )
        yield _row(n, what, results, medians)


def _sphere_rows(n, args, repeats):
    h, load = sphere_problem(n)
    loads = load * np.geomspace(0.05, 1.0, 5)
    laws = {
        "sphere series elastic": None,
        "sphere series p_Y 0.05 E*": PenetrationHardness(0.05 * E_STAR),
        "sphere series k 0.2 E*/px": ContactHardening(0.2 * E_STAR),
    }
    for what, law in laws.items():
        results, medians = _alternated(
            lambda name, tol, law=law: _series(h, loads, name, law, args.threads, tol),
            repeats,
        )
        yield _row(n, what, results, medians)


def main():
    ap = parser(__doc__.splitlines()[0])
    ap.add_argument("--near-full", action="store_true", help="add 50/80/95 %% contact")
    ap.add_argument("--spheres", action="store_true", help="rough-sphere load series instead")
    args = ap.parse_args()
    sizes = args.sizes or ([128, 256] if args.quick else [512, 1024, 2048])
    repeats = args.repeats or 3
    header("Benchmark 3b: preconditioned CG against Polonsky-Keer, periodic rough", args)
    rows = []
    for n in sizes:
        for row in (_sphere_rows if args.spheres else _periodic_rows)(n, args, repeats):
            rows.append(row)
            print(row, flush=True)
    table(rows, list(rows[0]))


if __name__ == "__main__":
    main()
