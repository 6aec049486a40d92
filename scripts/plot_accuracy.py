"""Rule plot_accuracy: error against wall time for each error measure, with each problem's
Pareto front (docs/accuracy.md)."""

import logging

import pandas as pd

from amontons.accuracy.figure import plot_error_versus_time
from amontons.runlog import run_logged

log = logging.getLogger(__name__)


def main(table_path: str, sphere: str, data_label: str, paths: list) -> None:
    table = pd.read_csv(table_path)
    title = f"What accuracy costs: sphere {sphere} ({data_label}) and a periodic surface"
    plot_error_versus_time(table, title, paths)


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        table_path=sm.input.table,
        sphere=sm.params.sphere,
        data_label=sm.params.data_label,
        paths=[sm.output.png, sm.output.pdf],
    )
