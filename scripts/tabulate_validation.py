"""Rule tabulate_validation: the validation study's tables, checks, summary and figure from
every case's record (docs/study.md §7)."""

import pandas as pd

from amontons.io.files import atomic_path, read_json, write_table
from amontons.runlog import run_logged
from amontons.validation.figure import plot_intervals
from amontons.validation.tables import (
    case_table,
    checks,
    confusion_table,
    cost_table,
    coverage_table,
    summary_markdown,
)


def main(records: list[str], ratio: float, confidence: float, left_out: list[str], outputs: dict):
    cases = [read_json(p) for p in records]
    table = case_table(cases)
    coverage = coverage_table(table, confidence)
    confusion = confusion_table(cases)
    cost = cost_table(table)
    checked = checks(coverage, confusion, confidence)
    write_table(outputs["cases"], table)
    write_table(outputs["coverage"], coverage)
    write_table(outputs["confusion"], confusion)
    write_table(outputs["cost"], cost)
    write_table(outputs["checks"], pd.DataFrame(checked))
    with atomic_path(outputs["summary"]) as tmp:
        tmp.write_text(summary_markdown(coverage, confusion, checked, cost, left_out))
    plot_intervals(table, ratio, [outputs["figure"]])


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        records=list(sm.input.records),
        ratio=sm.params.ratio,
        confidence=sm.params.confidence,
        left_out=list(sm.params.left_out),
        outputs=dict(sm.output.items()),
    )
