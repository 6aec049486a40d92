"""Rule plot_model_curves: appendix Fig. B.12 for one sphere. The measured contact area
against load (symbols) with every model's curve: each scene (rendered Otsu area where it has
optics, else the solver's real area: Greenwood–Tripp) and each scan's best value, with the
power-law fit's exponent and its interval in the legend and the fit's 95 % band. A scan's
curve is the model at the grid's best value, named as such; the title gives the scans'
estimates with their intervals."""

import logging

import numpy as np
import pandas as pd

from amontons.io.files import read_json, write_table
from amontons.power_law import fit_power_law
from amontons.runlog import run_logged
from amontons.simulate.fits import MIN_FIT_LOADS
from amontons.simulate.scan_record import estimate_text, grid_best_label, is_decided
from amontons.study.figures import Curve, plot_area_curves

log = logging.getLogger(__name__)


def fitted_curve(label: str, loads, areas, confidence: float, style: str) -> tuple[Curve, dict]:
    """A model's curve with its fit: the label carries α and its interval."""
    loads = np.asarray(loads, dtype=float)
    areas = np.asarray(areas, dtype=float)
    fit = fit_power_law(loads, areas, x_ref=loads[0], confidence=confidence)
    exponent = fit.exponent
    text = f"{label}: α = {exponent.estimate:.3f} [{exponent.ci_low:.3f}, {exponent.ci_high:.3f}]"
    ratio = loads / loads[0]
    band = (
        fit.prefactor.ci_low * ratio**exponent.ci_low,
        fit.prefactor.ci_high * ratio**exponent.ci_high,
    )
    summary = {
        "exponent": exponent.estimate,
        "exponent_ci_low": exponent.ci_low,
        "exponent_ci_high": exponent.ci_high,
    }
    return Curve(text, loads, areas, style, band), summary


def main(
    measured_path: str,
    measured_fit_path: str,
    scenes: dict,
    scans: dict,
    table_path: str,
    figure_paths: list[str],
    confidence: float,
    label: str,
) -> None:
    measured = pd.read_csv(measured_path)
    measured = measured[measured["contact_found"]]
    fit = read_json(measured_fit_path)["exponent"]
    points = Curve(
        f"measured: α = {fit['estimate']:.3f} [{fit['ci_low']:.3f}, {fit['ci_high']:.3f}]",
        measured["load_mn"].to_numpy(),
        measured["area_um2"].to_numpy(),
    )
    records = [
        {
            "series": "measured",
            "area": "measured Otsu",
            "load_mn": f,
            "area_um2": a,
            "exponent": fit["estimate"],
            "exponent_ci_low": fit["ci_low"],
            "exponent_ci_high": fit["ci_high"],
        }
        for f, a in zip(points.loads_mn, points.areas_um2, strict=True)
    ]
    curves, estimates = [], []
    for name, files in scenes.items():
        if "render" in files:
            table = pd.read_csv(files["render"])
            loads, areas, kind = table["load_mn"], table["rendered_area_um2"], "rendered Otsu"
        else:
            rows = read_json(files["solve"])["loads"]
            loads = [r["load_mn"] for r in rows]
            areas = [r["area_um2"] for r in rows]
            kind = "solver real area"
        if len(loads) < MIN_FIT_LOADS:  # the AFM scan held fewer loads' windows
            estimates.append(f"scene {name} not fitted ({len(loads)} loads in the AFM scan)")
            continue
        curve, summary = fitted_curve(f"scene {name}", loads, areas, confidence, "-")
        curves.append(curve)
        records += [
            {"series": f"scene {name}", "area": kind, "load_mn": f, "area_um2": a, **summary}
            for f, a in zip(curve.loads_mn, curve.areas_um2, strict=True)
        ]
    for name, path in scans.items():
        best = read_json(path)
        if not is_decided(best):  # its AFM scan held no load: no curve to draw
            estimates.append(f"{name} not decided (no load in the AFM scan)")
            continue
        estimates.append(estimate_text(best))
        rows = best["best_loads"]
        # the CSV's series keeps its name; the legend names the grid's best as such
        series = f"{best['scene']}, best {best['parameter']} = {best['grid_best']:g}"
        curve, summary = fitted_curve(
            f"{best['scene']}, {grid_best_label(best)}",
            [r["load_mn"] for r in rows],
            [r["simulated_area_um2"] for r in rows],
            confidence,
            "--",
        )
        curves.append(curve)
        records += [
            {"series": series, "area": "rendered Otsu", "load_mn": f, "area_um2": a, **summary}
            for f, a in zip(curve.loads_mn, curve.areas_um2, strict=True)
        ]
    write_table(table_path, pd.DataFrame(records))
    plot_area_curves(
        points,
        curves,
        f"{label}: measured contact area and every model's ({confidence:.0%} bands); scans' "
        f"estimates: {'; '.join(estimates)}",
        figure_paths,
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        measured_path=sm.input.measured,
        measured_fit_path=sm.input.measured_fit,
        scenes=sm.params.scenes,
        scans=sm.params.scans,
        table_path=sm.output.table,
        figure_paths=[sm.output.png, sm.output.pdf],
        confidence=sm.params.confidence,
        label=sm.params.label,
    )
