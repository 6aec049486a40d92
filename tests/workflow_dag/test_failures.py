"""A failed run's jobs named per sphere (amontons.workflow.failures), read from the Error
blocks of a real Snakemake 9 log: the small run with one truncated fluorescence image
(tests/workflow/test_own_data.py), cut to those blocks, and one of its jobs' own log."""

import shutil
from pathlib import Path

import pandas as pd

from amontons.workflow.failures import FAILED_JOBS, failed_jobs, failure_lines, last_error
from amontons.workflow.ledger import record_failures
from amontons.workflow.paths import RunPaths

DATA = Path(__file__).parent / "data"
RUN_LOG = DATA / "failed_run.snakemake.log"
JOB_LOG = "logs/small/PS/PS-corrupt/measure_contact_area.log"


def test_every_failed_job_is_named_with_its_rule_sphere_and_log():
    jobs = failed_jobs(RUN_LOG.read_text(), RunPaths("small"), workdir=DATA / "absent")
    assert [job.rule for job in jobs] == [
        "measure_contact_area",
        "measure_intensity_pressure",
        "compare_scene",
    ]
    assert {(job.material, job.sphere) for job in jobs} == {("PS", "PS-corrupt")}
    assert jobs[2].log == "logs/small/PS/PS-corrupt/scenes/elastic/compare_scene.log"
    # no job log where it looked: the line points to the log instead of inventing an error
    assert all(job.error == "" for job in jobs)
    assert failure_lines(jobs)[0] == (
        f"sphere PS-corrupt (PS): measure_contact_area failed: see its log [{JOB_LOG}]"
    )


def test_a_job_error_is_the_last_exception_line_of_its_log():
    """The job's log holds the ImageError and the RawDataError raised from it: the last one,
    which names the file and what was expected, is the job's error."""
    error = last_error((DATA / "measure_contact_area.log").read_text())
    assert error.startswith("amontons.io.layout.RawDataError: fluorescence image: ")
    assert "PS-corrupt/fluorescence/100.tif: not a readable TIFF" in error
    assert last_error("INFO all well\n") == ""


def test_the_report_writes_the_run_record_and_reads_logs_from_a_list(tmp_path, monkeypatch):
    """As Snakefile's onerror calls it (Snakemake 9 passes its logs as a list)."""
    monkeypatch.chdir(tmp_path)
    job_log = tmp_path / JOB_LOG
    job_log.parent.mkdir(parents=True)
    shutil.copy(DATA / "measure_contact_area.log", job_log)
    lines = record_failures([str(RUN_LOG)], RunPaths("small"), lambda sphere: "stamp", [])
    table = pd.read_csv(tmp_path / "results" / "small" / FAILED_JOBS, keep_default_na=False)
    columns = ["rule", "material", "sphere", "log", "error", "outputs", "data_stamp"]
    assert table.columns.tolist() == columns
    assert len(table) == len(lines) - 1 == 3  # and the line that says what a rerun does
    assert "100.tif: not a readable TIFF" in table["error"].iloc[0]
    assert table["error"].iloc[1] == ""  # that job's log is not there
    assert "100.tif: not a readable TIFF" in lines[0]
