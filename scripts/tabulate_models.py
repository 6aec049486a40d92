"""Rule tabulate_models: the model-comparison table of one material (docs/study.md): every
scene and every scan's best value against the measured load-area exponent, per sphere."""

import logging

import pandas as pd

from amontons.io.files import read_json, write_table
from amontons.runlog import run_logged
from amontons.simulate.fits import model_table_rows

log = logging.getLogger(__name__)


def _largest_row(path: str | None) -> dict | None:
    return None if path is None else pd.read_csv(path).iloc[-1].to_dict()


def main(inputs: dict, table_path: str, spheres: list[str], models: dict) -> None:
    rows = []
    for sphere in spheres:
        own = inputs[sphere]
        scenes = {
            name: {
                "fit": read_json(files["fit"]),
                "solve": read_json(files["solve"]),
                "largest": _largest_row(files.get("comparison")),
            }
            for name, files in own["scenes"].items()
        }
        bests = {name: read_json(path) for name, path in own["scans"].items()}
        rows += model_table_rows(sphere, read_json(own["measured"]), scenes, bests, models)
    table = pd.DataFrame(rows)
    log.info("\n%s", table.to_string(index=False))
    write_table(table_path, table)


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        inputs=sm.params.layout,
        table_path=sm.output.table,
        spheres=sm.params.spheres,
        models=sm.params.models,
    )
