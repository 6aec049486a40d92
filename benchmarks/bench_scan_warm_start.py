"""Benchmark 7, part D: the pipeline's own scan, its values warm-started from their neighbours.

A sphere's p_Y or k scan as the pipeline runs it (rule scan_scene: the scan's scene at each
value on the sphere's levelled AFM map, its measured loads, the run's preset), each value's
load series solved

* ``independent``: from nothing, each load from the previous one (the pipeline until
  2026-11-28);
* ``descending`` / ``ascending``: each load from the neighbouring value's pressure at the
  same load (:mod:`amontons.simulate.scan_start`), the values in that order, the first from
  nothing;
* ``pipeline``: as the scan job runs it: the values in its chain's order
  (``SCAN_CHAIN_ORDER``), and the first from the sphere's elastic solve where the chain
  starts at the elastic end (``Scenes.scan_seed_scene``: p_Y from its largest value down);

against one elastic load series of the same sphere (its run's elastic scene), solved first
and timed in the same process just before each repeat of a scan. Prints per value and order
the CG iterations and wall time, each order's total over the elastic series' (the median of
the repeats' ratios), and the largest change of a value's contact areas against the
independent solves (relative): the warm start may move a converged solution only within
the solver's tolerance.

    python benchmarks/bench_scan_warm_start.py --configfile config/config.yaml --sphere PS
    python benchmarks/bench_scan_warm_start.py --sphere PTFE --bounded-reset-fractions 0.01 0.1 1
    python benchmarks/bench_scan_warm_start.py --sphere PTFE --start-predictors neighbour coarse

``--start-predictors``: the p_Y chain as the job runs it, each value's loads started by one
of :data:`PREDICTORS` instead (the starts tried for the values where the bound binds,
docs/study.md §1).

Needs the run's raw data and levelled maps (``make reproduce`` or the run of
``--configfile``). One thread, as a scan job runs; medians of ``--repeats`` solves.
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime
import os
import platform
import statistics
import time
from pathlib import Path

import numpy as np
import yaml

from amontons.contact import FreeBoundaryError, cg_iteration
from amontons.simulate.scan import scene_config_at
from amontons.simulate.scan_start import ScanStart
from amontons.simulate.solve import solve_scene
from amontons.simulate.surface import afm_indenter, afm_scene, load_levelled_map
from amontons.workflow.paths import LEVELLED_MAP
from amontons.workflow.run import WorkflowRun

REPO = Path(__file__).resolve().parents[1]
ORDERS = ("independent", "descending", "ascending", "pipeline")
# a p_Y value's start from the chain so far: the neighbour's pressures (the pipeline); their
# extrapolation in log p_Y from the two previous values; the value solved first on a grid
# twice as coarse (from the neighbour's coarse solve) and repeated onto the solver grid; the
# neighbour's pressures plus the coarse grid's change between the two values
PREDICTORS = ("neighbour", "secant", "coarse", "coarse-corrected")


def sphere_scene(run, name: str, config: dict, sphere: str, levelled, levelled_path: str):
    """The scene ``name`` under ``config`` on the sphere's map, and its indenter."""
    scene, _ = afm_scene(name, config, sphere, run.spheres.scene_record(sphere), levelled)
    return scene, afm_indenter(levelled, scene, levelled_path)


def timed_series(scene, indenter, starts=None):
    """(solution or None, iterations, wall s) of one load series."""
    t0 = time.perf_counter()
    try:
        solution = solve_scene(scene, indenter, warm_starts=starts)
    except FreeBoundaryError:
        return None, 0, time.perf_counter() - t0
    iterations = sum(row["iterations"] for row in solution.per_load)
    return solution, iterations, time.perf_counter() - t0


def solved_start(solution, scene, indenter) -> ScanStart:
    """A solve's pressures as a start (none where it solved nothing)."""
    if solution is None:
        return ScanStart()
    pressures = [f["pressure"] for f in solution.fields]
    return ScanStart.of(scene.loads_n, pressures, indenter.spacing_m, indenter.centre_in_scan_m)


def scan_order(run, scan, sphere, levelled, path, order, seed: ScanStart) -> list[dict]:
    """Every value of the scan solved in ``order``: value, iterations, wall s, areas (µm²).
    ``seed``: the sphere's elastic solve, the first value's start in the ``pipeline`` order
    where the pipeline starts it so."""
    spec = run.scenes.scans[scan]
    base = run.scenes.config(spec["scene"])
    values = [float(v) for v in run.scenes.scan_value_labels(sphere, scan)]
    if order == "descending":
        values = values[::-1]
    start = ScanStart()
    if order == "pipeline":
        values = [float(v) for v in run.scenes.scan_chain(sphere, scan)]
        if run.scenes.scan_seed_scene(sphere, scan) is not None:
            start = seed
    rows = []
    for value in values:
        config = scene_config_at(base, spec["parameter"], value)
        scene, indenter = sphere_scene(run, spec["scene"], config, sphere, levelled, path)
        starts, _ = start.starts_for(
            scene.loads_n, indenter.heights.shape, indenter.spacing_m, indenter.centre_in_scan_m
        )
        if not start.loads_n:
            starts = None
        solution, iterations, wall = timed_series(scene, indenter, starts)
        areas = [] if solution is None else [row["area_um2"] for row in solution.per_load]
        rows.append({"value": value, "iterations": iterations, "wall_s": wall, "areas": areas})
        if order != "independent":
            start = solved_start(solution, scene, indenter)
    return sorted(rows, key=lambda row: row["value"])


