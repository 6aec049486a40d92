"""The judgement of a parameter scan (docs/study.md §1): the best of its values under the
criterion of :mod:`amontons.simulate.scan_criterion` (χ² of the log-area residuals, counting
the measured scatter and the model's error), the estimate and its interval.

* **The interval**: the values whose χ² lies within the criterion's quantile (F(1, ν), ν the
  parameter's degrees of freedom: n − 2 without model error) above its minimum. Near the
  best solved value χ² is the parabola in ln v through it and its two solved neighbours (its
  vertex is the ``refined`` value, the scan's **estimate**); beyond them it is interpolated
  linearly in ln v between solved values. Read off solved values only where they lie close
  about it: the scan job refines the grid there (:mod:`amontons.simulate.scan_refine`) and
  :func:`interval_resolution` says how close they lie. Where the interval reaches the end
  of the scan, that side is open (``None``): the data bound the parameter on one side only,
  and the record states a bound.
* **The grid's best**: the coarse grid's value of least χ² (the figures and the model table
  show the model there, and name it so). It need not lie inside the interval, which belongs
  to the estimate.
* **The resolution bracket**: the grid's best value's neighbours on the coarse grid (one
  scan step each side).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from amontons.simulate.scan_criterion import (
    MIN_LOADS,
    Criterion,
    ModelError,
    TooFewLoads,
)
from amontons.simulate.scan_grid import ScanError
from amontons.simulate.scan_record import NOT_DECIDED

__all__ = [
    "ScanBest",
    "ScanPoint",
    "best_scan_value",
    "best_targets",
    "criterion_of_record",
    "elastic_limit_chi2",
    "finite_or_none",
    "floored_log_residuals",
    "model_error_of_record",
    "rms",
    "interval_resolution",
    "interval_width_ln",
    "measured_rows",
    "point_from_record",
    "not_decided_record",
    "too_few_loads_record",
]

# Relative difference in χ² below which two values count as equally good (tie-break: IoU).
TIE = 1e-9


@dataclass(frozen=True)
class ScanPoint:
    """One solved value: its log-area distance D, the IoU and the area ratio at the largest
    load (simulated / measured Otsu area), and its residuals ln A_sim − ln A_meas at the
    criterion's loads (inf where the contact left the window)."""

    value: float
    distance: float
    iou_largest: float
    area_ratio_largest: float
    residuals: tuple[float, ...]

    @classmethod
    def outside_window(cls, value: float, n_loads: int) -> ScanPoint:
        """A value whose contact left the solver window: never best."""
        return cls(value, float("inf"), 0.0, float("inf"), (float("inf"),) * n_loads)


