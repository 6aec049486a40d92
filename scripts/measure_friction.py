"""Rule measure_friction: static and dynamic friction per load from the rheometer records."""

import logging

from amontons.io.export_map import export_maps
from amontons.io.files import write_table
from amontons.io.layout import per_load_files, rheometer_name
from amontons.io.rheometer_export_shapes import EXPORT_SHAPES
from amontons.measure.friction import measure_friction
from amontons.runlog import run_logged

log = logging.getLogger(__name__)


def main(
    rheometer,
    table_path: str,
    loads_mn: list[float],
    median_window_s: float,
    plateau_fraction: float,
    export: dict | None,
    virtual_format: str | None,
) -> None:
    """``rheometer``: the per-load files, or the virtual experiment's folder of them, written
    in ``virtual_format`` (config virtual_experiment.formats.rheometer; None for measured
    data); ``export``: the export map(s) of the rheometer programs (config rheometer_export,
    or the one the sheet names for the sphere; None: none), which read the files that are
    not our own CSV (amontons.io.rheometer_files)."""
    suffix = ".csv" if virtual_format in (None, "csv") else EXPORT_SHAPES[virtual_format].suffix
    table = measure_friction(
        per_load_files(rheometer, loads_mn, lambda load: rheometer_name(load, suffix)),
        loads_mn,
        median_window_s=median_window_s,
        plateau_fraction=plateau_fraction,
        maps=export_maps(export),
    )
    for row in table.itertuples():
        log.info("%s: %g mN → static %.4g mN", row.file, row.load_mn, row.static_friction_mn)
    write_table(table_path, table)


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        rheometer=sm.input.rheometer,
        table_path=sm.output.table,
        loads_mn=sm.params.loads_mn,
        median_window_s=sm.params.friction["median_window_s"],
        plateau_fraction=sm.params.friction["plateau_fraction"],
        export=sm.params.export,
        virtual_format=sm.params.virtual_format,
    )
