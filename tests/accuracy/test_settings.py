"""The accuracy study's grid of settings: what each problem runs, and configs that cannot run."""

import pytest

from amontons.accuracy.settings import (
    REFERENCE,
    AccuracyConfigError,
    check_accuracy,
    problem_settings,
    settings_by_name,
)

STUDY = {
    "problems": ["elastic_sphere", "hardening_sphere", "periodic"],
    "grid": [
        {
            "pixel_factor": [1, 2],
            "tol": [1e-4, 1e-6],
            "window_factor": [1.5],
            "coarse_to_fine": [False],
        },
        {
            "pixel_factor": [2],
            "tol": [1e-6],
            "window_factor": [1.2, 1.5],
            "coarse_to_fine": [False, True],
        },
    ],
    "reference": {"pixel_factor": 1, "tol": 1e-10, "window_factor": 1.8},
}


def test_blocks_are_a_union_of_products_without_repeats():
    # block 1: 4 settings; block 2: 4 more, one of which (px2, 1e-6, 1.5, off) block 1 has
    assert len(problem_settings("elastic_sphere", STUDY["grid"])) == 7


def test_coarse_to_fine_is_dropped_where_the_solver_ignores_it():
    """Hardening ignores coarse-to-fine: a job for it would repeat the solve without it."""
    settings = problem_settings("hardening_sphere", STUDY["grid"])
    assert not any(s.coarse_to_fine for s in settings)
    assert len(settings) == 5


def test_a_periodic_surface_has_no_window_to_choose():
    settings = problem_settings("periodic", STUDY["grid"])
    assert all(s.window_factor is None for s in settings)
    # (px, tol, c2f): (1,-4), (1,-6), (2,-4), (2,-6), (2,-6,c2f)
    assert len(settings) == 5
    assert all("_w" not in s.name for s in settings)


def test_names_are_unique_and_name_the_reference():
    named = settings_by_name("elastic_sphere", STUDY)
    assert REFERENCE in named and named[REFERENCE].tol == 1e-10
    assert "px2_tol1e-06_w1.2_c2f1" in named


@pytest.mark.parametrize(
    "key, value, text",
    [
        ("pixel_factor", 2, "finest pixel"),
        ("tol", 1e-5, "tightest"),
        ("window_factor", 1.4, "widest"),
    ],
)
def test_a_reference_less_converged_than_a_setting_is_refused(key, value, text):
    study = {**STUDY, "reference": {**STUDY["reference"], key: value}}
    with pytest.raises(AccuracyConfigError, match=f"accuracy.reference.{key}.*{text}"):
        check_accuracy(study, "config.yaml")


def test_an_unknown_problem_is_refused():
    with pytest.raises(AccuracyConfigError, match="'rough_plate'.*expected one of"):
        check_accuracy({**STUDY, "problems": ["rough_plate"]}, "config.yaml")


def test_timing_points_are_named_by_model_and_ratio():
    from amontons.accuracy.settings import Setting, timing_points, timing_setting

    study = {
        "timing_points": {
            "setting": {"pixel_factor": 4, "tol": 1e-4, "window_factor": 1.5},
            "stiffness_ratio": [0.03, 3.0],
            "yield_ratio": [0.6],
        }
    }
    assert timing_points(study) == {
        "hardening_s0.03": ("hardening", 0.03),
        "hardening_s3": ("hardening", 3.0),
        "penetration_hardness_y0.6": ("penetration_hardness", 0.6),
    }
    assert timing_setting(study) == Setting(4, 1e-4, 1.5, False)
