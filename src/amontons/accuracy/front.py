"""Errors against the reference, the Pareto front of error against time, and the presets the
front proposes (docs/accuracy.md, "Errors" and "Presets")."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from amontons.accuracy.compare import relative_l2
from amontons.accuracy.settings import REFERENCE
from amontons.power_law import fit_power_law

# error measure -> what it is (column names of the table end in _error)
ERRORS = {
    "area": "true contact area, largest relative error over the loads",
    "exponent": "load-area exponent of the true area, absolute error",
    "pressure": "pressure field on the common grid, largest relative L2 error over the loads",
    "rendered_area": "rendered Otsu area at the fluorescence pixel, largest relative error",
    "rendered_exponent": "load-area exponent of the rendered Otsu area, absolute error",
}


def exponent(loads_mn: Sequence[float], areas: Sequence[float]) -> float:
    """The load-area power-law exponent (OLS in log-log,
    :func:`amontons.power_law.fit_power_law`)."""
    loads = np.asarray(loads_mn, dtype=float)
    fit = fit_power_law(loads, np.asarray(areas, dtype=float), x_ref=loads[0])
    return float(fit.exponent.estimate)


def _largest_relative(values, reference) -> float:
    values, reference = np.asarray(values, float), np.asarray(reference, float)
    return float(np.max(np.abs(values / reference - 1.0)))


def setting_errors(summary: Mapping, pressure, reference: Mapping, reference_pressure) -> dict:
    """Every error measure of one setting (``summary``: its per-load areas; ``pressure``: its
    per-load pressure on the common grid) against the reference's."""
    loads = [p["load_mn"] for p in summary["loads"]]
    ref_loads = [p["load_mn"] for p in reference["loads"]]
    if not np.allclose(loads, ref_loads):
        raise ValueError(
            f"setting {summary['setting']} has loads {loads} mN, the reference {ref_loads}"
        )

    def column(record, key):
        return [p[key] for p in record["loads"]]

    return {
        "area_error": _largest_relative(column(summary, "area_um2"), column(reference, "area_um2")),
        "exponent_error": abs(
            exponent(loads, column(summary, "area_um2"))
            - exponent(loads, column(reference, "area_um2"))
        ),
        "pressure_error": max(
            relative_l2(p, r) for p, r in zip(pressure, reference_pressure, strict=True)
        ),
        "rendered_area_error": _largest_relative(
            column(summary, "rendered_area_um2"), column(reference, "rendered_area_um2")
        ),
        "rendered_exponent_error": abs(
            exponent(loads, column(summary, "rendered_area_um2"))
            - exponent(loads, column(reference, "rendered_area_um2"))
        ),
    }


def pareto_front(cost: Sequence[float], error: Sequence[float]) -> np.ndarray:
    """Mask of the points no other point beats: none is at most as costly and at most as wrong,
    and strictly better in one of the two."""
    cost, error = np.asarray(cost, float), np.asarray(error, float)
    no_worse = (cost[None, :] <= cost[:, None]) & (error[None, :] <= error[:, None])
    better = (cost[None, :] < cost[:, None]) | (error[None, :] < error[:, None])
    return ~np.any(no_worse & better, axis=1)


def accuracy_table(summaries: Sequence[Mapping], pressures: Mapping[tuple, list]) -> pd.DataFrame:
    """One row per problem and setting: the setting, its cost, its errors against its problem's
    reference and, per error measure, whether it lies on the problem's Pareto front (wall time
    against that error). The reference's own row has zero errors and no front flag."""
    by_problem: dict[str, list[Mapping]] = {}
    for summary in summaries:
        by_problem.setdefault(summary["problem"], []).append(summary)
    rows = []
    for problem, group in by_problem.items():
        reference = next((s for s in group if s["setting"] == REFERENCE), None)
        if reference is None:
            raise ValueError(f"accuracy problem {problem} has no reference solution")
        ref_pressure = pressures[(problem, REFERENCE)]
        problem_rows = []
        for summary in group:
            errors = (
                dict.fromkeys((f"{e}_error" for e in ERRORS), 0.0)
                if summary is reference
                else setting_errors(
                    summary, pressures[(problem, summary["setting"])], reference, ref_pressure
                )
            )
            problem_rows.append({**_cost_columns(summary), **errors})
        frame = pd.DataFrame(problem_rows)
        settings = frame["setting"] != REFERENCE
        for measure in ERRORS:
            on_front = np.zeros(len(frame), bool)
            on_front[settings.to_numpy()] = pareto_front(
                frame.loc[settings, "wall_time_s"], frame.loc[settings, f"{measure}_error"]
            )
            frame[f"{measure}_front"] = on_front
        rows.append(frame)
    return pd.concat(rows, ignore_index=True)


def _cost_columns(summary: Mapping) -> dict:
    keys = (
        "problem",
        "setting",
        "pixel_factor",
        "pixel_nm",
        "tol",
        "window_factor",
        "coarse_to_fine",
        "side_px",
        "fft_points",
        "wall_time_s",
        "peak_rss_mb",
        "iterations",
        "convolutions",
    )
    return {key: summary[key] for key in keys}


def propose_presets(table: pd.DataFrame, budgets: Mapping[str, Mapping[str, float]], problems):
    """Per preset: the cheapest setting (summed wall time over ``problems``) whose errors lie
    within the preset's budget (error measure → largest error) on every one of ``problems``;
    None where no setting does. Returns {preset: record of the setting, its errors and cost}."""
    rows = table[table["problem"].isin(problems) & (table["setting"] != REFERENCE)]
    complete = rows.groupby("setting").filter(lambda g: set(g["problem"]) == set(problems))
    out = {}
    for preset, budget in budgets.items():
        ok = complete.groupby("setting").filter(
            lambda g, budget=budget: all(
                (g[f"{m}_error"] <= limit).all() for m, limit in budget.items()
            )
        )
        if ok.empty:
            out[preset] = None
            continue
        cost = ok.groupby("setting")["wall_time_s"].sum().sort_values()
        best = cost.index[0]
        chosen = ok[ok["setting"] == best]
        out[preset] = {
            "setting": best,
            "budget": dict(budget),
            "wall_time_s": float(cost.iloc[0]),
            "per_problem": {
                row["problem"]: {
                    "pixel_nm": row["pixel_nm"],
                    "side_px": int(row["side_px"]),
                    "tol": row["tol"],
                    "window_factor": row["window_factor"],
                    "coarse_to_fine": bool(row["coarse_to_fine"]),
                    "wall_time_s": row["wall_time_s"],
                    "peak_rss_mb": row["peak_rss_mb"],
                    **{f"{m}_error": row[f"{m}_error"] for m in ERRORS},
                }
                for _, row in chosen.iterrows()
            },
        }
    return out