def reset_fractions(run, sphere, levelled, path, seed, fractions) -> None:
    """The p_Y scan's values solved independently under each bounded reset fraction: the
    measurement that chose BOUNDED_RESET_FRACTION (docs/models.md §2.2)."""
    default = cg_iteration.BOUNDED_RESET_FRACTION
    try:
        for fraction in fractions:
            cg_iteration.BOUNDED_RESET_FRACTION = fraction
            rows = scan_order(run, "p_y", sphere, levelled, path, "independent", seed)
            counts = ", ".join(f"{r['value']:.4g}: {r['iterations']}" for r in rows)
            total = sum(r["iterations"] for r in rows)
            wall = sum(r["wall_s"] for r in rows)
            print(f"bounded reset fraction {fraction:g}: {total} it, {wall:.2f} s ({counts})")
    finally:
        cg_iteration.BOUNDED_RESET_FRACTION = default


def coarse_indenter(indenter):
    """The indenter block-averaged 2×2 onto a grid of twice its pixel (an odd side loses its
    last row and column)."""
    n = indenter.heights.shape[0] // 2
    heights = indenter.heights[: 2 * n, : 2 * n].reshape(n, 2, n, 2).mean(axis=(1, 3))
    return dataclasses.replace(
        indenter, heights=heights - heights.max(), spacing_m=2 * indenter.spacing_m
    )


def fine_of(coarse: np.ndarray) -> np.ndarray:
    """A coarse grid's pressures repeated onto the solver grid (each value on 2×2 points)."""
    return np.kron(coarse, np.ones((2, 2)))


def predicted_starts(predictor, value, chain, coarse_now) -> list[np.ndarray]:
    """The loads' starts of p_Y ``value`` by ``predictor`` from ``chain``: (p_Y, pressures,
    coarse pressures) of the values solved so far, the elastic solve first (p_Y inf)."""
    (_, fine, coarse) = chain[-1]
    if predictor == "coarse":
        return [fine_of(c) for c in coarse_now]
    if predictor == "coarse-corrected":
        return [np.clip(f + fine_of(c - o), 0.0, None)
                for f, c, o in zip(fine, coarse_now, coarse, strict=True)]  # fmt: skip
    if predictor == "secant" and len(chain) >= 3:
        (v2, before, _), (v1, _, _) = chain[-2], chain[-1]
        step = (np.log(value) - np.log(v1)) / (np.log(v1) - np.log(v2))
        return [np.clip(f + step * (f - b), 0.0, None)
                for f, b in zip(fine, before, strict=True)]  # fmt: skip
    return [f.copy() for f in fine]


