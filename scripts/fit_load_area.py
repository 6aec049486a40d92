"""Rule fit_load_area: power law A = A_ref·(F/F_ref)^α for one sphere."""

import logging

import pandas as pd

from amontons.io.files import write_json
from amontons.measure.load_area import fit_load_area
from amontons.runlog import run_logged

log = logging.getLogger(__name__)


def main(table_path: str, fit_path: str, reference_load_mn: float, confidence: float) -> None:
    record = fit_load_area(pd.read_csv(table_path), reference_load_mn, confidence)
    exponent = record["exponent"]
    log.info(
        "%s: exponent %.4f ± %.4f", table_path, exponent["estimate"], exponent["standard_error"]
    )
    write_json(fit_path, record)


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        table_path=sm.input.table,
        fit_path=sm.output.fit,
        reference_load_mn=sm.params.load_area["reference_load_mn"],
        confidence=sm.params.load_area["confidence"],
    )
