"""The timing model: it recovers the law it was fitted on, predicts in pure Python, and its
plastic ratios are the dimensionless numbers they claim to be."""

import math

import pytest

from amontons.accuracy.timing import (
    convolutions_per_load,
    predict,
    stiffness_ratio,
    yield_ratio,
)
from amontons.accuracy.timing_fit import fit_timing_model

# the law the synthetic points obey: elastic [b0, b_periodic, b_tol, b_extent]; plastic
# (offset, gamma); time c_0 + c_conv·work; memory m0 + m1·N
ELASTIC = [0.8, -0.5, 0.1, 0.22]
PLASTIC = {"hardening": (0.05, 0.4), "penetration_hardness": (0.2, 0.7)}
C_0, C_CONV, M0, M1 = 0.2, 6e-10, 150.0, 5e-5


def _per_load(model, tol, periodic, contact_px, ratio):
    b0, bp, bt, be = ELASTIC
    count = math.exp(b0 + bp * periodic + bt * math.log10(1 / tol) + be * 2 * math.log(contact_px))
    if model == "elastic":
        return count
    offset, gamma = PLASTIC[model]
    return count * math.exp(offset) * (ratio / (1 + ratio)) ** gamma


def _points():
    """Solves obeying the model exactly: spheres and periodic surfaces, several tolerances,
    extents and (for the plastic models) ratios."""
    out = []
    for model in ("elastic", "hardening", "penetration_hardness"):
        ratios = [None] if model == "elastic" else [0.05, 0.3, 1.0, 4.0]
        for side in (64, 128, 256, 512):
            for periodic in (False, True):
                for tol in (1e-4, 1e-6, 1e-8):
                    for ratio in ratios:
                        extent = side if periodic else 0.55 * side
                        n = side**2 if periodic else (2 * side) ** 2
                        conv = 5 * _per_load(model, tol, periodic, extent, ratio)
                        out.append(
                            {
                                "model": model,
                                "fft_points": n,
                                "periodic": periodic,
                                "contact_px": extent,
                                "ratio": ratio,
                                "loads": 5,
                                "tol": tol,
                                "convolutions": conv,
                                "wall_time_s": C_0 + C_CONV * conv * n * math.log2(n),
                                "peak_rss_mb": M0 + M1 * n,
                            }
                        )
    return out


def test_fit_recovers_the_law_and_predict_reproduces_it():
    """Exact points: every coefficient back to 1e-6 (least squares on an exact law)."""
    record = fit_timing_model(_points())
    assert record["time"]["c_0"] == pytest.approx(C_0, rel=1e-6)
    assert record["time"]["c_conv"] == pytest.approx(C_CONV, rel=1e-6)
    assert record["convolutions"]["elastic"]["coef"] == pytest.approx(ELASTIC, abs=1e-9)
    for model, (offset, gamma) in PLASTIC.items():
        assert record["convolutions"][model]["offset"] == pytest.approx(offset, abs=1e-9)
        assert record["convolutions"][model]["gamma"] == pytest.approx(gamma, abs=1e-9)
    seconds, mb = predict(
        record,
        "penetration_hardness",
        side_px=300,
        periodic=False,
        loads=4,
        tol=1e-5,
        contact_px=170.0,
        ratio=0.8,
    )
    n = 600**2
    conv = 4 * _per_load("penetration_hardness", 1e-5, False, 170.0, 0.8)
    assert seconds == pytest.approx(C_0 + C_CONV * conv * n * math.log2(n), rel=1e-6)
    assert mb == pytest.approx(M0 + M1 * n, rel=1e-6)


def test_an_unknown_ratio_takes_the_elastic_limit():
    """ratio None is z/(1+z) = 1: the plastic model's count at z → ∞, above any finite z
    when γ > 0."""
    record = fit_timing_model(_points())
    at = {"tol": 1e-6, "periodic": False, "contact_px": 200.0}
    unknown = convolutions_per_load(record, "hardening", ratio=None, **at)
    elastic = convolutions_per_load(record, "elastic", **at)
    assert unknown == pytest.approx(elastic * math.exp(PLASTIC["hardening"][0]), rel=1e-6)
    assert convolutions_per_load(record, "hardening", ratio=1e6, **at) == pytest.approx(
        unknown, rel=1e-5
    )
    assert convolutions_per_load(record, "hardening", ratio=0.1, **at) < unknown


def test_a_sphere_costs_by_its_contact_not_its_window():
    """Two windows around one contact: the same convolutions per load; only the FFT grows."""
    record = fit_timing_model(_points())
    narrow = predict(
        record, "elastic", side_px=200, periodic=False, loads=5, tol=1e-6, contact_px=120.0
    )[0]
    wide = predict(
        record, "elastic", side_px=400, periodic=False, loads=5, tol=1e-6, contact_px=120.0
    )[0]
    n_narrow, n_wide = 400**2, 800**2
    expected = (n_wide * math.log2(n_wide)) / (n_narrow * math.log2(n_narrow))
    assert (wide - C_0) / (narrow - C_0) == pytest.approx(expected, rel=1e-6)


def test_memory_line_lies_above_every_measured_point():
    points = _points()
    points[3]["peak_rss_mb"] += 400  # one job with a larger baseline (a big input file)
    record = fit_timing_model(points)
    for p in points:
        assert (
            record["memory"]["m0"] + record["memory"]["m1"] * p["fft_points"]
            >= p["peak_rss_mb"] - 1e-6
        )


def test_a_model_the_study_did_not_measure_takes_the_elastic_count():
    record = fit_timing_model([p for p in _points() if p["model"] == "elastic"])
    kwargs = {"side_px": 128, "periodic": True, "loads": 3, "tol": 1e-6}
    assert predict(record, "penetration_hardness", ratio=0.5, **kwargs) == predict(
        record, "elastic", **kwargs
    )


def test_a_fit_without_elastic_solves_is_refused():
    with pytest.raises(ValueError, match="needs elastic solves"):
        fit_timing_model([p for p in _points() if p["model"] != "elastic"])


def test_the_ratios_in_numbers():
    """The virtual PS sphere at the standard pixel: k = 5 MPa/nm, Δx = 206 nm, E* = 3.7 GPa
    gives s = 2kΔx/(πE*) = 0.177; p_Y = 179 MPa over E*·h'/2 with h' = 0.0967 gives y = 1.0."""
    assert stiffness_ratio(5e15, 206e-9, 3.7e9) == pytest.approx(0.1772, rel=1e-3)
    assert yield_ratio(179e6, 3.7e9, 0.0967) == pytest.approx(1.0006, rel=1e-3)
