"""The per-material tables of scenes and models against the measured exponent, from the
scenes' fits (:mod:`.fits`, scene_fits.json) and the scans' best values (best.json)
(docs/simulate.md, "Fits and tables"; docs/study.md §3).

Apart from :mod:`.fits` so that a table job, which fits nothing, does not import the fitting
library (statsmodels: 2.6 s a process, docs/study.md §5)."""

from __future__ import annotations

from collections.abc import Mapping

from amontons.models import model_named
from amontons.simulate.scan_record import NOT_DECIDED, NOT_DECIDED_SOURCE

# The exponent columns of a scene that was not fitted: empty, with left_out saying why.
_NO_EXPONENT = {"estimate": None, "ci_low": None, "ci_high": None}


def left_out_note(fit: Mapping) -> str:
    """What a scene's fit lacks, in words ('' for a scene that simulated every load): the
    loads outside the AFM scan and, where it was not fitted, why."""
    notes = []
    outside = fit.get("outside_scan") or []
    if outside:
        loads = ", ".join(f"{row['load_mn']:g}" for row in outside)
        notes.append(f"outside_scan: {loads} mN")
    if fit.get("not_fitted"):
        notes.append(f"not fitted: {fit['not_fitted']}")
    return "; ".join(notes)


def _chosen_fit(fit: Mapping) -> tuple[str, Mapping | None]:
    """The area a scene is judged on (the rendered Otsu area where it has optics) and its fit
    ('not fitted' and None where the scene was not fitted)."""
    if fit.get("not_fitted"):
        return "not fitted", None
    if fit["rendered_area"]:
        return "rendered Otsu", fit["rendered_area"]
    return "solver", fit["solver_area"]


def scene_table_rows(
    sphere: str, measured_fit: Mapping, scene_fits: Mapping[str, Mapping], models: Mapping
) -> list[dict]:
    """One row per scene of ``sphere``: its exponent and interval (the rendered area's where
    the scene has optics, else the solver's) next to the measured exponent."""
    measured = measured_fit["exponent"]
    rows = []
    for scene, record in scene_fits.items():
        area, chosen = _chosen_fit(record)
        exponent = chosen["exponent"] if chosen else _NO_EXPONENT
        solver = record["solver_area"]["exponent"] if record["solver_area"] else _NO_EXPONENT
        difference = None if chosen is None else exponent["estimate"] - measured["estimate"]
        rows.append(
            {
                "sphere": sphere,
                "scene": scene,
                "model": models[scene],
                "area": area,
                "exponent": exponent["estimate"],
                "exponent_ci_low": exponent["ci_low"],
                "exponent_ci_high": exponent["ci_high"],
                "solver_exponent": solver["estimate"],
                "measured_exponent": measured["estimate"],
                "measured_ci_low": measured["ci_low"],
                "measured_ci_high": measured["ci_high"],
                "difference": difference,
                "left_out": left_out_note(record),
            }
        )
    return rows


def _exponent_columns(exponent: Mapping, measured: Mapping) -> dict:
    """An exponent and its interval beside the measured one (empty where not fitted)."""
    fitted = exponent["estimate"] is not None
    return {
        "exponent": exponent["estimate"],
        "exponent_ci_low": exponent["ci_low"],
        "exponent_ci_high": exponent["ci_high"],
        "measured_exponent": measured["estimate"],
        "measured_ci_low": measured["ci_low"],
        "measured_ci_high": measured["ci_high"],
        "exponent_difference": exponent["estimate"] - measured["estimate"] if fitted else None,
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

    ``scenes``: name → {"fit": its entry of scene_fits.json, "largest": the comparison's row
    of the largest load compared or None (no optics, or no load in the scan), "solve":
    solve.json};
    ``scan_bests``: scan name → best.json."""
    measured = measured_fit["exponent"]
    rows = []
    for name, scene in scenes.items():
        area, fit = _chosen_fit(scene["fit"])
        largest = scene["largest"]
        own = model_named(models[name]).parameter
        parameter = None if own is None else own.key
        rows.append(
            {
                "sphere": sphere,
                "model": models[name],
                "source": f"scene {name}",
                "area": area,
                "parameter": parameter,
                "value": scene["solve"].get(parameter) if parameter else None,
                "value_low": None,
                "value_high": None,
                **_exponent_columns(fit["exponent"] if fit else _NO_EXPONENT, measured),
                "area_ratio_largest": largest["area_ratio"] if largest else None,
                "iou_largest": largest["iou"] if largest else None,
                "left_out": left_out_note(scene["fit"]),
            }
        )
    for name, best in scan_bests.items():
        if NOT_DECIDED in best:
            rows.append(_not_decided_row(sphere, name, best, models, measured))
            continue
        low, high = best["interval"]
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
                "left_out": left_out_note(best),
            }
        )
    return rows


def _not_decided_row(
    sphere: str, name: str, best: Mapping, models: Mapping[str, str], measured: Mapping
) -> dict:
    """A scan's row where it was not decided (best.json says why): no value, no exponent,
    and ``left_out`` saying why."""
    return {
        "sphere": sphere,
        "model": models[best["scene"]],
        "source": f"scan {name}, {NOT_DECIDED_SOURCE}",
        "area": "rendered Otsu",
        "parameter": best["parameter"],
        "value": None,
        "value_low": None,
        "value_high": None,
        **_exponent_columns(_NO_EXPONENT, measured),
        "area_ratio_largest": None,
        "iou_largest": None,
        "left_out": f"{NOT_DECIDED_SOURCE}: {best[NOT_DECIDED]}",
    }
