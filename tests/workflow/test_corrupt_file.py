"""A lab's corrupt file (issue 52), going on from the lab run's project (lab.py): one bad sphere
among good ones stops only itself until the file is fixed."""

import json

import pandas as pd
import pytest

from .lab import COMPLETE, SMALL, continued, jobs_of, run_check, run_snakemake

pytestmark = pytest.mark.workflow


def _spheres_in(project, table: str) -> set[str]:
    return set(pd.read_csv(project / "results" / SMALL / "PS" / table)["sphere"])


def test_one_corrupt_file_stops_only_its_sphere_until_it_is_fixed(lab_run, small_data, tmp_path):
    """Two spheres, one with a truncated fluorescence image: every output of the other is
    made, and the run exits non-zero naming the file. A rerun makes PS's tables and the
    summary without the failed sphere, marked failed, and still exits non-zero; once the file
    is fixed, the next run puts the sphere back and exits 0 (amontons.workflow.ledger). The
    project goes on from the lab run's (continued): the complete sphere's outputs are that
    run's, and no job of it runs again."""
    project = continued(lab_run[0], tmp_path, small_data, [COMPLETE], ["PS-corrupt"])
    image = tmp_path / "lab" / "PS-corrupt" / "fluorescence" / "100.tif"
    intact = image.read_bytes()
    image.write_bytes(intact[:2000])
    run = run_snakemake(project, "--cores", "2")
    assert run.returncode != 0
    assert jobs_of(run, COMPLETE) == set() and jobs_of(run, "PS-corrupt")
    assert str(image) in run.stderr
    check = run_check(project)
    plans = {plan["sphere"]: plan for plan in json.loads(check.stdout)}
    for path in plans[COMPLETE]["outputs"]:
        assert (project / path).is_file(), path
    errors = [f["error"] for f in plans["PS-corrupt"]["files"] if "error" in f]
    assert errors and str(image) in errors[0]
    # the check reads the run's record too: the next run holds the sphere out
    assert plans[COMPLETE]["failed"] == [] and str(image) in plans["PS-corrupt"]["failed"][0]
    # the failure, per sphere, with its error, in the run's record and at the end of its log
    record = project / "results" / SMALL / "failed_jobs.csv"
    failed = pd.read_csv(record)
    assert set(failed["sphere"]) == {"PS-corrupt"} and set(failed["material"]) == {"PS"}
    assert failed["error"].str.contains(str(image), regex=False).all()
    assert all((project / log).is_file() for log in failed["log"])
    assert f"sphere PS-corrupt (PS): {failed['rule'].iloc[0]} failed:" in run.stderr
    # PS's tables read every sphere, so this run could not make them; it says what a rerun does
    summary = project / "results" / SMALL / "summary.md"
    assert not (project / "results" / SMALL / "PS" / "load_area.csv").exists()
    assert "run again to make PS's tables, figures, summary and report without PS-corrupt" in (
        run.stderr
    )

    rerun = run_snakemake(project, "--cores", "2")
    assert rerun.returncode != 0  # the failed jobs ran again, and failed again
    assert "sphere PS-corrupt (PS): failed in an earlier run: " in rerun.stderr
    assert _spheres_in(project, "load_area.csv") == _spheres_in(project, "scenes.csv") == {COMPLETE}
    text = summary.read_text()
    held = text[text.index("## Failed: held out of every table and figure") :]
    assert "sphere PS-corrupt (PS): failed in an earlier run: measure_contact_area: " in held
    assert str(image) in held
    assert set(pd.read_csv(record)["sphere"]) == {"PS-corrupt"}

    image.write_bytes(intact)  # the file fixed: the sphere's data stamp changes
    fixed = run_snakemake(project, "--cores", "2")
    assert fixed.returncode == 0, fixed.stderr[-3000:]
    assert (
        _spheres_in(project, "load_area.csv")
        == _spheres_in(project, "scenes.csv")
        == {
            COMPLETE,
            "PS-corrupt",
        }
    )
    assert "Failed" not in summary.read_text()
    assert not record.exists()
