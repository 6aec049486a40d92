"""A failed run's jobs named per sphere (amontons.workflow.failures), read from the Error
blocks of a real Snakemake 9 log: the small run with one truncated fluorescence image
(tests/workflow/test_own_data.py), cut to those blocks, and one of its jobs' own log."""

import shutil
from pathlib import Path

import pandas as pd

from amontons.workflow.failures import (
    FAILED_JOBS,
    failed_jobs,
    failure_lines,
    last_error,
    limit_error,
    started_resources,
)
from amontons.workflow.ledger import record_failures
from amontons.workflow.paths import RunPaths

DATA = Path(__file__).parent / "data"
RUN_LOG = DATA / "failed_run.snakemake.log"
# A run through a real SLURM (tests/cluster) whose scene job ran past its runtime of 1 min.
TIMEOUT_LOG = DATA / "timeout_run.snakemake.log"
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
    columns = ["rule", "material", "sphere", "log", "error", "outputs", "data_stamp", "limit"]
    assert table.columns.tolist() == columns
    assert len(table) == len(lines) - 1 == 3  # and the line that says what a rerun does
    assert "100.tif: not a readable TIFF" in table["error"].iloc[0]
    assert table["error"].iloc[1] == ""  # that job's log is not there
    assert "100.tif: not a readable TIFF" in lines[0]


def test_a_job_slurm_stopped_at_its_runtime_names_the_resource_and_how_to_raise_it(
    tmp_path, monkeypatch
):
    """The SLURM executor's TIMEOUT, from a real run's log: the job's own log is empty, so the
    error comes from the block's message and the runtime from the block that started it."""
    jobs = failed_jobs(TIMEOUT_LOG.read_text(), RunPaths("small"), workdir=DATA / "absent")
    assert [(job.rule, job.sphere, job.limit) for job in jobs] == [
        ("simulate_scene", "glass", "runtime")
    ]
    assert failure_lines(jobs) == [
        "sphere glass (glass): simulate_scene failed: stopped by SLURM (TIMEOUT) at its runtime "
        "of 1 min: raise it, e.g. --set-resources simulate_scene:runtime=2 "
        "[logs/small/glass/glass/scenes/penetration_hardness/simulate_scene.log]"
    ]
    monkeypatch.chdir(tmp_path)  # the record is written in the run's folder
    lines = record_failures([str(TIMEOUT_LOG)], RunPaths("small"), lambda s: "stamp", [])
    assert (tmp_path / "results" / "small" / FAILED_JOBS).is_file()
    assert lines[-1] == (
        "raise simulate_scene's runtime and run again: only the jobs that are missing run, and "
        "no sphere is held out for it"
    )


def test_out_of_memory_names_mem_mb_and_other_states_no_resource():
    message = "SLURM-job '7' failed, SLURM status is: 'OUT_OF_MEMORY'. Reason: Unknown."
    assert limit_error("level_afm_map", message, {"mem_mb": "1500"}) == (
        "mem_mb",
        "stopped by SLURM (OUT_OF_MEMORY) at its mem_mb of 1500 MB: raise it, e.g. "
        "--set-resources level_afm_map:mem_mb=3000",
    )
    failed = "SLURM-job '7' failed, SLURM status is: 'FAILED'. Reason: Unknown."
    assert limit_error("level_afm_map", failed, {"mem_mb": "1500"}) == ("", "")
    assert limit_error("level_afm_map", "None", {}) == ("", "")


def test_a_slurm_run_names_each_failed_job_once_with_its_own_resources():
    """A real SLURM run (tests/cluster) with a failed job and a timeout: its log repeats the
    failed cluster job's own log, whose Snakemake names the job again (and numbers it anew),
    and lists a group job's jobs indented. Each failed job is named once, and the timeout
    reads the runtime of its own start block."""
    text = (DATA / "slurm_faults_run.snakemake.log").read_text()
    assert text.count("Error in rule measure_contact_area:") == 3
    jobs = failed_jobs(text, RunPaths("small"), workdir=DATA / "absent")
    assert [(job.rule, job.sphere, job.limit) for job in jobs] == [
        ("measure_contact_area", "PS", ""),
        ("simulate_scene", "glass", "runtime"),
    ]
    assert "at its runtime of 1 min" in jobs[1].error
    resources = started_resources(text)
    psf = "results/small/glass/glass/measure/psf"
    grouped = ("measure_psf", f"{psf}.json, {psf}.png, {psf}.pdf")
    assert resources[grouped]["mem_mb"].isdigit()
