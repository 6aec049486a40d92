"""The timing model (docs/accuracy.md, "Timing model"): a solve's wall time and peak memory
from its FFT grid, its iterations and its preset, fitted to the accuracy study's measured
points. :func:`predict` is pure Python (the workflow sizes jobs with it while it builds the
DAG); :func:`fit_timing_model` needs numpy.

Per load series on an FFT grid of N points (n² periodic, (2n)² non-periodic):

    iterations per load  I = exp(b0 + b1·log10(1/tol) + b2·ln N)      (per contact model)
    wall time            t = c_0 + c_fix·N + c_it·L·I·N·log2 N
    peak memory          m = m0 + m1·N

c_it is the cost of one CG iteration per N·log2 N (one FFT pair dominates it), c_fix the
per-solve work linear in N (surface, Green's function, plans), c_0 what every solve costs
whatever its grid (FFTW plans, dispatch of the compiled kernels); L the number of loads.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

from amontons.resources import fft_points


def iterations_per_load(model_record: Mapping, tol: float, points: int) -> float:
    b0, b1, b2 = model_record["iterations"]
    return math.exp(b0 + b1 * math.log10(1.0 / tol) + b2 * math.log(points))


def predict(record: Mapping, model: str, *, side_px: int, periodic: bool, loads: int, tol: float):
    """(wall time s, peak memory MB) of a load series of ``loads`` loads: the fitted
    iterations of ``model`` at ``tol`` (a model the study did not measure takes the elastic
    one's), then the time and memory model. ``record``: the JSON :func:`fit_timing_model`
    writes."""
    points = fft_points(side_px, periodic)
    per_model = record["models"].get(model, record["models"]["elastic"])
    iterations = loads * iterations_per_load(per_model, tol, points)
    time = record["time"]
    seconds = (
        time["c_0"]
        + time["c_fix"] * points
        + time["c_it"] * iterations * points * math.log2(points)
    )
    memory = record["memory"]
    return seconds, memory["m0"] + memory["m1"] * points


def fit_timing_model(points: Sequence[Mapping]) -> dict:
    """Fit the model to measured solves: each point a mapping with model, fft_points, loads,
    tol, iterations (all loads), wall_time_s and peak_rss_mb. Time by non-negative least
    squares in relative terms (each point weighted by 1/t, so small solves count as much as
    large ones); memory by the line under which no point lies above by more than its own
    measurement (its largest excess over the fitted baseline); iterations by OLS in logs."""
    import numpy as np
    from scipy.optimize import nnls

    n = np.array([p["fft_points"] for p in points], float)
    t = np.array([p["wall_time_s"] for p in points], float)
    its = np.array([p["iterations"] for p in points], float)
    design = np.column_stack([np.ones_like(n), n, its * n * np.log2(n)]) / t[:, None]
    (c_0, c_fix, c_it), _ = nnls(design, np.ones_like(t))
    predicted = c_0 + c_fix * n + c_it * its * n * np.log2(n)
    memory = np.array([p["peak_rss_mb"] for p in points], float)
    m1, m0 = np.polyfit(n, memory, 1)
    m0 += float(np.max(memory - (m0 + m1 * n)))
    models = {}
    for model in sorted({p["model"] for p in points}):
        rows = [p for p in points if p["model"] == model]
        x = np.column_stack(
            [
                np.ones(len(rows)),
                [math.log10(1.0 / p["tol"]) for p in rows],
                [math.log(p["fft_points"]) for p in rows],
            ]
        )
        y = np.log([p["iterations"] / p["loads"] for p in rows])
        coef, *_ = np.linalg.lstsq(x, y, rcond=None)
        models[model] = {"iterations": [float(c) for c in coef], "points": len(rows)}
    ratio = predicted / t
    return {
        "time": {"c_0": float(c_0), "c_fix": float(c_fix), "c_it": float(c_it)},
        "memory": {"m0": float(m0), "m1": float(m1)},
        "models": models,
        "fit": {
            "points": len(points),
            "time_ratio_range": [float(ratio.min()), float(ratio.max())],
            "note": "predicted / measured wall time at the measured iterations",
        },
    }
