"""Rule plot_curvature_study: appendix Fig. B.10. Real contact area against load of a synthetic
self-affine surface on a flat periodic and on a curved non-periodic interface, for each model
of the configured pairs, on log-log axes with the linear and the 2/3 power law: whether the
sphere's curvature changes the load-area exponent."""

import logging

import numpy as np
import pandas as pd

from amontons.io.files import read_json, write_table
from amontons.runlog import run_logged
from amontons.study.figures import Curve, plot_area_curves

log = logging.getLogger(__name__)


def main(pairs: dict, solves: dict, fits: dict, table_path: str, figure_paths: list[str]):
    records, curves, notes = [], [], []
    for model, (flat, curved) in pairs.items():
        exponents = {}
        for geometry, scene in (("flat periodic", flat), ("curved", curved)):
            rows = read_json(solves[scene])["loads"]
            exponent = read_json(fits[scene])[scene]["solver_area"]["exponent"]
            exponents[geometry] = exponent["estimate"]
            loads = np.array([r["load_mn"] for r in rows])
            areas = np.array([r["area_um2"] for r in rows])
            # Each curve over its own area at its first load: the two geometries carry
            # different loads (a flat window against one contact), the exponents compare.
            curves.append(
                Curve(
                    f"{model}, {geometry} ({scene}): α = {exponent['estimate']:.3f}",
                    loads / loads[0],
                    areas / areas[0],
                    "-" if geometry == "flat periodic" else "--",
                )
            )
            records += [
                {
                    "model": model,
                    "geometry": geometry,
                    "scene": scene,
                    "load_mn": f,
                    "area_um2": a,
                    "load_over_first": f / loads[0],
                    "area_over_first": a / areas[0],
                    "exponent": exponent["estimate"],
                    "exponent_ci_low": exponent["ci_low"],
                    "exponent_ci_high": exponent["ci_high"],
                }
                for f, a in zip(loads, areas, strict=True)
            ]
        difference = exponents["curved"] - exponents["flat periodic"]
        notes.append(f"{model}: curved - flat = {difference:+.3f}")
        log.info("%s: flat %.4f, curved %.4f", model, *exponents.values())
    table = pd.DataFrame(records)
    write_table(table_path, table)
    plot_area_curves(
        None,
        curves,
        "Synthetic self-affine surface, flat periodic (solid) and curved (dashed): "
        + "; ".join(notes),
        figure_paths,
        guides_at=1.0,
        xlabel="F / F(first load)",
        ylabel="A / A(first load)",
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        pairs=sm.params.pairs,
        solves=sm.params.solves,
        fits=sm.params.fits,
        table_path=sm.output.table,
        figure_paths=[sm.output.png, sm.output.pdf],
    )
