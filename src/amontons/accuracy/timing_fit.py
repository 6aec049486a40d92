"""The timing model fitted to measured solves (docs/accuracy.md, "Timing model"): the law
amontons.accuracy.timing states and predicts with, in least squares. Needs numpy and scipy,
which the DAG does not load: only the rule fit_timing_model and the tests fit."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from scipy.optimize import nnls

from amontons.accuracy.timing import point_features
from amontons.models import ELASTIC


def _fit_elastic(rows: Sequence[Mapping]) -> dict:
    x = np.array([point_features(p) for p in rows])
    y = np.log([p["convolutions"] / p["loads"] for p in rows])
    coef, *_ = np.linalg.lstsq(x, y, rcond=None)
    return {"coef": [float(c) for c in coef], "points": len(rows)}


def _fit_plastic(rows: Sequence[Mapping], elastic: Mapping) -> dict:
    """offset a and exponent γ of a plastic model over the elastic count: least squares in
    logs; γ = 0 where the points hold fewer than two distinct ratios."""
    b = np.array(elastic["coef"])
    base = np.array([np.dot(b, point_features(p)) for p in rows])
    excess = np.log([p["convolutions"] / p["loads"] for p in rows]) - base
    ratios = np.array([p["ratio"] for p in rows], float)
    share = np.log(ratios / (1.0 + ratios))
    if len(np.unique(np.round(share, 6))) < 2:
        return {"offset": float(excess.mean()), "gamma": 0.0, "points": len(rows)}
    x = np.column_stack([np.ones_like(share), share])
    (offset, gamma), *_ = np.linalg.lstsq(x, excess, rcond=None)
    return {"offset": float(offset), "gamma": float(gamma), "points": len(rows)}


def fit_timing_model(points: Sequence[Mapping]) -> dict:
    """Fit the model to measured solves: each point a mapping with model, fft_points,
    periodic, contact_px (periodic: the side), loads, tol, convolutions (all loads), ratio
    (z of a plastic model), wall_time_s and peak_rss_mb.
    Convolutions by least squares in logs (elastic first, each plastic model as its excess
    over the elastic count); time by non-negative least squares in relative terms (each
    point weighted by 1/t, so small solves count as much as large ones); memory by the line
    under which no point lies above by more than its own measurement (its largest excess
    over the fitted baseline)."""
    elastic_rows = [p for p in points if p["model"] == ELASTIC.name]
    if not elastic_rows:
        raise ValueError("the timing model needs elastic solves: none among the points")
    counts = {ELASTIC.name: _fit_elastic(elastic_rows)}
    for model in sorted({p["model"] for p in points} - {ELASTIC.name}):
        rows = [p for p in points if p["model"] == model and p.get("ratio") is not None]
        if rows:
            counts[model] = _fit_plastic(rows, counts[ELASTIC.name])
    n = np.array([p["fft_points"] for p in points], float)
    t = np.array([p["wall_time_s"] for p in points], float)
    work = np.array([p["convolutions"] for p in points], float) * n * np.log2(n)
    (c_0, c_conv), _ = nnls(np.column_stack([np.ones_like(n), work]) / t[:, None], np.ones_like(t))
    memory = np.array([p["peak_rss_mb"] for p in points], float)
    m1, m0 = np.polyfit(n, memory, 1)
    m0 += float(np.max(memory - (m0 + m1 * n)))
    ratio = (c_0 + c_conv * work) / t
    return {
        "time": {"c_0": float(c_0), "c_conv": float(c_conv)},
        "memory": {"m0": float(m0), "m1": float(m1)},
        "convolutions": counts,
        "fit": {
            "points": len(points),
            "time_ratio_range": [float(ratio.min()), float(ratio.max())],
            "note": "predicted / measured wall time at the measured convolutions",
        },
    }
