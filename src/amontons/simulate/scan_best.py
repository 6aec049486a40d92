"""The judgement of a parameter scan (docs/study.md §1): the best of its values under the
criterion D of :mod:`amontons.simulate.scan`, and the brackets about it.

Brackets, two of them:

* the scan's resolution: the grid neighbours of the best value (one scan step each side);
* the measured areas' scatter: the values whose χ² = n D² / s² lies within the
  ``confidence`` quantile of χ²(1 dof) above its minimum. ``s`` is the residual standard
  deviation of the measured log areas about their own power-law fit (what a perfect model
  would still miss by), inflated by the Birge ratio sqrt(χ²_min / (n - 1)) where the best
  value misses by more than that (the model, not the measurement, then sets the scatter),
  so that a misfit does not shrink the interval. Near the best value χ² is the parabola
  in ln v through the best value and its two neighbours (its vertex is the ``refined``
  best value); beyond the neighbours it is interpolated linearly in ln v between grid
  points. Where the interval reaches the end of the scan, that side is open (``None``): the
  data do not bound the parameter there (glass: no value of k within the scan changes its
  contact).

The scan's **estimate** is the refined value: the interval is the one about the parabola's
vertex, so it always holds the estimate. The grid's best value need not lie inside it: χ² at
the grid point lies above the vertex's by the parabola's rise over the grid step, which can
exceed the χ² quantile (docs/study.md §4: PS's k). The grid's best is what was solved and
rendered, so the figures and the model table show the model at it, named as the grid's best.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from scipy import stats

from amontons.simulate.scan_grid import ScanError
from amontons.simulate.scan_record import NOT_DECIDED

__all__ = ["ScanBest", "ScanPoint", "best_scan_value", "log_area_scatter", "not_decided_record"]

# Relative difference in D below which two values count as equally good (tie-break: IoU).
TIE = 1e-9


def log_area_scatter(loads: Sequence[float], areas: Sequence[float]) -> float:
    """s: residual standard deviation of ln A about the straight line fitted to ln A against
    ln F (n - 2 degrees of freedom; at least 3 loads)."""
    x = np.log(np.asarray(loads, dtype=float))
    y = np.log(np.asarray(areas, dtype=float))
    if x.size < 3:
        raise ScanError(f"{x.size} measured loads; the scatter needs at least 3")
    residuals = y - np.polyval(np.polyfit(x, y, 1), x)
    return float(np.sqrt(np.sum(residuals**2) / (x.size - 2)))


@dataclass(frozen=True)
class ScanPoint:
    """One scanned value: its log-area distance D, the IoU and the area ratio at the largest
    load (simulated / measured Otsu area)."""

    value: float
    distance: float
    iou_largest: float
    area_ratio_largest: float


@dataclass(frozen=True)
class ScanBest:
    """The best value, its two brackets (``None``: open at the scan's end) and the
    criterion's numbers."""

    value: float
    refined: float
    distance: float
    resolution_low: float | None
    resolution_high: float | None
    scatter_low: float | None
    scatter_high: float | None
    scatter_sd: float
    scatter_sd_used: float
    n_loads: int
    confidence: float
    at_scan_edge: bool

    def to_record(self) -> dict:
        """best.json's judgement: the scan's estimate inside its own interval first, then the
        grid's best (the scanned value the figures and the model table show), under the name
        ``grid_best`` and under its former name ``best``."""
        return {
            "estimate": self.refined,
            "scatter_interval": [self.scatter_low, self.scatter_high],
            "grid_best": self.value,
            "best": self.value,
            "resolution_bracket": [self.resolution_low, self.resolution_high],
            "distance": self.distance,
            "measured_log_area_sd": self.scatter_sd,
            "log_area_sd_used": self.scatter_sd_used,
            "n_loads": self.n_loads,
            "confidence": self.confidence,
            "at_scan_edge": self.at_scan_edge,
            "criterion": "least root-mean-square distance of ln(rendered Otsu area) from "
            "ln(measured Otsu area) over the loads; tie-break: IoU at the largest load",
            "estimate_definition": "the vertex in ln(value) of the parabola of chi2 through the "
            "grid's best value and its two neighbours (the grid's best where it lies at the "
            "scan's end or the three points are not convex); it lies inside scatter_interval",
            "grid_best_definition": "the scanned value with the least distance (also `best`); "
            "distance, iou_largest, area_ratio_largest, best_loads and best_rendered_fit are "
            "its, and it may lie outside scatter_interval, which belongs to the estimate",
            "scatter_interval_definition": "values with n D^2 / s^2 within the chi2(1) "
            "quantile at `confidence` of its minimum; s the residual sd of the measured ln "
            "areas about their power-law fit, inflated by the Birge ratio where the grid's best "
            "value misses by more (log_area_sd_used); a parabola in ln(value) through the grid's "
            "best value and its neighbours (vertex: estimate), linear beyond; null: open at the "
            "scan's end",
        }


def _best_index(points: Sequence[ScanPoint]) -> int:
    distances = np.array([p.distance for p in points])
    best = float(np.min(distances))
    if not np.isfinite(best):
        raise ScanError("no scanned value gives a contact at every load")
    tied = [i for i, d in enumerate(distances) if d <= best * (1 + TIE) + 1e-15]
    return max(tied, key=lambda i: points[i].iou_largest)


def _crossing(x, chi2, i, j, level) -> float:
    """Where χ² crosses ``level`` between scan points i (inside) and j (outside), linear in
    x = ln(value)."""
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


def _scatter_interval(x, chi2, best: int, rise: float):
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


def best_scan_value(
    points: Sequence[ScanPoint], scatter_sd: float, n_loads: int, confidence: float
) -> ScanBest:
    """The best of ``points`` (sorted by value) under the criterion of this module, with its
    resolution and scatter brackets."""
    points = sorted(points, key=lambda p: p.value)
    values = np.array([p.value for p in points])
    best = _best_index(points)
    distances = np.array([p.distance for p in points])
    # A perfect model still misses each ln area by s (floor 1e-6); a model that misses by
    # more sets the scatter itself (Birge ratio; n - 1 degrees of freedom for one parameter).
    sd = max(scatter_sd, 1e-6, distances[best] * np.sqrt(n_loads / max(n_loads - 1, 1)))
    chi2 = n_loads * distances**2 / sd**2
    low, high, refined = _scatter_interval(
        np.log(values), chi2, best, stats.chi2.ppf(confidence, 1)
    )
    return ScanBest(
        value=float(values[best]),
        refined=refined,
        distance=float(points[best].distance),
        resolution_low=float(values[best - 1]) if best > 0 else None,
        resolution_high=float(values[best + 1]) if best < len(values) - 1 else None,
        scatter_low=low,
        scatter_high=high,
        scatter_sd=float(scatter_sd),
        scatter_sd_used=float(sd),
        n_loads=int(n_loads),
        confidence=float(confidence),
        at_scan_edge=best in (0, len(values) - 1),
    )


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