@dataclass(frozen=True)
class ScanBest:
    """The estimate with its interval (``None``: open at the scan's end), the grid's best
    and the criterion's numbers."""

    value: float
    refined: float
    distance: float
    chi2_min: float
    resolution_low: float | None
    resolution_high: float | None
    scatter_low: float | None
    scatter_high: float | None
    scatter_sd: float
    scatter_sd_used: float
    n_loads: int
    confidence: float
    rise: float
    at_scan_edge: bool
    chi2_min_measured: float = float("nan")
    elastic_end: float = float("nan")
    chi2_elastic_end: float = float("nan")
    chi2_elastic_end_measured: float = float("nan")

    @property
    def estimate(self) -> float | None:
        """The scan's estimate where its interval is closed on both sides; None where the data
        bound the parameter on one side only (a bound has no point estimate: the least χ²
        of a scan that reaches its end says nothing of where the parameter lies beyond)."""
        bounded = self.scatter_low is not None and self.scatter_high is not None
        return self.refined if bounded else None

    @property
    def elastic_excluded(self) -> bool:
        """Whether the data exclude the scan's elastic end (its highest value: the most
        nearly elastic contact it solved) against its best value, at the interval's
        confidence."""
        return bool(self.chi2_elastic_end - self.chi2_min > self.rise)

    def to_record(self) -> dict:
        """best.json's judgement: the scan's estimate inside its own interval first, then the
        grid's best (the scanned value the figures and the model table show), under the name
        ``grid_best`` and under its former name ``best``."""
        return {
            "estimate": self.estimate,
            "interval": [self.scatter_low, self.scatter_high],
            "grid_best": self.value,
            "best": self.value,
            "resolution_bracket": [self.resolution_low, self.resolution_high],
            "distance": self.distance,
            "chi2_min": self.chi2_min,
            "chi2_rise": self.rise,
            "chi2_min_measured_sd": self.chi2_min_measured,
            "elastic_end": self.elastic_end,
            "chi2_elastic_end": finite_or_none(self.chi2_elastic_end),
            "chi2_elastic_end_measured_sd": finite_or_none(self.chi2_elastic_end_measured),
            "elastic_excluded": self.elastic_excluded,
            "measured_log_area_sd": self.scatter_sd,
            "log_area_sd_used": self.scatter_sd_used,
            "n_loads": self.n_loads,
            "confidence": self.confidence,
            "at_scan_edge": self.at_scan_edge,
            "criterion": "chi2 of the residuals ln(rendered Otsu area) - bias - ln(measured "
            "Otsu area) over the loads, under C = s^2 I + offset_sd^2 11' + slope_sd^2 "
            "(x - mean x)(x - mean x)' + sum of u u' over the modes, x = ln F (model_error); "
            "tie-break: IoU at the largest load",
            "estimate_definition": "the vertex in ln(value) of the parabola of chi2 through the "
            "solved value of least chi2 and its two solved neighbours (that value itself where "
            "it lies at the scan's end or the three are not convex); it lies inside interval; "
            "null where the interval is open at an end (a bound, with no point estimate)",
            "grid_best_definition": "the coarse grid's value of least chi2 (also `best`); "
            "distance, iou_largest, area_ratio_largest, best_loads and best_rendered_fit are "
            "its, and it may lie outside interval, which belongs to the estimate",
            "elastic_end_definition": "the scan's highest solved value, its most nearly "
            "elastic contact: elastic_excluded where its chi2 lies above chi2_min by more than "
            "chi2_rise; the *_measured_sd chi2 are taken under the measured scatter, before "
            "the Birge ratio: the verdict compares the models by them",
            "interval_definition": "values whose chi2 lies within chi2_rise (the F(1, nu) "
            "quantile at `confidence`, nu = n - 2 without model error and more, by "
            "Welch-Satterthwaite, as the stated model error takes a share of the parameter's "
            "variance) of its minimum; s the residual sd of the measured ln "
            "areas about their power-law fit, inflated by the Birge ratio where the best value "
            "misses by more than s and the model error allow (log_area_sd_used); a parabola in "
            "ln(value) near the estimate, linear between solved values beyond; null: open at "
            "the scan's end (a bound)",
        }


def finite_or_none(value: float) -> float | None:
    """``value`` where finite, else None (JSON has no infinity: a scan's elastic end whose
    contact is lost at a load has no χ² to state)."""
    return value if math.isfinite(value) else None


def floored_log_residuals(
    simulated_m2: Sequence[float], measured_m2: Sequence[float], floor_m2: float
) -> tuple[float, ...]:
    """ln A_sim − ln A_meas per load, a rendered area below ``floor_m2`` (m²; one image
    pixel, the least contact the threshold can find) taken at it: a load where the model
    renders no contact misses by at least that much, and the χ² stays finite to be
    compared (used for the elastic limit, whose contact is the smallest)."""
    return tuple(
        math.log(max(s, floor_m2) / m) for s, m in zip(simulated_m2, measured_m2, strict=True)
    )


def _best_index(chi2: np.ndarray, points: Sequence[ScanPoint], among: Sequence[int]) -> int:
    """The index of least χ² among ``among`` (ties: the larger IoU at the largest load)."""
    best = float(np.min(chi2[list(among)]))
    if not np.isfinite(best):
        raise ScanError("no scanned value gives a contact at every load")
    tied = [i for i in among if chi2[i] <= best * (1 + TIE) + 1e-15]
    return max(tied, key=lambda i: points[i].iou_largest)


