"""How well the timing model (docs/accuracy.md) predicts the solves of a whole run.

For every solver job of a run (each scene's solve.json and each scan value's scan_point.json
under results/<run>/), the model predicts the load series' wall time from the job's grid,
loads, tolerance and contact model alone (its iterations predicted too, as a dry run must),
and the script prints predicted / measured per job and per model, and the share of jobs within
a factor of 2:

    python benchmarks/check_timing_model.py --run full [--model workflow/timing_model.json]
        [--root a/fresh/clone]

The measured times are those of the run's own jobs, under whatever else the machine ran.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pandas as pd

from amontons.accuracy.timing import predict

REPO = Path(__file__).resolve().parents[1]


def solver_jobs(results: Path) -> pd.DataFrame:
    """Each solver job of a run: model, grid side, periodic, loads, tol, measured solve time."""
    rows = []
    scenes = {}
    for path in sorted(results.rglob("scenes/*/solve.json")):
        solve = json.loads(path.read_text())
        if "side_px" not in solve or "wall_time_s" not in solve:
            continue  # Greenwood-Tripp: no grid
        scenes[(path.parents[2], solve["scene"])] = solve
        rows.append(_row("scene", solve, solve["wall_time_s"]))
    for path in sorted(results.rglob("scans/*/*/scan_point.json")):
        point = json.loads(path.read_text())
        base = scenes.get((path.parents[3], point["scene"]))
        if base is None or point.get("wall_time_s") is None:
            continue
        rows.append(_row("scan", base, point["wall_time_s"]))
    return pd.DataFrame(rows)


def _row(kind: str, solve: dict, seconds: float) -> dict:
    return {
        "kind": kind,
        "model": solve["model"],
        "side_px": solve["side_px"],
        "periodic": solve["geometry"] == "flat_periodic",
        "loads": len(solve["loads_mn"]),
        "tol": solve["tol"],
        "measured_s": seconds,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--run", default="full")
    parser.add_argument("--model", default=str(REPO / "workflow" / "timing_model.json"))
    parser.add_argument("--root", default=str(REPO), help="project folder holding results/")
    args = parser.parse_args()
    record = json.loads(Path(args.model).read_text())
    jobs = solver_jobs(Path(args.root) / "results" / args.run)
    jobs["predicted_s"] = [
        predict(record, r.model, side_px=r.side_px, periodic=r.periodic, loads=r.loads, tol=r.tol)[
            0
        ]
        for r in jobs.itertuples()
    ]
    jobs["ratio"] = jobs["predicted_s"] / jobs["measured_s"]
    within = (jobs["ratio"] >= 0.5) & (jobs["ratio"] <= 2.0)
    print(f"timing model {args.model} on run {args.run}: {len(jobs)} solver jobs")
    header = ("kind", "model", "jobs", "median", "min", "max", "in 2x")
    print("{:6s} {:22s} {:>5s} {:>7s} {:>6s} {:>6s} {:>6s}".format(*header))
    for (kind, model), group in jobs.groupby(["kind", "model"]):
        ok = within[group.index]
        print(
            f"{kind:6s} {model:22s} {len(group):5d} {group['ratio'].median():7.2f} "
            f"{group['ratio'].min():6.2f} {group['ratio'].max():6.2f} {ok.mean():6.0%}"
        )
    total_ratio = jobs["predicted_s"].sum() / jobs["measured_s"].sum()
    print(
        f"all: {within.mean():.0%} of jobs within a factor of 2; summed predicted / measured "
        f"{total_ratio:.2f} ({jobs['predicted_s'].sum():.0f} s / {jobs['measured_s'].sum():.0f} s)"
    )
    print(f"median ratio {np.median(jobs['ratio']):.2f}")


if __name__ == "__main__":
    main()
