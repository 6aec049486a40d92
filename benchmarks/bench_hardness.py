"""Benchmark 7: penetration hardness in one bounded CG ("bounded") against the root find.

Part A (route beside route): the periodic benchmark surface (Hurst 0.8, rms slope 0.1,
spacing 1, E* = 1), mean pressure 0.005 E*, p_Y = 0.1 E*, local increments (eq. B.2),
load control. ``"bounded"`` is one bounded Polonsky–Keer solve under the force constraint
(docs/models.md §2.3); ``"appendix"`` is the root find on the approach, each trial a bounded
solve plus the plastic update. CG iterations and bounded solves are counted over every
trial (a wrapper around the routes' ``polonsky_keer``), not only the final approach that
``ContactResult.iterations`` reports; wall time is the median of the repeats, the two
routes timed in alternation.

Part B (p_Y scan): the rough PMMA sphere of benchmark 6 (R = 0.75 mm, E* = 3.5 GPa,
rms height 30 nm, 51.2 µm non-periodic window, 512²), 5 loads 1–10 mN (geometric);
8 hardness values from 15 MPa to 240 MPa (geometric), each a
warm-started load series on the default ("bounded") route, against one elastic load
series of the same sphere. Ratio = mean time of one hardness series / time of the elastic
series; the medians over the repeats.

Part C (the scan warm-started from its neighbours): the scan of part B through
``solve_scan``, each value's series started load by load from the previous value's
pressures, in descending p_Y (from the nearly elastic end) and ascending order, against the
independent series of part B and one elastic series, timed in alternation. Target: the
whole scan ≤ 3× one elastic series. The fields agree with the independent series to the
solver's tolerance (max |Δp| / p_Y printed).

Both parts plan FFTs with FFTW_MEASURE (_common.TIMING_EFFORT), one thread, plain process.

    python benchmarks/bench_hardness.py                 # A at 256², 512²; B at 512²
    python benchmarks/bench_hardness.py --sizes 1024 --repeats 1 --skip-scan
    python benchmarks/bench_hardness.py --quick         # A at 64²; B and C at 128²
    python benchmarks/bench_hardness.py --skip-routes --skip-scan   # part C only
"""

from __future__ import annotations

import statistics
import time

import numpy as np
from _common import E_STAR, PBAR, TIMING_EFFORT, header, parser, rough_surface, table

from amontons.contact import (
    PenetrationHardness,
    appendix,
    bounded,
    self_affine,
    solve,
    solve_load_series,
    solve_scan,
    sphere,
)

P_Y = 0.1  # E*
RADIUS, E_STAR_PMMA = 0.75e-3, 3.5e9  # m, Pa
WINDOW = 51.2e-6  # m
SCAN_LOADS = np.geomspace(1e-3, 10e-3, 5)  # N
# p_Y, Pa: from nearly fully plastic (15 MPa: 10 mN needs a 15 µm radius at p_Y, inside the
# 25.6 µm half-window) to nearly elastic (240 MPa, 1.5x the elastic peak at 10 mN, 160 MPa
# at 512²), so that most values flow
SCAN_P_Y = np.geomspace(15e6, 240e6, 8)


class _Counter:
    """Counts the bounded CG solves and their iterations made by the hardness routes
    (bounded.py, appendix.py)."""

    MODULES = (bounded, appendix)

    def __init__(self):
        self.solves = 0
        self.iterations = 0
        self.original = bounded.polonsky_keer

    def __enter__(self):
        def counted(*args, **kwargs):
            out = self.original(*args, **kwargs)
            self.solves += 1
            self.iterations += out.iterations
            return out

        for module in self.MODULES:
            module.polonsky_keer = counted
        return self

    def __exit__(self, *exc):
        for module in self.MODULES:
            module.polonsky_keer = self.original


def solve_route(h, method, threads):
    n = h.shape[0]
    with _Counter() as count:
        t0 = time.perf_counter()
        res = solve(
            h,
            1.0,
            E_STAR,
            load=PBAR * E_STAR * n * n,
            periodic=True,
            plasticity=PenetrationHardness(P_Y * E_STAR),
            method=method,
            threads=threads,
            planner_effort=TIMING_EFFORT,
        )
        wall = time.perf_counter() - t0
    return wall, count, res


def part_a(sizes, repeats, threads):
    rows = []
    for n in sizes:
        h = rough_surface(n)
        solve_route(h, "bounded", threads)  # warm-up: plans, operator cache, kernels
        times = {"bounded": [], "appendix": []}
        for _ in range(repeats):
            for method in times:
                wall, count, res = solve_route(h, method, threads)
                times[method].append(wall)
                if method == "bounded":
                    new, new_count = res, count
                else:
                    old, old_count = res, count
        t_new = statistics.median(times["bounded"])
        t_old = statistics.median(times["appendix"])
        rows.append(
            {
                "grid": f"{n}²",
                "bounded: solves": new_count.solves,
                "bounded: CG iterations": new_count.iterations,
                "bounded: s": t_new,
                "appendix: solves": old_count.solves,
                "appendix: CG iterations": old_count.iterations,
                "appendix: s": t_old,
                "speed-up": t_old / t_new,
                "contact %": 100 * new.contact_fraction,
                "at p_Y %": 100 * float(np.mean(new.pressure == P_Y * E_STAR)),
                "max |Δp|/p_Y": float(np.abs(new.pressure - old.pressure).max()) / P_Y,
                "repeats": len(times["bounded"]),
            }
        )
    table(rows, list(rows[0]))


