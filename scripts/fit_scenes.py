"""Rules fit_sphere_scenes and fit_synthetic_scene: each scene's load-area power law, from the
solver's area and (with optics) from the rendered Otsu area, into one file (scene → fit).

A sphere's scenes are fitted in one job: a fit takes milliseconds, the job's imports
(statsmodels, pandas) seconds (docs/study.md §5)."""

import logging

import pandas as pd

from amontons.io.files import read_json, write_json
from amontons.runlog import run_logged
from amontons.simulate.fits import scene_area_fits

log = logging.getLogger(__name__)


def scene_fit(solve_path: str, render_path: str | None, confidence: float) -> dict:
    """One scene's fits from its solve record and, with optics, its render table."""
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
    return record


def main(layout: dict[str, dict[str, str]], fits_path: str, confidence: float) -> None:
    """``layout``: scene → {"solve": solve.json, "render": render.csv (with optics)}."""
    fits = {
        scene: scene_fit(files["solve"], files.get("render"), confidence)
        for scene, files in layout.items()
    }
    write_json(fits_path, fits)


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        layout=sm.params.layout,
        fits_path=sm.output.fits,
        confidence=sm.params.confidence,
    )
