"""A sphere without a prior for p_Y or k (issue 36): its scans run over the prior-free ranges
(docs/study.md, "Scans without a prior") and find what the same sphere's scans about the
sheet's values find, within one step of the prior-free scan."""

import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
import yaml

pytestmark = pytest.mark.workflow

REPO = Path(__file__).resolve().parents[2]
SMALL = "small"


@pytest.fixture(scope="module")
def no_prior_run(small_data, tmp_path_factory):
    """The virtual PS sphere as measured data, its sheet row without hardness_mpa and
    hardening_k_mpa_per_nm, its scans run with the small config's (target ``scans``)."""
    tmp_path = tmp_path_factory.mktemp("no_prior")
    folder = tmp_path / "lab" / "PS-noprior"
    shutil.copytree(small_data / "resources" / "synthetic" / SMALL / "PS", folder)
    (folder / "truth.json").unlink()
    project = tmp_path / "project"
    shutil.copytree(REPO / "config", project / "config")
    sheet = pd.read_csv(project / "config" / "materials.tsv", sep="\t", dtype=str)
    row = sheet[sheet["sphere"] == "PS"].assign(
        sphere="PS-noprior", data_source=str(folder), hardness_mpa="", hardening_k_mpa_per_nm=""
    )
    row.to_csv(project / "config" / "own.tsv", sep="\t", index=False)
    path = project / "config" / "test.yaml"
    config = yaml.safe_load(path.read_text())
    # Only what the tests read: the scans (target `scans`: their best values, with the
    # elastic scene the sphere registers on) and the scenes whose prior is missing.
    config.update(
        materials=["PS"],
        materials_sheet="config/own.tsv",
        run_scenes=["elastic", "penetration_hardness", "hardening"],
    )
    config["study"] = {"run_curvature_pairs": []}
    path.write_text(yaml.safe_dump(config))
    command = [sys.executable, "-m", "snakemake", "-s", str(REPO / "Snakefile"), "-d", str(project)]
    run = subprocess.run(
        [*command, "scans", "--cores", "2", "--configfile", "config/test.yaml"],
        cwd=project,
        capture_output=True,
        text=True,
        timeout=2400,
    )
    assert run.returncode == 0, run.stderr[-3000:]
    return project, run


def _best(project, sphere, scan) -> dict:
    path = project / "results" / SMALL / "PS" / sphere / "scans" / scan / "best.json"
    return json.loads(path.read_text())


@pytest.mark.parametrize("scan", ["p_y", "k"])
def test_a_scan_without_prior_finds_what_the_scan_about_the_prior_finds(
    small_run, no_prior_run, scan
):
    """Within one step of the prior-free scan (a factor of its grid's ratio, 1.47 for p_Y and
    1.78 for k by default): the two scans judge the same images on different grids."""
    project, _ = no_prior_run
    free = pd.read_csv(
        project / "results" / SMALL / "PS" / "PS-noprior" / "scans" / scan / "scan.csv"
    )
    values = free[~free["refined"]]["value"].to_numpy()  # the grid's, not refinement's
    step = math.log(values[1] / values[0])
    config = yaml.safe_load((REPO / "config" / "config.yaml").read_text())["scans"][scan]
    assert len(values) == config["prior_free_steps"]
    with_prior = _best(small_run, "PS", scan)["best"]
    without = _best(project, "PS-noprior", scan)["best"]
    assert abs(math.log(without / with_prior)) <= step * (1 + 1e-9)


def test_the_scenes_at_the_missing_prior_are_left_out_and_said(no_prior_run):
    project, run = no_prior_run
    scenes = project / "results" / SMALL / "PS" / "PS-noprior" / "scenes"
    assert (scenes / "elastic" / "comparison.csv").is_file()
    assert not (scenes / "hardening").exists() and not (scenes / "penetration_hardness").exists()
    assert "no hardening_k_mpa_per_nm in the sheet: scene hardening" in run.stderr
    assert "scan k runs over its prior-free range" in run.stderr
