"""Rule write_report_page: the report's first page (docs/study.md §6), which
workflow/report/workflow.rst includes: the verdict table and Figs. B.13 and B.12."""

import logging

import pandas as pd

from amontons.io.files import atomic_path
from amontons.runlog import run_logged
from amontons.study.summary import ReportFigure, report_page

log = logging.getLogger(__name__)


def main(
    verdict_path: str,
    figures: dict,
    page_path: str,
    sources: list[str],
    data_label: str,
    confidence: float,
    left_out: list[str],
    failed: list[str],
) -> None:
    """``left_out``: per sphere, what its data did not allow and why (the dry run's lines);
    ``failed``: per sphere held out by an earlier run's failure, its failed jobs."""
    page = report_page(
        pd.read_csv(verdict_path),
        [ReportFigure(png, caption) for png, caption in figures.items()],
        confidence,
        data_label,
        sources,
        verdict_path,
        left_out,
        failed,
    )
    with atomic_path(page_path) as tmp:
        tmp.write_text(page, encoding="utf-8")
    log.info("%s: %d characters, %d figures", page_path, len(page), len(figures))


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        verdict_path=sm.input.verdict,
        figures=sm.params.figures,
        page_path=sm.output.page,
        sources=sm.params.sources,
        data_label=sm.params.data_label,
        confidence=sm.params.confidence,
        left_out=sm.params.left_out,
        failed=sm.params.failed,
    )