def _crossing(x, chi2, i, j, level) -> float:
    """Where χ² crosses ``level`` between scan points i (inside) and j (outside), linear in
    x = ln(value); at j itself where j has no χ² (its contact left the window: the crossing
    lies somewhere between, and the interval keeps the whole step, which refinement
    bisects)."""
    if not np.isfinite(chi2[j]):
        return float(np.exp(x[j]))
    f = (level - chi2[i]) / (chi2[j] - chi2[i])
    return float(np.exp(x[i] + f * (x[j] - x[i])))


def _linear_bound(x, chi2, start: int, step: int, level: float) -> float | None:
    """The first crossing of ``level`` walking from ``start`` by ``step``; None past the end."""
    j = start + step
    while 0 <= j < len(x):
        if chi2[j] > level:
            return _crossing(x, chi2, j - step, j, level)
        j += step
    return None


def _parabola(x, chi2, best: int):
    """Curvature a and vertex x0 of the parabola through the best point and its neighbours
    (None where the best point is at an end, or the three points are not convex)."""
    if best in (0, len(x) - 1) or not np.all(np.isfinite(chi2[best - 1 : best + 2])):
        return None
    a, b, _ = np.polyfit(x[best - 1 : best + 2], chi2[best - 1 : best + 2], 2)
    return (a, -b / (2 * a)) if a > 0 else None


def _profile_interval(x, chi2, best: int, rise: float):
    """(low, high, refined): the interval where χ² lies within ``rise`` of its minimum."""
    parabola = _parabola(x, chi2, best)
    if parabola is None:
        level = chi2[best] + rise
        low = _linear_bound(x, chi2, best, -1, level) if best > 0 else None
        high = _linear_bound(x, chi2, best, +1, level) if best < len(x) - 1 else None
        return low, high, float(np.exp(x[best]))
    a, x0 = parabola
    half = np.sqrt(rise / a)
    level = chi2[best] - a * (x[best] - x0) ** 2 + rise  # vertex value + rise
    low = (
        float(np.exp(x0 - half))
        if x0 - half >= x[best - 1]
        else _linear_bound(x, chi2, best - 1, -1, level)
    )
    high = (
        float(np.exp(x0 + half))
        if x0 + half <= x[best + 1]
        else _linear_bound(x, chi2, best + 1, +1, level)
    )
    return low, high, float(np.exp(np.clip(x0, x[best - 1], x[best + 1])))


def _neighbours(values: np.ndarray, target: float) -> tuple[float | None, float | None]:
    """The solved values either side of ``target`` (a solved value is its own neighbour)."""
    below = values[values <= target]
    above = values[values >= target]
    return (
        float(below.max()) if below.size else None,
        float(above.min()) if above.size else None,
    )


def chi2_of_points(
    points: Sequence[ScanPoint], criterion: Criterion
) -> tuple[np.ndarray, np.ndarray, float, int]:
    """(χ² of every point, in the order of ``points``, under the random part Birge-inflated at
    the best point, and under the measured scatter; that random part; the index of least
    χ²)."""
    measured = np.array([criterion.chi2_measured(p.residuals) for p in points])
    sd = criterion.random_sd_used(
        points[_best_index(measured, points, range(len(points)))].residuals
    )
    chi2 = np.array([criterion.chi2(p.residuals, sd) for p in points])
    # the least under the covariance the interval is read with: a shared error can reorder
    # the values between the measured scatter and the inflated one
    return chi2, measured, sd, _best_index(chi2, points, range(len(points)))


