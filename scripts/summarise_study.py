"""Rule summarise_study: results/<run>/summary.md (docs/study.md §6), the headline numbers a
user would quote, each with the file (and key) it is read from: the verdict table, each
sphere's measured exponent, its scans' estimates, each model's exponent and area ratio, the
growth of area and static friction over the loads, and the curvature study."""

import logging

import pandas as pd

from amontons.io.files import atomic_path, read_json
from amontons.runlog import run_logged
from amontons.study.decision import ELASTIC
from amontons.study.summary import (
    amontons_headline,
    curvature_headlines,
    display_rows,
    measured_headline,
    model_headlines,
    scan_headline,
    summary_markdown,
)

log = logging.getLogger(__name__)


def main(
    layout: dict,
    summary_path: str,
    run: str,
    data_label: str,
    confidence: float,
    left_out: list[str],
    failed: list[str],
) -> None:
    """``left_out``: per sphere, what its data did not allow and why (the dry run's lines);
    ``failed``: per sphere held out by an earlier run's failure, its failed jobs."""
    verdict = None if layout["verdict"] is None else pd.read_csv(layout["verdict"])
    amontons = {m: pd.read_csv(p) for m, p in layout["amontons"].items()}
    headlines = []
    for sphere, fit_path in layout["fits"].items():
        headlines.append(measured_headline(sphere, read_json(fit_path), fit_path))
        rows = [] if verdict is None else verdict[verdict["sphere"] == sphere].to_dict("records")
        elastic = any(row.get("decided") == ELASTIC for row in rows)
        for path in layout["bests"][sphere].values():
            headlines.append(scan_headline(sphere, read_json(path), path, elastic))
        for row in rows:  # none for a sphere whose data allowed no scan
            headlines += model_headlines(row, layout["verdict"], layout["models"][row["material"]])
    for material, table in amontons.items():
        for sphere, rows in table.groupby("sphere", sort=False):
            headlines.append(amontons_headline(sphere, rows, layout["amontons"][material]))
    if layout["curvature"] is not None:
        headlines += curvature_headlines(pd.read_csv(layout["curvature"]), layout["curvature"])
    text = summary_markdown(
        run,
        data_label,
        None if verdict is None else display_rows(verdict, confidence),
        layout["verdict"],
        headlines,
        left_out,
        failed,
    )
    with atomic_path(summary_path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    log.info("%s: %d headline numbers", summary_path, len(headlines))


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        layout=sm.params.layout,
        summary_path=sm.output.summary,
        run=sm.params.run,
        data_label=sm.params.data_label,
        confidence=sm.params.confidence,
        left_out=sm.params.left_out,
        failed=sm.params.failed,
    )
