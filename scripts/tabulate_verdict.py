"""Rule tabulate_verdict: the study's verdict per sphere of every material (docs/study.md §6)
from the model tables: measured exponent, each model's exponent and area ratio, the scans'
estimates of k and p_Y with their intervals, and the models that give the measured exponent."""

import logging

from amontons.io.files import write_table
from amontons.runlog import run_logged
from amontons.study.summary import verdict_table

log = logging.getLogger(__name__)


def main(tables: dict, table_path: str) -> None:
    table = verdict_table(tables)
    log.info("\n%s", table.to_string(index=False))
    write_table(table_path, table)


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(main, sm.log[0], tables=sm.params.tables, table_path=sm.output.table)
