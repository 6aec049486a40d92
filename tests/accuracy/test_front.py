"""Errors against the reference, the Pareto front and the presets it proposes."""

import numpy as np
import pandas as pd
import pytest

from amontons.accuracy.front import accuracy_table, pareto_front, propose_presets, setting_errors


def test_pareto_front_keeps_exactly_the_points_nothing_beats():
    cost = [1, 2, 3, 4, 2]
    error = [0.5, 0.2, 0.3, 0.05, 0.2]
    # (3, 0.3) is beaten by (2, 0.2); the two (2, 0.2) tie and beat nothing of each other
    np.testing.assert_array_equal(pareto_front(cost, error), [True, True, False, True, True])


def _summary(setting, areas, rendered, loads=(1.0, 2.0, 4.0)):
    return {
        "problem": "p",
        "setting": setting,
        "loads": [
            {"load_mn": f, "area_um2": a, "rendered_area_um2": r}
            for f, a, r in zip(loads, areas, rendered, strict=True)
        ],
    }


def test_errors_of_a_known_perturbation():
    """Areas 10 % high at one load, exponent exact otherwise: the errors are what was put in."""
    loads = np.array([1.0, 2.0, 4.0])
    ref_areas = 3.0 * loads**0.8
    reference = _summary("reference", ref_areas, ref_areas)
    scaled = _summary("s", 1.1 * ref_areas, ref_areas * [1.0, 1.0, 1.05])
    p_ref = [np.ones((4, 4))] * 3
    p = [np.ones((4, 4)) * 1.02] * 3
    errors = setting_errors(scaled, p, reference, p_ref)
    assert errors["area_error"] == pytest.approx(0.1, rel=1e-12)
    # a uniform factor leaves the exponent unchanged (to rounding)
    assert errors["exponent_error"] == pytest.approx(0.0, abs=1e-12)
    assert errors["pressure_error"] == pytest.approx(0.02, rel=1e-12)
    assert errors["rendered_area_error"] == pytest.approx(0.05, rel=1e-12)
    # the rendered exponent: OLS slope of ln(1, 1, 1.05) over ln(1, 2, 4) is ln(1.05)/(2 ln 2)
    assert errors["rendered_exponent_error"] == pytest.approx(
        np.log(1.05) / (2 * np.log(2)), rel=1e-9
    )


def test_presets_take_the_cheapest_setting_within_budget_on_every_problem():
    rows = []
    for problem, scale in (("a", 1.0), ("b", 2.0)):
        for setting, t, err in (("cheap", 1, 0.08), ("mid", 3, 0.008), ("dear", 9, 0.001)):
            rows.append(
                {
                    "problem": problem,
                    "setting": setting,
                    "wall_time_s": t,
                    "pixel_nm": 100.0,
                    "side_px": 64,
                    "tol": 1e-6,
                    "window_factor": 1.5,
                    "coarse_to_fine": False,
                    "peak_rss_mb": 100.0,
                    **{
                        f"{m}_error": err * scale
                        for m in (
                            "area",
                            "exponent",
                            "pressure",
                            "rendered_area",
                            "rendered_exponent",
                        )
                    },
                }
            )
    table = pd.DataFrame(rows)
    presets = propose_presets(
        table,
        {
            "loose": {"rendered_area": 0.2},
            "tight": {"rendered_area": 0.01},
            "never": {"area": 1e-5},
        },
        ["a", "b"],
    )
    assert presets["loose"]["setting"] == "cheap"
    # 'mid' meets 0.01 on a (0.008) but not on b (0.016): the dearer one
    assert presets["tight"]["setting"] == "dear"
    assert presets["tight"]["wall_time_s"] == 18
    assert presets["never"] is None


def test_a_problem_without_reference_is_refused():
    with pytest.raises(ValueError, match="no reference"):
        accuracy_table([{**_summary("s", [1, 2, 3], [1, 2, 3]), "problem": "p"}], {})
