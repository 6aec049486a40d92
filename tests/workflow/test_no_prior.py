"""A sphere scanned without the sheet's priors (issue 36), going on from the lab run's project
(lab.py): its plastic scenes are left out and said, and its scans run over the prior-free
ranges and find what the scans about the priors find."""

import json
import math

import pandas as pd
import pytest
import yaml

from amontons.models import with_parameter

from .lab import COMPLETE, MEASURING, REPO, SMALL, continued, jobs_of, run_snakemake

pytestmark = pytest.mark.workflow


# The sheet's priors of the plastic models (issue 36), as their records name them: the
# columns a lab leaves blank when it does not know them.
PRIORS = tuple(model.parameter.sheet_column for model in with_parameter())


@pytest.fixture(scope="module")
def no_prior_run(lab_run, small_data, tmp_path_factory):
    """The lab's project gone on from (continued) with the complete sphere's sheet row
    without hardness_mpa and hardening_k_mpa_per_nm, and its scans run with the small
    config's (target ``scans``: their best values, with the elastic scene the sphere
    registers on, as the small run has it): a lab that measured a sphere, then scans it
    without knowing its priors. Its measurements are the lab run's."""
    tmp_path = tmp_path_factory.mktemp("no_prior")
    project = continued(lab_run[0], tmp_path, small_data, [COMPLETE], [])
    sheet_path = project / "config" / "own.tsv"
    sheet = pd.read_csv(sheet_path, sep="\t", dtype=str)
    sheet.assign(**dict.fromkeys(PRIORS, "")).to_csv(sheet_path, sep="\t", index=False)
    path = project / "config" / "test.yaml"
    config = yaml.safe_load(path.read_text())
    # Only what the tests read: the scans and the scenes whose prior is missing, with the
    # small config's scenes and scans (the lab's widens the elastic window and runs none).
    del config["scenes"]["elastic"], config["run_scans"]
    config.update(run_scenes=["elastic", "penetration_hardness", "hardening"])
    path.write_text(yaml.safe_dump(config))
    run = run_snakemake(project, "--cores", "2", targets=["scans"])
    assert run.returncode == 0, run.stderr[-3000:]
    return project, run


def _best(project, sphere, scan) -> dict:
    path = project / "results" / SMALL / "PS" / sphere / "scans" / scan / "best.json"
    return json.loads(path.read_text())


@pytest.mark.parametrize("scan", ["p_y", "k"])
def test_a_scan_without_prior_finds_what_the_scan_about_the_prior_finds(
    small_run, no_prior_run, scan
):
    """Its scans run over the prior-free ranges (docs/study.md, "Scans without a prior") and
    find what the small run's PS scans about the sheet's values find, within one step of the
    prior-free scan (a factor of its grid's ratio, 1.47 for p_Y and 1.78 for k by default):
    the two scans judge the same images on different grids."""
    project, _ = no_prior_run
    free = pd.read_csv(project / "results" / SMALL / "PS" / COMPLETE / "scans" / scan / "scan.csv")
    values = free[~free["refined"]]["value"].to_numpy()  # the grid's, not refinement's
    step = math.log(values[1] / values[0])
    config = yaml.safe_load((REPO / "config" / "config.yaml").read_text())["scans"][scan]
    assert len(values) == config["prior_free_steps"]
    with_prior = _best(small_run, "PS", scan)["best"]
    without = _best(project, COMPLETE, scan)["best"]
    assert abs(math.log(without / with_prior)) <= step * (1 + 1e-9)


def test_the_scenes_at_the_missing_prior_are_left_out_and_said(no_prior_run):
    """The plastic scenes need the prior the sheet lacks: they are left out, and the run says
    so; the scans run prior-free, on the lab run's measurements."""
    project, run = no_prior_run
    scenes = project / "results" / SMALL / "PS" / COMPLETE / "scenes"
    assert (scenes / "elastic" / "comparison.csv").is_file()
    assert not (scenes / "hardening").exists() and not (scenes / "penetration_hardness").exists()
    assert "no hardening_k_mpa_per_nm in the sheet: scene hardening" in run.stderr
    assert "scan k runs over its prior-free range" in run.stderr
    again = jobs_of(run, COMPLETE)
    assert "scan_scene" in again and not {r for r in again if r.startswith(MEASURING)}, again