def residual_gradient(points: Sequence[ScanPoint], best: int) -> np.ndarray | None:
    """How the residuals move per unit of ln v at the best point: the mean of its one-sided
    differences to its solved neighbours with finite residuals (None where it has none)."""
    here = np.asarray(points[best].residuals)
    slopes = []
    for j in (best - 1, best + 1):
        if 0 <= j < len(points) and np.all(np.isfinite(points[j].residuals)):
            step = math.log(points[j].value / points[best].value)
            slopes.append((np.asarray(points[j].residuals) - here) / step)
    return np.mean(slopes, axis=0) if slopes else None


def best_scan_value(
    points: Sequence[ScanPoint],
    criterion: Criterion,
    confidence: float,
    grid: Sequence[float] | None = None,
) -> ScanBest:
    """The estimate of ``points`` (every solved value, any order) under ``criterion``, its
    interval at ``confidence``, and the best of the coarse ``grid``'s values (None: every
    point is the grid's)."""
    points = sorted(points, key=lambda p: p.value)
    values = np.array([p.value for p in points])
    chi2, measured, sd, best = chi2_of_points(points, criterion)
    rise = criterion.rise(confidence, residual_gradient(points, best), sd)
    low, high, refined = _profile_interval(np.log(values), chi2, best, rise)
    coarse = None if grid is None else {float(g) for g in grid}
    on_grid = [i for i, v in enumerate(values) if coarse is None or float(v) in coarse]
    grid_best = _best_index(chi2, points, on_grid)
    # the scan's resolution: the grid's best value's neighbours on the coarse grid
    position = on_grid.index(grid_best)
    below = float(values[on_grid[position - 1]]) if position > 0 else None
    above = float(values[on_grid[position + 1]]) if position < len(on_grid) - 1 else None
    return ScanBest(
        value=float(values[grid_best]),
        refined=refined,
        distance=float(points[grid_best].distance),
        chi2_min=float(chi2[best]),
        resolution_low=below,
        resolution_high=above,
        scatter_low=low,
        scatter_high=high,
        scatter_sd=float(criterion.scatter_sd),
        scatter_sd_used=float(sd),
        n_loads=criterion.n,
        confidence=float(confidence),
        rise=rise,
        at_scan_edge=grid_best in (on_grid[0], on_grid[-1]),
        chi2_min_measured=float(np.min(measured)),
        elastic_end=float(values[-1]),
        chi2_elastic_end=float(chi2[-1]),
        chi2_elastic_end_measured=float(measured[-1]),
    )


def interval_width_ln(best: ScanBest, values: Sequence[float]) -> float:
    """The interval's width in ln v; where an end is open, up to the scan's end on that
    side."""
    low = best.scatter_low if best.scatter_low is not None else min(values)
    high = best.scatter_high if best.scatter_high is not None else max(values)
    return float(np.log(high / low)) if high > low else 0.0


def interval_resolution(values: Sequence[float], best: ScanBest) -> dict[str, dict]:
    """The solved ``values`` about the estimate and each closed end of its interval, and
    their spacing in ln v: what the interpolation between solved values could move each of
    them by at most."""
    solved = np.sort(np.asarray(values, dtype=float))
    out = {}
    for name, target in best_targets(best).items():
        below, above = _neighbours(solved, target)
        spacing = None if below is None or above is None else float(np.log(above / below))
        out[name] = {"value": target, "solved_neighbours": [below, above], "spacing_ln": spacing}
    return out


def best_targets(best: ScanBest) -> dict[str, float]:
    """The values a scan's answer is read at: its estimate and its interval's closed ends."""
    targets = {"estimate": best.refined, "low": best.scatter_low, "high": best.scatter_high}
    return {name: value for name, value in targets.items() if value is not None}


def measured_rows(record: Mapping) -> list[dict]:
    """A solved value's comparison rows (scan_point.json) at the loads the criterion reads:
    those whose measured image shows a contact."""
    return [row for row in record["loads"] if row["measured_contact_found"]]


def criterion_of_record(record: Mapping, model_error: ModelError | None = None) -> Criterion:
    """The criterion of a solved value's measured loads (scan_point.json; every solved value
    of a scan has the same), with ``model_error`` (None: the measured scatter alone)."""
    rows = measured_rows(record)
    return Criterion.of_measured(
        [row["load_mn"] for row in rows], [row["measured_area_um2"] for row in rows], model_error
    )


