"""Benchmark 6: a contact-hardening load series against the elastic series on the same grid.

Problem (SI units): a PMMA sphere (R = 0.75 mm, E* = 3.5 GPa) with self-affine roughness
(Hurst 0.8, rms height 30 nm) on a 51.2 µm non-periodic window (0.1 µm pixels at 512²), 8 loads from
1 mN to 10 mN (geometric), contact hardening k = 7 MPa/nm (appendix value for PMMA).
The hardening series takes the Winkler route (docs/models.md §2.4): each load step is one
Polonsky–Keer solve with the operator K + I/k, plus active-set rounds when points unload.
Both series are timed in alternation, and the ratio is the median of the per-round ratios;
both plan their FFTs with ``planner_effort="FFTW_MEASURE"`` (explicit: _common.TIMING_EFFORT).

    python benchmarks/bench_hardening.py           # 512² (target: ratio ≤ 3)
    python benchmarks/bench_hardening.py --quick   # 128²
"""

from __future__ import annotations

import statistics
import time

import numpy as np
from _common import TIMING_EFFORT, header, parser, table

from amontons.contact import ContactHardening, self_affine, solve_load_series, sphere

RADIUS, E_STAR_PMMA, K_PMMA = 0.75e-3, 3.5e9, 7e15  # m, Pa, Pa/m
WINDOW = 51.2e-6  # m
LOADS = np.geomspace(1e-3, 10e-3, 8)  # N


def rough_sphere(n: int) -> np.ndarray:
    dx = WINDOW / n
    return sphere((n, n), dx, RADIUS) + self_affine((n, n), dx, 0.8, rms_height=30e-9, rng=3)


def run_series(h, threads, plasticity=None):
    t0 = time.perf_counter()
    dx = WINDOW / h.shape[0]
    series = solve_load_series(
        h,
        dx,
        E_STAR_PMMA,
        LOADS,
        threads=threads,
        plasticity=plasticity,
        planner_effort=TIMING_EFFORT,
    )
    return time.perf_counter() - t0, series


def main():
    args = parser(__doc__.splitlines()[0]).parse_args()
    sizes = args.sizes or ([128] if args.quick else [512])
    repeats = args.repeats or 3
    header("Benchmark 6: contact-hardening load series / elastic load series", args)
    law = ContactHardening(K_PMMA)
    rows = []
    for n in sizes:
        h = rough_sphere(n)
        run_series(h, args.threads)  # warm-up: FFTW plans, operator cache
        t_el, t_hd, ratios = [], [], []
        for _ in range(repeats):
            te, elastic = run_series(h, args.threads)
            th, hardening = run_series(h, args.threads, law)
            t_el.append(te)
            t_hd.append(th)
            ratios.append(th / te)
        rows.append(
            {
                "grid": f"{n}²",
                "elastic series s": statistics.median(t_el),
                "hardening series s": statistics.median(t_hd),
                "ratio (median of per-round ratios)": statistics.median(ratios),
                "min / max ratio": f"{min(ratios):.2f} / {max(ratios):.2f}",
                "elastic CG iterations": sum(r.iterations for r in elastic),
                "hardening CG iterations": sum(r.iterations for r in hardening),
                "active-set rounds": sum(r.info.outer_iterations for r in hardening),
                "area ratio at 10 mN": hardening[-1].area / elastic[-1].area,
            }
        )
    table(rows, list(rows[0]))


if __name__ == "__main__":
    main()
