"""A scan on cut AFM scans (issues 52 and 65), going on from the lab run's project (lab.py):
the loads a scan holds are judged, and a scan that holds too few or none says why."""

import json

import pandas as pd
import pytest
import yaml

from .lab import (
    CUT_SCANS,
    MEASURING,
    SMALL,
    TWO_LOAD_SCANS,
    continued,
    jobs_of,
    run_check,
    run_snakemake,
)

pytestmark = pytest.mark.workflow


def test_a_scan_on_a_cut_scan_judges_the_loads_it_holds(lab_run, small_data, tmp_path):
    """The p_Y scan (three values, to keep it short) of the sphere whose AFM scan holds three
    loads: every value is solved and compared on those three, the best value's fit is over
    them, and best.json and the model table list 200 and 300 mN as outside_scan. Beside it,
    a sphere whose scan holds no load's contact: its scan is not decided, an answer that
    says why, and the run exits 0 (test_a_scan_with_nothing_to_judge_says_why). The project
    goes on from the lab run's (continued), with the scan switched on: the two cut spheres'
    measurements are that run's, and only their new scene and scan run."""
    project = continued(lab_run[0], tmp_path, small_data, [*CUT_SCANS], [*TWO_LOAD_SCANS])
    path = project / "config" / "test.yaml"
    config = yaml.safe_load(path.read_text())
    config.update(run_scenes=["penetration_hardness"], run_scans=["p_y"])
    config["scans"] = {"p_y": {"steps": 3}}
    path.write_text(yaml.safe_dump(config))
    check = run_check(project)
    run = run_snakemake(project, "--cores", "2")
    assert run.returncode == 0, run.stderr[-3000:]
    again = jobs_of(run, "PS-cutscan")
    assert "scan_scene" in again and not {r for r in again if r.startswith(MEASURING)}, again
    scan = project / "results" / SMALL / "PS" / "PS-cutscan" / "scans" / "p_y"
    best = json.loads((scan / "best.json").read_text())
    assert [row["load_mn"] for row in best["outside_scan"]] == [200.0, 300.0]
    assert [row["load_mn"] for row in best["best_loads"]] == pytest.approx([25, 50, 100])
    points = pd.read_csv(scan / "scan.csv")
    # a value soft enough that its contact leaves the window is recorded, never judged; the
    # values refinement added (issue 65) are solved on the same loads
    judged = points[~points["contact_leaves_window"]]
    grid = points[~points["refined"]]
    assert len(grid) == 3 and len(judged) >= 2 and judged["log_area_distance"].notna().all()
    assert sorted(points[points["refined"]]["value"]) == sorted(best["refined_values"])
    for value in judged["value"]:
        point = json.loads((scan / "values" / f"{value:g}" / "scan_point.json").read_text())
        assert [row["load_mn"] for row in point["loads"]] == pytest.approx([25, 50, 100])
    models = pd.read_csv(project / "results" / SMALL / "PS" / "models.csv")
    cut = models[models["sphere"] == "PS-cutscan"]
    assert set(cut["left_out"]) == {"outside_scan: 200, 300 mN"}
    _a_scan_with_nothing_to_judge_says_why(project, models)
    _a_scan_with_too_few_loads_says_why(project, models)
    # the data check said so before the run, and of those spheres only
    plans = {plan["sphere"]: plan for plan in json.loads(check.stdout)}
    assert list(plans["PS-noload"]["undecided_scans"]) == ["p_y"]
    assert plans["PS-twoloads"]["undecided_scans"]["p_y"] == (
        "scan p_y: not decided (its scene penetration_hardness keeps 2 loads inside the AFM "
        "scan, 25, 50 mN; the criterion needs at least 3)"
    )
    assert plans["PS-cutscan"]["undecided_scans"] == {}


def _a_scan_with_too_few_loads_says_why(project, models):
    """PS-twoloads' 40 µm scan holds two loads' contacts (issue 65: a lab's sphere whose scan
    held one load stopped the run with a ScanError): its values are solved on them, but two
    loads leave the measured scatter no degree of freedom, so the scan is not decided, with
    the loads it holds and the loads the criterion needs, in best.json, the model table, the
    verdict and summary.md; and the run exits 0."""
    scan = project / "results" / SMALL / "PS" / "PS-twoloads" / "scans" / "p_y"
    best = json.loads((scan / "best.json").read_text())
    assert "estimate" not in best and "grid_best" not in best
    assert best["measured_loads_mn"] == pytest.approx([25, 50]) and best["loads_needed"] == 3
    assert best["not_decided"].startswith("too few loads to judge: 2 measured loads (25, 50 mN)")
    assert [row["load_mn"] for row in best["outside_scan"]] == [100.0, 200.0, 300.0]
    points = pd.read_csv(scan / "scan.csv")
    assert len(points) == 3 and not points["best"].any()
    own = models[(models["sphere"] == "PS-twoloads") & models["source"].str.startswith("scan")]
    (row,) = own.to_dict("records")
    assert row["source"] == "scan p_y, not decided"
    assert row["left_out"] == f"not decided: {best['not_decided']}"
    verdict = pd.read_csv(project / "results" / SMALL / "verdict.csv").set_index("sphere")
    assert verdict.loc["PS-twoloads", "penetration_hardness_source"] == "scan p_y, not decided"
    summary = (project / "results" / SMALL / "summary.md").read_text()
    assert f"not decided: {best['not_decided']}" in summary


def _a_scan_with_nothing_to_judge_says_why(project, models):
    """PS-noload's 24 µm scan holds none of the loads' windows, nor any contact: best.json
    says 'not decided' and why (the loads left out with their windows, the scan's size and
    the largest window in it), every value's row is there unjudged, and the model table, the
    verdict and summary.md show it in the sphere's place, the verdict's other columns still
    the sphere's own."""
    scan = project / "results" / SMALL / "PS" / "PS-noload" / "scans" / "p_y"
    best = json.loads((scan / "best.json").read_text())
    assert "estimate" not in best and "grid_best" not in best
    assert [row["load_mn"] for row in best["outside_scan"]] == [25, 50, 100, 200, 300]
    assert best["largest_window_in_scan_um"] <= min(best["scan_um"]) <= CUT_SCANS["PS-noload"]
    assert "holds no load's window" in best["not_decided"]
    assert (
        f"largest window it holds is {best['largest_window_in_scan_um']:.1f} µm"
        in (best["not_decided"])
    )
    points = pd.read_csv(scan / "scan.csv")
    assert len(points) == 3 and points["log_area_distance"].isna().all()
    assert not points["best"].any()
    own = models[(models["sphere"] == "PS-noload") & models["source"].str.startswith("scan")]
    (row,) = own.to_dict("records")
    assert row["source"] == "scan p_y, not decided" and pd.isna(row["exponent"])
    assert row["left_out"] == f"not decided: {best['not_decided']}"
    verdict = pd.read_csv(project / "results" / SMALL / "verdict.csv").set_index("sphere")
    assert verdict.loc["PS-noload", "penetration_hardness_source"] == "scan p_y, not decided"
    assert pd.isna(verdict.loc["PS-noload", "p_y_estimate"])
    assert pd.notna(verdict.loc["PS-cutscan", "p_y_grid_best"])  # judged (a bound: no estimate)
    summary = (project / "results" / SMALL / "summary.md").read_text()
    assert f"not decided: {best['not_decided']}" in summary
