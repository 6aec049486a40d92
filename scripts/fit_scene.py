"""Rule fit_scene: a scene's load-area power law, from the solver's area and (with optics)
from the rendered Otsu area."""

import logging

import pandas as pd

from amontons.io.files import read_json, write_json
from amontons.runlog import run_logged
from amontons.simulate.fits import scene_area_fits

log = logging.getLogger(__name__)


def main(solve_path: str, render_path: str | None, fit_path: str, confidence: float) -> None:
    solve = read_json(solve_path)
    loads = solve["loads"]
    rendered = None
    if render_path is not None:
        rendered = pd.read_csv(render_path)["rendered_area_um2"].to_list()
    record = scene_area_fits(
        [row["load_mn"] for row in loads],
        [row["area_um2"] for row in loads],
        rendered,
        confidence,
        solve.get("outside_scan", []),
    )
    if record["not_fitted"]:
        log.warning("%s: %s", solve_path, record["not_fitted"])
    else:
        exponent = record["solver_area"]["exponent"]["estimate"]
        log.info("%s: solver-area exponent %.4f", solve_path, exponent)
    write_json(fit_path, record)


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        solve_path=sm.input.solve,
        render_path=sm.input.get("render"),
        fit_path=sm.output.fit,
        confidence=sm.params.confidence,
    )
