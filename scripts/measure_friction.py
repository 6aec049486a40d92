"""Rule measure_friction: static and dynamic friction per load from the rheometer records."""

import logging

from amontons.images import atomic_path
from amontons.measurements import measure_friction
from amontons.runlog import run_logged

log = logging.getLogger(__name__)


def main(
    rheometer_dir: str,
    table_path: str,
    loads_mn: list[float],
    median_window_s: float,
    plateau_fraction: float,
) -> None:
    table = measure_friction(
        rheometer_dir,
        loads_mn,
        median_window_s=median_window_s,
        plateau_fraction=plateau_fraction,
    )
    for row in table.itertuples():
        log.info("%s: %g mN → static %.4g mN", row.file, row.load_mN, row.static_friction_mN)
    with atomic_path(table_path) as tmp:
        table.to_csv(tmp, index=False)


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        rheometer_dir=sm.params.rheometer_dir,
        table_path=sm.output.table,
        loads_mn=sm.params.loads_mn,
        median_window_s=sm.params.friction["median_window_s"],
        plateau_fraction=sm.params.friction["plateau_fraction"],
    )
