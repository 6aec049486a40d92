"""Rule check_hertz: measured contact radius against the Hertz radius per load."""

import logging

import pandas as pd

from amontons.io.files import write_table
from amontons.measure.hertz_check import hertz_check_table
from amontons.runlog import run_logged

log = logging.getLogger(__name__)


def main(area_path: str, table_path: str, diameter_mm: float, e_star_gpa: float) -> None:
    table = hertz_check_table(pd.read_csv(area_path), diameter_mm * 0.5e-3, e_star_gpa * 1e9)
    log.info(
        "%s: radius ratio measured/Hertz %s", area_path, table["radius_ratio"].round(3).tolist()
    )
    write_table(table_path, table)


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        area_path=sm.input.table,
        table_path=sm.output.table,
        diameter_mm=sm.params.diameter_mm,
        e_star_gpa=sm.params.e_star_gpa,
    )
