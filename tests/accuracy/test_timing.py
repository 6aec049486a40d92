"""The timing model: it recovers the law it was fitted on, and predicts in pure Python."""

import math

import pytest

from amontons.accuracy.timing import fit_timing_model, predict


def _points(c_0=0.2, c_fix=2e-8, c_it=3e-10, m0=150.0, m1=5e-5):
    """Solves obeying the model exactly, with iterations per load ∝ tol^-0.1 · N^0.2."""
    out = []
    for model, b0 in (("elastic", 0.5), ("hardening", 0.1)):
        for side in (64, 128, 256, 512):
            for tol in (1e-4, 1e-6, 1e-8):
                n = (2 * side) ** 2
                per_load = math.exp(b0 + 0.1 * math.log10(1 / tol) + 0.2 * math.log(n))
                its = 5 * per_load
                out.append(
                    {
                        "model": model,
                        "fft_points": n,
                        "loads": 5,
                        "tol": tol,
                        "iterations": its,
                        "wall_time_s": c_0 + c_fix * n + c_it * its * n * math.log2(n),
                        "peak_rss_mb": m0 + m1 * n,
                    }
                )
    return out


def test_fit_recovers_the_law_and_predict_reproduces_the_points():
    record = fit_timing_model(_points())
    assert record["time"]["c_0"] == pytest.approx(0.2, rel=1e-6)
    assert record["time"]["c_fix"] == pytest.approx(2e-8, rel=1e-6)
    assert record["time"]["c_it"] == pytest.approx(3e-10, rel=1e-6)
    assert record["models"]["hardening"]["iterations"] == pytest.approx([0.1, 0.1, 0.2], abs=1e-9)
    seconds, mb = predict(record, "hardening", side_px=256, periodic=False, loads=5, tol=1e-6)
    n = 512**2
    its = 5 * math.exp(0.1 + 0.6 + 0.2 * math.log(n))
    assert seconds == pytest.approx(0.2 + 2e-8 * n + 3e-10 * its * n * math.log2(n), rel=1e-6)
    assert mb == pytest.approx(150.0 + 5e-5 * n, rel=1e-6)


def test_memory_line_lies_above_every_measured_point():
    points = _points()
    points[3]["peak_rss_mb"] += 400  # one job with a larger baseline (a big input file)
    record = fit_timing_model(points)
    for p in points:
        assert (
            record["memory"]["m0"] + record["memory"]["m1"] * p["fft_points"]
            >= p["peak_rss_mb"] - 1e-6
        )


def test_a_model_the_study_did_not_measure_takes_the_elastic_iterations():
    record = fit_timing_model([p for p in _points() if p["model"] == "elastic"])
    assert predict(
        record, "penetration_hardness", side_px=128, periodic=True, loads=3, tol=1e-6
    ) == predict(record, "elastic", side_px=128, periodic=True, loads=3, tol=1e-6)
