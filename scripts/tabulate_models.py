"""Rule tabulate_models: the model-comparison table of one material (docs/study.md): every
scene and every scan's best value against the measured load-area exponent, per sphere.

A scan's row is the model at the grid's best value (``value``: what was solved, so the
exponent, area ratio and IoU are its), with the scan's estimate and the interval that belongs
to it (``estimate``, ``estimate_low``, ``estimate_high``); the grid's best may lie outside
that interval (docs/study.md §1)."""

import logging

import pandas as pd

from amontons.io.files import read_json, write_table
from amontons.runlog import run_logged
from amontons.simulate.compare import largest_compared
from amontons.simulate.scan_record import estimate_columns
from amontons.simulate.tables import model_table_rows

log = logging.getLogger(__name__)

# model_table_rows gives a scan row the interval as value_low/value_high, beside the grid's
# best in `value`, which it need not hold; the table gives it beside the estimate instead.
_VALUE_INTERVAL = ("value_low", "value_high")


def _largest_row(path: str | None) -> dict | None:
    """The comparison's row of the largest load compared (None: no optics, or none compared)."""
    if path is None:
        return None
    return largest_compared(pd.read_csv(path).to_dict("records"))


def with_estimate(row: dict, best: dict | None) -> dict:
    """``row`` with the scan's estimate and its interval after ``value`` (empty for a scene)
    in place of the interval beside the grid's best."""
    out = {}
    for key, cell in row.items():
        if key in _VALUE_INTERVAL:
            continue
        out[key] = cell
        if key == "value":
            out.update(estimate_columns(best))
    return out


def sphere_rows(sphere: str, files: dict, models: dict) -> list[dict]:
    """The model-table rows of one sphere: its scenes, then its scans' best values."""
    measured = read_json(files["measured"])
    fits = read_json(files["fits"])
    scenes = {
        name: {
            "fit": fits[name],
            "solve": read_json(own["solve"]),
            "largest": _largest_row(own.get("comparison")),
        }
        for name, own in files["scenes"].items()
    }
    rows = [
        with_estimate(row, None) for row in model_table_rows(sphere, measured, scenes, {}, models)
    ]
    for name, path in files["scans"].items():
        best = read_json(path)
        (row,) = model_table_rows(sphere, measured, {}, {name: best}, models)
        rows.append(with_estimate(row, best))
    return rows


def main(inputs: dict, table_path: str, spheres: list[str], models: dict) -> None:
    table = pd.DataFrame(
        [row for sphere in spheres for row in sphere_rows(sphere, inputs[sphere], models)]
    )
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
