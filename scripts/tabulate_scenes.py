"""Rule tabulate_scenes: every scene's load-area exponent of one material next to the measured
exponent of each sphere."""

import logging

import pandas as pd

from amontons.io.files import read_json, write_table
from amontons.runlog import run_logged
from amontons.simulate.fits import scene_table_rows

log = logging.getLogger(__name__)


def main(
    measured_fits: list[str],
    scene_fits: list[str],
    table_path: str,
    spheres: list[str],
    scenes: list[str],
    models: dict,
) -> None:
    rows = []
    per_sphere = len(scenes)
    for index, sphere in enumerate(spheres):
        fits = scene_fits[index * per_sphere : (index + 1) * per_sphere]
        rows += scene_table_rows(
            sphere,
            read_json(measured_fits[index]),
            {scene: read_json(path) for scene, path in zip(scenes, fits, strict=True)},
            models,
        )
    table = pd.DataFrame(rows)
    log.info("\n%s", table.to_string(index=False))
    write_table(table_path, table)


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        measured_fits=list(sm.input.measured),
        scene_fits=list(sm.input.scenes),
        table_path=sm.output.table,
        spheres=sm.params.spheres,
        scenes=sm.params.scenes,
        models=sm.params.models,
    )