def rms(residuals: Sequence[float]) -> float:
    """The root-mean-square of ``residuals`` (ln area): D of residuals already formed, such as
    :func:`floored_log_residuals`'s."""
    return math.sqrt(sum(r * r for r in residuals) / len(residuals))


def model_error_of_record(record: Mapping | None) -> ModelError | None:
    """The model error a scan job counted (refinement.json's ``model_error``: measured, or
    stated where it could not be measured); None where it records none."""
    return ModelError.from_record(record) if record and "bias" in record else None


def elastic_limit_chi2(record: Mapping, elastic_limit: Mapping | None) -> float | None:
    """χ² of the elastic limit (refinement.json's ``elastic_limit``: the elastic model solved
    on the scan's window) under the measured scatter of ``record``'s loads (a solved value's
    scan_point.json) and the elastic model's own error; None where it was not solved."""
    if not elastic_limit or not elastic_limit.get("solved"):
        return None
    criterion = criterion_of_record(record, model_error_of_record(elastic_limit["model_error"]))
    return criterion.chi2_measured(elastic_limit["residuals"])


def point_from_record(record: Mapping, n_loads: int) -> ScanPoint:
    """A value's :class:`ScanPoint` from its scan_point.json (``n_loads``: the criterion's
    loads; a value whose contact left the window is never best)."""
    if record["outside_window"] is not None:
        return ScanPoint.outside_window(record["value"], n_loads)
    # a load with no simulated contact matches nothing: an infinite residual
    residuals = tuple(
        math.log(row["simulated_area_um2"] / row["measured_area_um2"])
        if row["simulated_area_um2"] > 0
        else math.inf
        for row in measured_rows(record)
    )
    return ScanPoint(
        record["value"],
        record["log_area_distance"],
        record["iou_largest"],
        record["area_ratio_largest"],
        residuals,
    )


def too_few_loads_record(record: Mapping, error: TooFewLoads, values: Sequence[float]) -> dict:
    """best.json of a scan whose measured loads are too few to judge (``record``: one value's
    scan_point.json): not decided, with the loads it holds and the loads the criterion needs."""
    return {
        "sphere": record["sphere"],
        "scene": record["scene"],
        "parameter": record["parameter"],
        "values": list(values),
        NOT_DECIDED: f"too few loads to judge: {error}",
        "measured_loads_mn": error.loads_mn,
        "loads_needed": MIN_LOADS,
        "outside_scan": record["outside_scan"],
    }


def not_decided_record(points: Sequence[Mapping]) -> dict:
    """best.json of a scan with nothing to judge: its AFM scan holds none of the loads'
    windows, so no value was solved (``points``: every value's scan_point.json, which then
    carries the scan's size and the largest window about the apex it holds). Says why, with
    the loads left out and each one's window, the scan's size and the largest window in it
    (µm); no estimate, interval or grid's best."""
    first = points[0]
    outside = first["outside_scan"]
    windows = [row["window_um"] for row in outside]
    scan = " × ".join(f"{side:.1f}" for side in first["scan_um"])
    loads = ", ".join(f"{row['load_mn']:g}" for row in outside)
    why = (
        f"the AFM scan ({scan} µm) holds no load's window about the apex: the largest window "
        f"it holds is {first['largest_window_in_scan_um']:.1f} µm, and the windows of the "
        f"loads ({loads} mN) need {min(windows):.1f} to {max(windows):.1f} µm; a scan is "
        "judged on the loads whose window the scan holds"
    )
    return {
        "sphere": first["sphere"],
        "scene": first["scene"],
        "parameter": first["parameter"],
        "values": [point["value"] for point in points],
        NOT_DECIDED: why,
        "outside_scan": outside,
        "scan_um": first["scan_um"],
        "largest_window_in_scan_um": first["largest_window_in_scan_um"],
    }
