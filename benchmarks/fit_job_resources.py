"""Fit the cluster resources of every rule to a measured run (amontons.measured_resources).

Reads the benchmark file Snakemake wrote for every job of a run (logs/<run>/**/*.benchmark.tsv:
wall time s, peak resident memory max_rss in MB). Writes workflow/resources.json, which the
workflow's rules read for their mem_mb and runtime. The solve rules take theirs from the
timing model instead (workflow/timing_model.json, docs/accuracy.md); their entries here are
the record of what they took.

    python benchmarks/fit_job_resources.py --run full --run small   # after both runs

The figures are those of the machine the run took place on, under whatever else ran there:
amontons.measured_resources asks for twice them.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
from collections import defaultdict
from pathlib import Path

import pandas as pd

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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--run", action="append", help="run name(s) (default: full)")
    parser.add_argument("--out", default=str(REPO / "workflow" / "resources.json"))
    args = parser.parse_args()
    runs = args.run or ["full"]
    rows = defaultdict(list)
    benchmark_files = [
        (path, REPO / "logs" / run)
        for run in runs
        for path in sorted((REPO / "logs" / run).rglob("*.benchmark.tsv"))
    ]
    for path, logs in benchmark_files:
        table = pd.read_csv(path, sep="\t")
        if table.empty or table["max_rss"].astype(str).eq("-").any():
            continue
        last = table.iloc[-1]
        for rule in rule_of(path, logs):
            rows[rule].append((float(last["s"]), float(last["max_rss"])))
    record = {
        "measured": {
            "runs": runs,
            "date": datetime.date.today().isoformat(),
            "cores": len(os.sched_getaffinity(0)),
            "note": "wall time s and peak RSS MB of every job's benchmark file; the workflow "
            "asks for amontons.measured_resources.SAFETY times these",
        },
        "rules": {
            rule: {
                "max_s": max(s for s, _ in values),
                "max_rss_mb": max(m for _, m in values),
                "jobs": len(values),
            }
            for rule, values in sorted(rows.items())
        },
    }
    Path(args.out).write_text(json.dumps(record, indent=1) + "\n")
    print(f"{len(record['rules'])} rules -> {args.out}")


if __name__ == "__main__":
    main()
