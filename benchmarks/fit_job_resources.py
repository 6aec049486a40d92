"""Fit the cluster resources of every rule to a measured run (amontons.resources).

Reads the benchmark file Snakemake wrote for every job of a run (logs/<run>/**/*.benchmark.tsv:
wall time s, peak resident memory max_rss in MB) and, for the jobs that solve a contact
problem, the grid and loads of their solve (solve.json, or the scan value's rendered.h5).
Writes workflow/resources.json, which the workflow's rules read for their mem_mb and runtime.

    python benchmarks/fit_job_resources.py --run full --run small   # after both runs

The figures are those of the machine the run took place on, under whatever else ran there:
amontons.resources asks for twice them.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
from collections import defaultdict
from pathlib import Path

import h5py
import numpy as np
import pandas as pd

from amontons.resources import GRID_RULES, fft_points

REPO = Path(__file__).resolve().parents[1]


def rule_of(path: Path, logs: Path) -> list[str]:
    """The rule(s) a benchmark file belongs to (its name, and for the shared names, where)."""
    parts = path.relative_to(logs).parts
    name = path.name.removesuffix(".benchmark.tsv")
    if parts[0] == "virtual_experiment":
        return ["generate_virtual_experiment", "generate_virtual_experiment_with_flim"]
    if parts[0] == "synthetic" and name in ("simulate_scene", "fit_scene"):
        return [name.replace("_scene", "_synthetic_scene")]
    return [name]


def solve_record(path: Path, logs: Path, results: Path) -> dict | None:
    """Grid side, geometry, model and number of loads of a grid job's solve (None: the job's
    output is gone, e.g. it is being re-run)."""
    folder = results / path.parent.relative_to(logs)
    if path.name.startswith("scan_scene"):
        if not (folder / "rendered.h5").exists():
            return None
        with h5py.File(folder / "rendered.h5", "r") as h5:
            attrs = {key: h5.attrs[key] for key in ("side_px", "geometry", "model")}
            loads = len(json.loads(h5.attrs["loads_mn"]))
        return {**attrs, "loads": loads}
    if not (folder / "solve.json").exists():
        return None
    solve = json.loads((folder / "solve.json").read_text())
    return {
        "side_px": solve["side_px"],
        "geometry": solve["geometry"],
        "model": solve["model"],
        "loads": len(solve["loads_mn"]),
    }


def fit_grid(jobs: pd.DataFrame) -> dict:
    """c_t = max time per load and point; memory line m_0 + m_1 N above every job."""
    per_point = jobs["s"] / (jobs["loads"] * jobs["points"])
    if jobs["points"].nunique() > 1:
        slope = float(np.polyfit(jobs["points"], jobs["max_rss"], 1)[0])
    else:
        slope = 0.0
    slope = max(slope, 0.0)
    base = float((jobs["max_rss"] - slope * jobs["points"]).max())
    return {
        "s_per_load_point": float(per_point.max()),
        "base_mb": base,
        "mb_per_point": slope,
        "jobs": int(len(jobs)),
        "points": sorted(int(p) for p in jobs["points"].unique()),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--run", action="append", help="run name(s) (default: full)")
    parser.add_argument("--out", default=str(REPO / "workflow" / "resources.json"))
    args = parser.parse_args()
    runs = args.run or ["full"]
    rows, grid_rows = defaultdict(list), []
    benchmark_files = [
        (path, REPO / "logs" / run, REPO / "results" / run)
        for run in runs
        for path in sorted((REPO / "logs" / run).rglob("*.benchmark.tsv"))
    ]
    for path, logs, results in benchmark_files:
        table = pd.read_csv(path, sep="\t")
        if table.empty or table["max_rss"].astype(str).eq("-").any():
            continue
        last = table.iloc[-1]
        for rule in rule_of(path, logs):
            rows[rule].append((float(last["s"]), float(last["max_rss"])))
            if rule in GRID_RULES:
                solve = solve_record(path, logs, results)
                if solve is None:
                    print(f"skipped (no output): {path.relative_to(REPO)}")
                    continue
                points = fft_points(int(solve["side_px"]), solve["geometry"] == "flat_periodic")
                grid_rows.append(
                    {
                        "rule": rule,
                        **solve,
                        "points": points,
                        "s": float(last["s"]),
                        "max_rss": float(last["max_rss"]),
                    }
                )
    grid = pd.DataFrame(grid_rows)
    record = {
        "measured": {
            "runs": runs,
            "date": datetime.date.today().isoformat(),
            "cores": len(os.sched_getaffinity(0)),
            "note": "wall time s and peak RSS MB of every job's benchmark file; the workflow "
            "asks for amontons.resources.SAFETY times these",
        },
        "rules": {
            rule: {
                "max_s": max(s for s, _ in values),
                "max_rss_mb": max(m for _, m in values),
                "jobs": len(values),
            }
            for rule, values in sorted(rows.items())
        },
        "grid_rules": {
            rule: {model: fit_grid(jobs) for model, jobs in by_rule.groupby("model")}
            for rule, by_rule in grid.groupby("rule")
        },
    }
    Path(args.out).write_text(json.dumps(record, indent=1) + "\n")
    print(f"{len(record['rules'])} rules, {len(grid)} grid jobs -> {args.out}")
    for rule, models in record["grid_rules"].items():
        for model, fit in models.items():
            print(
                f"{rule:26s} {model:22s} {fit['s_per_load_point'] * 1e6:8.3f} s per load per "
                f"Mpoint, memory {fit['base_mb']:.0f} MB + {fit['mb_per_point'] * 1e6:.0f} "
                f"MB per Mpoint ({fit['jobs']} jobs)"
            )


if __name__ == "__main__":
    main()