def scan_sphere(n):
    dx = WINDOW / n
    h = sphere((n, n), dx, RADIUS) + self_affine((n, n), dx, 0.8, rms_height=30e-9, rng=3)
    return h, dx


def run_series(h, dx, threads, law=None):
    t0 = time.perf_counter()
    series = solve_load_series(
        h, dx, E_STAR_PMMA, SCAN_LOADS, plasticity=law, threads=threads,
        planner_effort=TIMING_EFFORT,
    )  # fmt: skip
    return time.perf_counter() - t0, series


def part_b(n, repeats, threads):
    h, dx = scan_sphere(n)
    _, elastic = run_series(h, dx, threads)  # warm-up: plans, operator cache
    p_ys = SCAN_P_Y
    run_series(h, dx, threads, PenetrationHardness(p_ys[0]))  # warm-up of the bounded path
    t_el, t_scan, ratios, per_value = [], [], [], []
    for _ in range(repeats):
        te, elastic = run_series(h, dx, threads)
        scan = [run_series(h, dx, threads, PenetrationHardness(p)) for p in p_ys]
        per_value.append([t / te for t, _ in scan])
        ts = sum(t for t, _ in scan)
        t_el.append(te)
        t_scan.append(ts)
        ratios.append(ts / len(p_ys) / te)
    last = [series for _, series in scan]
    rows = [
        {
            "grid": f"{n}²",
            "elastic series s": statistics.median(t_el),
            "scan (8 series) s": statistics.median(t_scan),
            "one hardness series / elastic series": statistics.median(ratios),
            "min / max ratio": f"{min(ratios):.2f} / {max(ratios):.2f}",
            "scan / elastic series": statistics.median(t_scan) / statistics.median(t_el),
            "elastic CG iterations": sum(r.iterations for r in elastic),
            "scan CG iterations (mean per series)": statistics.mean(
                sum(r.iterations for r in series) for series in last
            ),
            "repeats": repeats,
        }
    ]
    table(rows, list(rows[0]))
    detail = [
        {
            "p_Y MPa": float(p) / 1e6,
            "p_Y / elastic peak at 10 mN": float(p) / float(elastic[-1].pressure.max()),
            "series / elastic series (median)": statistics.median(r[i] for r in per_value),
            "CG iterations (5 loads)": sum(r.iterations for r in series),
            "area / elastic area at 10 mN": series[-1].area / elastic[-1].area,
            "at p_Y % of contact at 10 mN": 100
            * float(np.mean(series[-1].pressure[series[-1].contact] == p)),
        }
        for i, (p, series) in enumerate(zip(p_ys, last, strict=True))
    ]
    table(detail, list(detail[0]))


def run_scan(h, dx, threads, p_ys):
    t0 = time.perf_counter()
    scan = solve_scan(
        h, dx, E_STAR_PMMA, SCAN_LOADS, [PenetrationHardness(p) for p in p_ys],
        threads=threads, planner_effort=TIMING_EFFORT,
    )  # fmt: skip
    return time.perf_counter() - t0, scan


def part_c(n, repeats, threads):
    h, dx = scan_sphere(n)
    run_series(h, dx, threads)  # warm-up: plans, operator cache
    run_series(h, dx, threads, PenetrationHardness(SCAN_P_Y[0]))
    orders = {"descending p_Y": SCAN_P_Y[::-1], "ascending p_Y": SCAN_P_Y}
    times = {key: [] for key in ("elastic", "independent", *orders)}
    scans = {}
    for _ in range(repeats):
        times["elastic"].append(run_series(h, dx, threads)[0])
        runs = [run_series(h, dx, threads, PenetrationHardness(p)) for p in SCAN_P_Y]
        times["independent"].append(sum(t for t, _ in runs))
        scans["independent"] = [series for _, series in runs]
        for key, p_ys in orders.items():
            t, scan = run_scan(h, dx, threads, p_ys)
            times[key].append(t)
            scans[key] = scan if key == "ascending p_Y" else scan[::-1]
    elastic_s = statistics.median(times["elastic"])
    rows = []
    for key in ("independent", *orders):
        scan = scans[key]
        worst = max(
            float(np.max(np.abs(a.pressure - b.pressure))) / p
            for p, ours, ref in zip(SCAN_P_Y, scan, scans["independent"], strict=True)
            for a, b in zip(ours, ref, strict=True)
        )
        rows.append(
            {
                "grid": f"{n}²",
                "scan": key,
                "scan s": statistics.median(times[key]),
                "elastic series s": elastic_s,
                "scan / elastic series": statistics.median(
                    t / e for t, e in zip(times[key], times["elastic"], strict=True)
                ),
                "CG iterations per value": " ".join(
                    str(sum(r.iterations for r in series)) for series in scan
                ),
                "max |Δp| / p_Y vs independent": worst,
                "repeats": repeats,
            }
        )
    table(rows, list(rows[0]))


def main():
    ap = parser(__doc__.splitlines()[0])
    ap.add_argument("--skip-scan", action="store_true", help="no part B")
    ap.add_argument("--skip-routes", action="store_true", help="no part A")
    ap.add_argument("--skip-neighbours", action="store_true", help="no part C")
    args = ap.parse_args()
    sizes = args.sizes or ([64] if args.quick else [256, 512])
    repeats = args.repeats or 3
    header("Benchmark 7: penetration hardness, bounded CG vs root find; p_Y scan", args)
    if not args.skip_routes:
        part_a(sizes, repeats, args.threads)
    if not args.skip_scan:
        part_b(128 if args.quick else 512, repeats, args.threads)
    if not args.skip_neighbours:
        part_c(128 if args.quick else 512, repeats, args.threads)


if __name__ == "__main__":
    main()