def start_predictors(run, sphere, levelled, path, seeded, solution, predictors) -> None:
    """The p_Y chain (the job's order, from ``solution``, the elastic scene and indenter
    ``seeded``'s solve) under each predictor of the loads' starts: CG iterations per value,
    and the wall time with the coarse solves'."""
    spec = run.scenes.scans["p_y"]
    base = run.scenes.config(spec["scene"])
    values = [float(v) for v in run.scenes.scan_chain(sphere, "p_y")]
    coarse = timed_series(seeded[0], coarse_indenter(seeded[1]))[0]
    first = (np.inf, [f["pressure"] for f in solution.fields],
             [f["pressure"] for f in coarse.fields])  # fmt: skip
    for predictor in predictors:
        chain, counts, wall = [first], [], 0.0
        for value in values:
            config = scene_config_at(base, spec["parameter"], value)
            scene, indenter = sphere_scene(run, spec["scene"], config, sphere, levelled, path)
            coarse_now = chain[-1][2]
            if predictor.startswith("coarse"):
                solved, _, coarse_wall = timed_series(
                    scene, coarse_indenter(indenter), [c.copy() for c in chain[-1][2]]
                )
                coarse_now, wall = [f["pressure"] for f in solved.fields], wall + coarse_wall
            starts = predicted_starts(predictor, value, chain, coarse_now)
            solved, iterations, fine_wall = timed_series(scene, indenter, starts)
            chain.append((value, [f["pressure"] for f in solved.fields], coarse_now))
            counts.append((value, iterations))
            wall += fine_wall
        total = sum(iterations for _, iterations in counts)
        listed = ", ".join(f"{value:.4g}: {iterations}" for value, iterations in counts)
        print(f"p_y start {predictor}: {total} it, {wall:.2f} s ({listed})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--configfile", type=Path, default=REPO / "config" / "config.yaml")
    parser.add_argument("--sphere", default="PS")
    parser.add_argument("--scans", nargs="+", default=["p_y", "k"])
    parser.add_argument("--orders", nargs="+", default=list(ORDERS), choices=ORDERS)
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument(
        "--bounded-reset-fractions",
        nargs="+",
        type=float,
        default=[],
        help="instead of the orders: the p_Y scan's independent values under each of these "
        "conjugation reset fractions of the bounded iteration (cg_iteration."
        "BOUNDED_RESET_FRACTION), CG iterations per value",
    )
    parser.add_argument(
        "--start-predictors",
        nargs="+",
        default=[],
        choices=PREDICTORS,
        help="instead of the orders: the p_Y chain with each value's loads started by each of "
        "these predictors, CG iterations per value",
    )
    args = parser.parse_args()
    config = yaml.safe_load(args.configfile.read_text())
    run = WorkflowRun.from_config(config, REPO / "workflow", str(args.configfile))
    material = run.spheres.rows.material_of(args.sphere)
    path = run.paths.measured(LEVELLED_MAP, material, args.sphere)
    levelled = load_levelled_map(path)
    print(f"# {__doc__.splitlines()[0]}")
    print(
        f"# {datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M} UTC, {platform.node()}, "
        f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}, {args.configfile}, "
        f"sphere {args.sphere}"
    )
    elastic_name = run.scenes.first("elastic", "microscope") or run.scenes.first("elastic")
    elastic = sphere_scene(
        run, elastic_name, run.scenes.config(elastic_name), args.sphere, levelled, path
    )
    # the first solve of each grid plans its transforms (FFTW wisdom): not timed
    elastic_solution, elastic_iterations, _ = timed_series(*elastic)
    seed_name = run.scenes.sphere_elastic_scene(args.sphere) or elastic_name
    seeded, seed_solution = elastic, elastic_solution
    if seed_name != elastic_name:
        print(f"# the scans' seed is scene {seed_name}, not {elastic_name}: solved apart")
        seeded = sphere_scene(
            run, seed_name, run.scenes.config(seed_name), args.sphere, levelled, path
        )
        seed_solution = timed_series(*seeded)[0]
    seed = solved_start(seed_solution, *seeded)
    walls = [timed_series(*elastic)[2] for _ in range(max(args.repeats, 3))]
    elastic_wall = statistics.median(walls)
    print(f"elastic series ({elastic_name}): {elastic_iterations} iterations, {elastic_wall:.2f} s")
    if args.bounded_reset_fractions:
        reset_fractions(run, args.sphere, levelled, path, seed, args.bounded_reset_fractions)
        return
    if args.start_predictors:
        start_predictors(
            run, args.sphere, levelled, path, seeded, seed_solution, args.start_predictors
        )
        return
    for scan in args.scans:
        results = {}
        for order in args.orders:
            # each round times an elastic series just before the scan: the machine's speed
            # drifts by tens of per cent between minutes, so the ratio is taken per round
            rounds = [(timed_series(*elastic)[2],
                       scan_order(run, scan, args.sphere, levelled, path, order, seed))
                      for _ in range(args.repeats)]  # fmt: skip
            repeats = [rows for _, rows in rounds]
            results[order] = repeats[0]
            walls = [sum(r["wall_s"] for r in rows) for rows in repeats]
            ratio = statistics.median(w / b for w, (b, _) in zip(walls, rounds, strict=True))
            iterations = sum(r["iterations"] for r in repeats[0])
            print(
                f"{scan} {order}: {iterations} iterations, {statistics.median(walls):.2f} s, "
                f"{ratio:.2f}× the elastic series timed before it (median of "
                f"{args.repeats} rounds), {iterations / elastic_iterations:.2f}× its iterations"
            )
            for row in repeats[0]:
                print(f"    {row['value']:10.4g}: {row['iterations']:5d} it, {row['wall_s']:.2f} s")
        base = results.get("independent")
        for order, rows in results.items():
            if base is None or order == "independent":
                continue
            change = max(
                (abs(a / b - 1) for r, q in zip(rows, base, strict=True)
                 for a, b in zip(r["areas"], q["areas"], strict=True) if b > 0),
                default=0.0,
            )  # fmt: skip
            print(f"{scan} {order}: largest area change against independent {change:.2e}")


if __name__ == "__main__":
    np.set_printoptions(precision=4)
    main()
