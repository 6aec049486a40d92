"""Parameter scans: the grid of values, the criterion, the best value and its brackets."""

import math

import numpy as np
import pytest

from amontons.simulate.scan import log_area_distance, scene_config_at
from amontons.simulate.scan_best import ScanPoint, best_scan_value
from amontons.simulate.scan_criterion import Criterion, ModelError, log_area_scatter
from amontons.simulate.scan_grid import ScanError, scan_values

LOADS_MN = (25.0, 50.0, 100.0, 200.0, 300.0)


def _scatter_only(scatter_sd, n_loads=5):
    """The criterion of the scans before the model's error was counted: the measured scatter
    alone, taken as known (χ²(1) quantile). χ² = n D² / s² exactly."""
    return Criterion(LOADS_MN[:n_loads], scatter_sd, ModelError.none(n_loads), quantile="chi2")


def _point(value, residual, iou=0.9, ratio=1.0, n_loads=5):
    """A value whose rendered areas are off by the same factor exp(residual) at every load."""
    return ScanPoint(value, abs(residual), iou, ratio, (residual,) * n_loads)


def test_log_scan_spans_the_range_with_equal_ratios():
    values = scan_values(5.0, [0.2, 4.0], 7)
    assert values[0] == pytest.approx(1.0) and values[-1] == pytest.approx(20.0)
    ratios = np.diff(np.log(values))
    # rounding to 4 significant digits moves a ratio by < 1e-3
    assert ratios == pytest.approx(np.log(20) / 6, abs=1e-3)


def test_linear_scan_and_bad_ranges():
    assert scan_values(10.0, [0.5, 1.5], 3, "linear") == [5.0, 10.0, 15.0]
    with pytest.raises(ScanError, match="expected 0 < low < high"):
        scan_values(10.0, [2.0, 1.0], 5)
    with pytest.raises(ScanError, match="at least 3"):
        scan_values(10.0, [0.5, 2.0], 2)
    with pytest.raises(ScanError, match="spacing"):
        scan_values(10.0, [0.5, 2.0], 5, "cubic")


def test_scene_config_at_sets_the_parameter_of_the_matching_model_only():
    base = {"model": "hardening", "k_mpa_per_nm": None}
    assert scene_config_at(base, "k_mpa_per_nm", 3.0)["k_mpa_per_nm"] == 3.0
    with pytest.raises(ScanError, match="belongs to model 'penetration_hardness'"):
        scene_config_at(base, "p_y_mpa", 100.0)


def test_log_area_distance_is_the_rms_log_ratio():
    # every area 10 % high: D = ln 1.1 exactly
    assert log_area_distance([1.1, 2.2, 4.4], [1, 2, 4]) == pytest.approx(math.log(1.1))
    assert log_area_distance([0.0, 2.0], [1.0, 2.0]) == float("inf")


def test_log_area_scatter_of_an_exact_power_law_is_zero_and_grows_with_noise():
    loads = np.array([25, 50, 100, 200, 300.0])
    assert log_area_scatter(loads, 7 * loads**0.8) == pytest.approx(0.0, abs=1e-12)
    # a known residual pattern: alternate ±e on ln A (orthogonal to the line only in part),
    # so s lies between 0 and e·sqrt(n/(n-2))
    e = 0.05
    noisy = 7 * loads**0.8 * np.exp(e * np.array([1, -1, 1, -1, 1]))
    s = log_area_scatter(loads, noisy)
    assert 0 < s <= e * math.sqrt(5 / 3) + 1e-12


def _points(values, true_value, slope=0.3):
    """A model whose areas are off by a factor (v/v0)^slope at every load: D = slope |ln v/v0|."""
    return [
        _point(v, slope * math.log(v / true_value), 0.9, (v / true_value) ** slope) for v in values
    ]


def test_best_value_is_the_grid_point_nearest_the_truth_in_log():
    values = scan_values(5.0, [0.2, 4.0], 7)  # 1, 1.648, 2.714, 4.472, 7.368, 12.14, 20
    best = best_scan_value(_points(values, 5.0), _scatter_only(0.02), 0.95)
    assert best.value == 4.472
    assert (best.resolution_low, best.resolution_high) == (2.714, 7.368)
    assert not best.at_scan_edge
    # χ² = n (0.3 ln(v/5))² / s² is a parabola in ln v: its vertex, the refined value, is
    # the truth exactly. The best point misses by D = 0.3 ln(5/4.472) > s, so s is inflated
    # to D sqrt(n/(n-1)) (Birge), and the interval is ln v = ln 5 ± s sqrt(3.841/(n 0.09)).
    assert best.refined == pytest.approx(5.0, rel=1e-9)
    s = 0.3 * math.log(5 / 4.472) * math.sqrt(5 / 4)
    assert best.scatter_sd_used == pytest.approx(s, rel=1e-12)
    half = s * math.sqrt(3.841459 / (5 * 0.09))
    assert best.scatter_low == pytest.approx(5 * math.exp(-half), rel=1e-5)
    assert best.scatter_high == pytest.approx(5 * math.exp(half), rel=1e-5)


def test_a_scatter_wider_than_the_misfit_widens_the_interval_beyond_the_neighbours():
    """With s = 0.3 the χ² rise of 3.84 is reached only beyond the best value's neighbours
    (exactly at ln v = ln 5 ± 0.3 sqrt(3.841/0.45), i.e. 2.08 and 12.0): there the interval
    follows χ² linearly between grid points, which overstates χ² between them and so lands
    inside the exact bounds, by less than one grid step (a factor 1.648)."""
    values = scan_values(5.0, [0.2, 4.0], 7)
    best = best_scan_value(_points(values, 5.0), _scatter_only(0.3), 0.95)
    half = 0.3 * math.sqrt(3.841459 / 0.45)
    exact = (5 * math.exp(-half), 5 * math.exp(half))
    assert exact[0] < best.scatter_low < 2.714 and 7.368 < best.scatter_high < exact[1]
    assert best.scatter_low < exact[0] * 1.648 and best.scatter_high > exact[1] / 1.648


def test_a_flat_criterion_leaves_the_interval_open_and_ties_go_to_the_better_overlap():
    values = [1000.0, 2000.0, 4000.0, 8000.0]
    points = [_point(v, 0.05, iou) for v, iou in zip(values, [0.8, 0.9, 0.85, 0.8], strict=True)]
    best = best_scan_value(points, _scatter_only(0.05), 0.95)
    assert best.value == 2000.0  # the IoU tie-break
    assert best.scatter_low is None and best.scatter_high is None


def test_best_at_the_scan_end_is_flagged():
    values = [1.0, 2.0, 4.0, 8.0]
    best = best_scan_value(_points(values, 20.0), _scatter_only(0.02), 0.95)
    assert best.value == 8.0 and best.at_scan_edge and best.resolution_high is None


def test_values_whose_contact_leaves_the_window_are_never_best():
    points = [ScanPoint.outside_window(1.0, 5)] + _points([2.0, 4.0, 8.0], 4.0)
    assert best_scan_value(points, _scatter_only(0.02), 0.95).value == 4.0
    with pytest.raises(ScanError, match="no scanned value"):
        best_scan_value([ScanPoint.outside_window(1.0, 5)] * 3, _scatter_only(0.02), 0.95)
