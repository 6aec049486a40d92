"""Load-area power laws of a scene and the per-material table of scenes against the measurement
(docs/simulate.md, "Fits and tables")."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from amontons.fits import fit_power_law


def scene_area_fits(
    loads_mn: Sequence[float],
    solver_areas_um2: Sequence[float],
    rendered_areas_um2: Sequence[float] | None,
    confidence: float,
) -> dict:
    """A = A_ref·(F/F_ref)^α fitted to the solver's true area and, for a scene with optics, to
    the rendered Otsu area (F_ref: the first load; areas in µm²)."""
    loads = np.asarray(loads_mn, dtype=float)

    def fit(areas):
        return fit_power_law(
            loads, np.asarray(areas, dtype=float), x_ref=loads[0], confidence=confidence
        ).to_record()

    return {
        "quantity": "real contact area versus normal load of a simulated scene, "
        "A = A_ref (F / F_ref)^exponent",
        "units": {"prefactor": "um2 (area at x_ref)", "x_ref": "mN"},
        "solver_area": fit(solver_areas_um2),
        "rendered_area": None if rendered_areas_um2 is None else fit(rendered_areas_um2),
    }


def scene_table_rows(
    sphere: str, measured_fit: Mapping, scene_fits: Mapping[str, Mapping], models: Mapping
) -> list[dict]:
    """One row per scene of ``sphere``: its exponent and interval (the rendered area's where
    the scene has optics, else the solver's) next to the measured exponent."""
    measured = measured_fit["exponent"]
    rows = []
    for scene, record in scene_fits.items():
        chosen = record["rendered_area"] or record["solver_area"]
        exponent = chosen["exponent"]
        solver = record["solver_area"]["exponent"]
        rows.append(
            {
                "sphere": sphere,
                "scene": scene,
                "model": models[scene],
                "area": "rendered Otsu" if record["rendered_area"] else "solver",
                "exponent": exponent["estimate"],
                "exponent_ci_low": exponent["ci_low"],
                "exponent_ci_high": exponent["ci_high"],
                "solver_exponent": solver["estimate"],
                "measured_exponent": measured["estimate"],
                "measured_ci_low": measured["ci_low"],
                "measured_ci_high": measured["ci_high"],
                "difference": exponent["estimate"] - measured["estimate"],
            }
        )
    return rows


def _exponent_columns(exponent: Mapping, measured: Mapping) -> dict:
    return {
        "exponent": exponent["estimate"],
        "exponent_ci_low": exponent["ci_low"],
        "exponent_ci_high": exponent["ci_high"],
        "measured_exponent": measured["estimate"],
        "measured_ci_low": measured["ci_low"],
        "measured_ci_high": measured["ci_high"],
        "exponent_difference": exponent["estimate"] - measured["estimate"],
    }


def model_table_rows(
    sphere: str,
    measured_fit: Mapping,
    scenes: Mapping[str, Mapping],
    scan_bests: Mapping[str, Mapping],
    models: Mapping[str, str],
) -> list[dict]:
    """The model-comparison rows of one sphere (docs/study.md): each scene at its configured
    parameter and each scan's best value, with its load-area exponent and interval beside the
    measured one, its parameter, and the area ratio and IoU at the largest load.

    ``scenes``: name → {"fit": scene_fit.json, "largest": the comparison's last row or None
    (no optics), "solve": solve.json}; ``scan_bests``: scan name → best.json."""
    measured = measured_fit["exponent"]
    rows = []
    for name, scene in scenes.items():
        fit = scene["fit"]["rendered_area"] or scene["fit"]["solver_area"]
        largest = scene["largest"]
        parameter = {"penetration_hardness": "p_y_mpa", "hardening": "k_mpa_per_nm"}.get(
            models[name]
        )
        rows.append(
            {
                "sphere": sphere,
                "model": models[name],
                "source": f"scene {name}",
                "area": "rendered Otsu" if scene["fit"]["rendered_area"] else "solver",
                "parameter": parameter,
                "value": scene["solve"][parameter] if parameter else None,
                "value_low": None,
                "value_high": None,
                **_exponent_columns(fit["exponent"], measured),
                "area_ratio_largest": largest["area_ratio"] if largest else None,
                "iou_largest": largest["iou"] if largest else None,
            }
        )
    for name, best in scan_bests.items():
        low, high = best["scatter_interval"]
        rows.append(
            {
                "sphere": sphere,
                "model": models[best["scene"]],
                "source": f"scan {name}, best value",
                "area": "rendered Otsu",
                "parameter": best["parameter"],
                "value": best["best"],
                "value_low": low,
                "value_high": high,
                **_exponent_columns(best["best_rendered_fit"]["exponent"], measured),
                "area_ratio_largest": best["area_ratio_largest"],
                "iou_largest": best["iou_largest"],
            }
        )
    return rows
