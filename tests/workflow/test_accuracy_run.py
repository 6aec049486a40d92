"""`snakemake accuracy` on the small data (config/test.yaml), with the small run: the table
holds every problem at every setting, and the errors fall as the pixel is refined."""

from pathlib import Path

import pandas as pd
import pytest

from amontons.accuracy.front import ERRORS
from amontons.accuracy.settings import REFERENCE, settings_by_name

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def accuracy_run(small_run):
    """The small run's accuracy study: the session's small-data run makes `accuracy` in the
    same Snakemake call as the rest (tests/workflow/conftest.py)."""
    return small_run / "results" / "small" / "accuracy"


@pytest.fixture(scope="module")
def study_config(small_run):
    from amontons.config import read_config

    return read_config(small_run / "config" / "config.yaml", small_run / "config" / "test.yaml")[
        "accuracy"
    ]


def test_table_holds_every_problem_at_every_setting(accuracy_run, study_config):
    table = pd.read_csv(accuracy_run / "accuracy.csv")
    for problem in study_config["problems"]:
        names = set(settings_by_name(problem, study_config))
        assert set(table.loc[table["problem"] == problem, "setting"]) == names
    errors = table[[f"{m}_error" for m in ERRORS]]
    assert errors.notna().all().all() and (errors >= 0).all().all()
    assert (table["wall_time_s"] > 0).all() and (table["iterations"] > 0).all()
    reference = table[table["setting"] == REFERENCE]
    assert (reference[[f"{m}_error" for m in ERRORS]] == 0).all().all()
    # every error measure has a front, and its cheapest point is on it
    for (problem, measure), rows in (
        (key, table[(table["problem"] == key[0]) & (table["setting"] != REFERENCE)])
        for key in ((p, m) for p in study_config["problems"] for m in ERRORS)
    ):
        assert rows.loc[rows["wall_time_s"].idxmin(), f"{measure}_front"], (problem, measure)
    for name in ("accuracy.png", "accuracy.pdf", "presets.json", "timing_model.json"):
        assert (accuracy_run / name).stat().st_size > 0


def test_errors_fall_as_the_pixel_is_refined(accuracy_run):
    """At one tolerance and window, a finer pixel resolves more of the same surface: the true
    area and the pressure field (on the common grid) come closer to the reference at every
    step of the pixel (8, 4, 2, 1 × the finest)."""
    table = pd.read_csv(accuracy_run / "accuracy.csv")
    rows = table[
        (table["tol"] == 1e-6) & ~table["coarse_to_fine"] & (table["setting"] != REFERENCE)
    ]
    for problem, group in rows.groupby("problem"):
        if "window_factor" in group and group["window_factor"].notna().any():
            group = group[group["window_factor"] == 1.5]
        group = group.sort_values("pixel_factor", ascending=False)
        assert list(group["pixel_factor"]) == [8, 4, 2, 1], problem
        for measure in ("area_error", "pressure_error"):
            values = group[measure].to_numpy()
            assert (values[1:] < values[:-1]).all(), (problem, measure, values)


def test_timing_points_vary_the_plastic_ratio_and_enter_the_model(accuracy_run, study_config):
    """Each timing point is solved at the ratio it names (to rounding), and the fitted model
    has a count for both plastic models: a softer hardening layer (smaller s) costs fewer
    convolutions per load, as its better-conditioned operator K + 1/k should (γ > 0)."""
    import json

    from amontons.accuracy.settings import timing_points

    for point, (model, ratio) in timing_points(study_config).items():
        summary = json.loads((accuracy_run / "timing" / point / "summary.json").read_text())
        assert summary["model"] == model
        if summary["outside_window"] is None:
            assert summary["ratio"] == pytest.approx(ratio, rel=1e-9)
            assert summary["convolutions"] > 0 and summary["wall_time_s"] > 0
    record = json.loads((accuracy_run / "timing_model.json").read_text())
    assert set(record["convolutions"]) == {"elastic", "hardening", "penetration_hardness"}
    assert record["convolutions"]["hardening"]["gamma"] > 0
