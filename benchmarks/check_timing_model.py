"""How well the timing model (docs/accuracy.md) predicts the solves of a whole run.

For every solver job of a run (each scene's solve.json and each scan value's scan_point.json
under results/<run>/), the model predicts the load series' wall time from what the job was
given: its grid, loads, tolerance, contact extent and plastic law (its convolutions
predicted too, as a dry run must). Two predictions per job:

- "known slope": the penetration-hardness yield ratio from the map's rms slope at the solver
  pixel, as the job recorded it (what a dry run after the measure step could know);
- "dry run": without it (the elastic limit), as the workflow sizes a job before the map is
  levelled.

It prints predicted / measured per kind and model, and the share of jobs within a factor of 2:

    python benchmarks/check_timing_model.py --run full [--model workflow/timing_model.json]
        [--root a/fresh/clone] [--jobs]

The measured times are those of the run's own jobs, under whatever else the machine ran.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pandas as pd

from amontons.accuracy.timing import plastic_ratio, predict
from amontons.physics.hertz import contact_radius

REPO = Path(__file__).resolve().parents[1]


def solver_jobs(results: Path) -> pd.DataFrame:
    """Each solver job of a run: its scene record, law (p_Y, k) and measured solve time."""
    rows = []
    scenes = {}
    for path in sorted(results.rglob("scenes/*/solve.json")):
        solve = json.loads(path.read_text())
        if "side_px" not in solve or "wall_time_s" not in solve:
            continue  # Greenwood–Tripp: no grid
        scenes[(path.parents[2], solve["scene"])] = solve
        law = (solve.get("p_y_mpa"), solve.get("k_mpa_per_nm"))
        rows.append(_row("scene", solve, *law, solve["wall_time_s"], None))
    for path in sorted(results.rglob("scans/*/*/scan_point.json")):
        point = json.loads(path.read_text())
        base = scenes.get((path.parents[3], point["scene"]))
        if base is None or point.get("wall_time_s") is None:
            continue
        law = {"p_y_mpa": base.get("p_y_mpa"), "k_mpa_per_nm": base.get("k_mpa_per_nm")}
        law[point["parameter"]] = point["value"]
        rows.append(
            _row("scan", base, law["p_y_mpa"], law["k_mpa_per_nm"], point["wall_time_s"], point)
        )
    return pd.DataFrame(rows)


def _row(kind, solve, p_y_mpa, k_mpa_per_nm, seconds, point) -> dict:
    pixel_m = solve["pixel_nm"] * 1e-9
    e_star = solve["e_star_gpa"] * 1e9
    periodic = solve["geometry"] == "flat_periodic"
    contact_px = None
    if not periodic and solve.get("radius_mm"):
        radius = contact_radius(max(solve["loads_mn"]) * 1e-3, solve["radius_mm"] * 1e-3, e_star)
        contact_px = 2 * radius / pixel_m
    law = {
        "pixel_m": pixel_m,
        "e_star_pa": e_star,
        "k_pa_per_m": (k_mpa_per_nm or 0.0) * 1e15,
        "p_y_pa": (p_y_mpa or 0.0) * 1e6,
    }
    slope = solve["surface_at_solver_pixel"]["slope_rms"]
    return {
        "kind": kind,
        "sphere": solve.get("sphere"),
        "scene": solve["scene"],
        "value": None if point is None else point["value"],
        "model": solve["model"],
        "side_px": solve["side_px"],
        "periodic": periodic,
        "loads": len(solve["loads_mn"]),
        "tol": solve["tol"],
        "contact_px": contact_px,
        "plastic_ratio": plastic_ratio(solve["model"], slope_rms=slope, **law),
        "dry_ratio": plastic_ratio(solve["model"], **law),  # the slope unknown
        "measured_s": seconds,
    }


def _predicted(record, jobs: pd.DataFrame, ratio_column: str) -> pd.Series:
    def one(r):
        return predict(
            record,
            r["model"],
            side_px=int(r["side_px"]),
            periodic=bool(r["periodic"]),
            loads=int(r["loads"]),
            tol=float(r["tol"]),
            contact_px=None if pd.isna(r["contact_px"]) else float(r["contact_px"]),
            ratio=None if pd.isna(r[ratio_column]) else float(r[ratio_column]),
        )[0]

    return jobs.apply(one, axis=1)


def report(jobs: pd.DataFrame, ratio: pd.Series, label: str) -> None:
    within = (ratio >= 0.5) & (ratio <= 2.0)
    print(f"\n{label}")
    header = ("kind", "model", "jobs", "median", "min", "max", "in 2x")
    print("{:6s} {:22s} {:>5s} {:>7s} {:>6s} {:>6s} {:>6s}".format(*header))
    for (kind, model), group in jobs.groupby(["kind", "model"]):
        r = ratio[group.index]
        print(
            f"{kind:6s} {model:22s} {len(group):5d} {r.median():7.2f} "
            f"{r.min():6.2f} {r.max():6.2f} {within[group.index].mean():6.0%}"
        )
    predicted = ratio * jobs["measured_s"]
    print(
        f"all: {within.mean():.0%} of jobs within a factor of 2 ({within.sum()}/{len(jobs)}); "
        f"ratio median {np.median(ratio):.2f}, range {ratio.min():.2f}-{ratio.max():.2f}; "
        f"summed predicted / measured {predicted.sum() / jobs['measured_s'].sum():.2f}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--run", default="full")
    parser.add_argument("--model", default=str(REPO / "workflow" / "timing_model.json"))
    parser.add_argument("--root", default=str(REPO), help="project folder holding results/")
    parser.add_argument("--jobs", action="store_true", help="print every job")
    args = parser.parse_args()
    record = json.loads(Path(args.model).read_text())
    jobs = solver_jobs(Path(args.root) / "results" / args.run)
    print(f"timing model {args.model} on run {args.run}: {len(jobs)} solver jobs")
    jobs["known"] = _predicted(record, jobs, "plastic_ratio") / jobs["measured_s"]
    jobs["dry"] = _predicted(record, jobs, "dry_ratio") / jobs["measured_s"]
    report(jobs, jobs["known"], "predicted / measured, with the map's slope (known slope)")
    report(jobs, jobs["dry"], "predicted / measured, as a dry run before levelling (dry run)")
    if args.jobs:
        columns = ["kind", "sphere", "scene", "value", "measured_s", "known", "dry"]
        print("\n" + jobs[columns].to_string(float_format=lambda v: f"{v:.3g}"))


if __name__ == "__main__":
    main()
