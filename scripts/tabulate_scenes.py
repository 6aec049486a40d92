"""Rule tabulate_scenes: every scene's load-area exponent of one material next to the measured
exponent of each sphere."""

import logging

import pandas as pd

from amontons.io.files import read_json, write_table
from amontons.runlog import run_logged
from amontons.simulate.tables import scene_table_rows

log = logging.getLogger(__name__)


def main(
    measured_fits: list[str],
    layout: dict[str, str],
    table_path: str,
    models: dict,
) -> None:
    """``layout``: sphere → its scenes' fits (scene_fits.json), for the spheres whose data run
    a scene; ``measured_fits``: those spheres' measured load-area fits, in the same order."""
    rows = []
    for sphere, measured in zip(layout, measured_fits, strict=True):
        rows += scene_table_rows(sphere, read_json(measured), read_json(layout[sphere]), models)
    table = pd.DataFrame(rows)
    log.info("\n%s", table.to_string(index=False))
    write_table(table_path, table)


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        measured_fits=list(sm.input.measured),
        layout=sm.params.layout,
        table_path=sm.output.table,
        models=sm.params.models,
    )
