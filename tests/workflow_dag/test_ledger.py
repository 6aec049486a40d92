"""A failed run's record read by the next run (amontons.workflow.ledger): the failed sphere is
held out of its material's tables while its data stay as they were and its job keeps
failing, and is back as soon as either changes. Built as workflow/rules/common.smk builds the
run, on the small config with its PS sphere as a measured folder."""

import os
import shutil
from pathlib import Path

from amontons.workflow.failures import FAILED_JOBS, FailedJob, read_failed_jobs
from amontons.workflow.ledger import merged, record_failures, settle_ledger, write_ledger
from amontons.workflow.paths import RunPaths

DATA = Path(__file__).parent / "data"
RUN_LOG = DATA / "failed_run.snakemake.log"
PATHS = RunPaths("small")
AREA = "results/small/PS/PS/measure/contact_area.csv"
LEDGER = Path("results/small") / FAILED_JOBS


def _ledger_of_ps(run, outputs=AREA, stamp=None):
    job = FailedJob(
        "measure_contact_area",
        "PS",
        "PS",
        "logs/small/PS/PS/measure_contact_area.log",
        "amontons.io.layout.RawDataError: fluorescence image: lab/PS/fluorescence/100.tif: "
        "not a readable TIFF",
        outputs,
        run.data_stamp("PS") if stamp is None else stamp,
    )
    write_ledger(PATHS, [job])
    return job


def test_a_sphere_with_a_failed_job_is_held_out_of_its_tables_and_its_job_retried(measured_ps):
    before = measured_ps()
    assert before.spheres.of("PS") == ["PS"] and not before.spheres.held_out
    figures = before.targets.figures(["PS"])
    assert any(path.startswith("results/small/PS/load_area.") for path in figures)
    job = _ledger_of_ps(before)
    run = measured_ps()
    assert list(run.spheres.held_out) == ["PS"]
    assert run.spheres.of("PS") == []
    # no PS table or figure is asked for; the failed job is, so the run fails while it does
    targets = run.targets.material(["PS"])
    assert not any(path.startswith("results/small/PS/PS/scenes/") for path in targets)
    assert not any(path.startswith("results/small/PS/load_area.") for path in targets)
    assert AREA in targets and run.targets.retries(["glass"]) == []
    assert "PS" not in run.summary.layout()["fits"]
    # named, with its error and log, in the dry run's lines, the summary and the report
    (line,) = run.failed()
    assert line.startswith("sphere PS (PS): failed in an earlier run: measure_contact_area: ")
    assert job.error in line and job.log in line
    # the other materials are untouched
    assert run.spheres.of("glass") == before.spheres.of("glass") == ["glass"]


def test_changed_data_or_config_let_the_sphere_back(measured_ps, tmp_path):
    run = measured_ps()
    _ledger_of_ps(run)
    assert measured_ps().spheres.held_out
    image = tmp_path / "lab" / "PS" / "bead.tif"
    image.write_text("a new bead image")
    assert not measured_ps().spheres.held_out
    _ledger_of_ps(measured_ps())
    assert measured_ps().spheres.held_out
    stat = image.stat()
    os.utime(image, ns=(stat.st_atime_ns, stat.st_mtime_ns + 1_000_000_000))  # re-saved
    assert not measured_ps().spheres.held_out
    _ledger_of_ps(run, stamp="a stamp under another config")
    assert not measured_ps().spheres.held_out


def test_a_job_stopped_at_its_runtime_holds_nothing_out(measured_ps):
    """SLURM's TIMEOUT says nothing about the sphere's data, and the runtime the user raises
    is not in the data stamp: the sphere stays in the tables and its job runs again."""
    run = measured_ps()
    job = FailedJob(
        "simulate_scene",
        "PS",
        "PS",
        "logs/small/PS/PS/scenes/elastic/simulate_scene.log",
        "stopped by SLURM (TIMEOUT) at its runtime of 1 min: raise it, e.g. "
        "--set-resources simulate_scene:runtime=2",
        "results/small/PS/PS/scenes/elastic/fields.h5",
        run.data_stamp("PS"),
        limit="runtime",
    )
    write_ledger(PATHS, [job])
    assert read_failed_jobs(LEDGER) == [job]
    assert not measured_ps().spheres.held_out


def test_a_job_that_has_made_its_outputs_holds_nothing_out(measured_ps):
    _ledger_of_ps(measured_ps())
    Path(AREA).parent.mkdir(parents=True)
    Path(AREA).write_text("sphere,load_mn\n")
    assert not measured_ps().spheres.held_out
    assert settle_ledger(PATHS, held=["PS"]) == [
        "sphere PS: its failed jobs now succeed; this run's tables were made without it, run "
        "again to put it back"
    ]
    assert not LEDGER.exists()  # no entry left: no ledger


def test_a_failed_run_stamps_its_jobs_and_says_what_a_rerun_does(measured_ps):
    """As Snakefile's onerror calls it, on the real log of the corrupt-file run (sphere
    PS-corrupt of material PS); the earlier entry of another sphere, still pending, stays."""
    run = measured_ps()
    earlier = _ledger_of_ps(run)
    stamps = {"PS-corrupt": "stamp of PS-corrupt"}
    lines = record_failures([str(RUN_LOG)], PATHS, stamps.get, held=[])
    jobs = read_failed_jobs(LEDGER)
    assert [job.sphere for job in jobs] == ["PS-corrupt"] * 3 + ["PS"]
    assert {job.data_stamp for job in jobs[:3]} == {"stamp of PS-corrupt"}
    assert jobs[0].output_files == [
        "results/small/PS/PS-corrupt/measure/contact_area.csv",
        "results/small/PS/PS-corrupt/measure/contact_area.png",
        "results/small/PS/PS-corrupt/measure/contact_area.pdf",
    ]
    assert jobs[3] == earlier
    assert lines[-1] == (
        "run again to make PS's tables, figures, summary and report without PS-corrupt, "
        "marked as failed (or fix the data first)"
    )
    # a sphere already held out in this run gets no such line: its tables were made
    again = record_failures([str(RUN_LOG)], PATHS, stamps.get, held=["PS-corrupt"])
    assert len(again) == 3 and len(read_failed_jobs(LEDGER)) == 4


def test_a_rerun_keeps_only_what_is_still_pending(tmp_path):
    made = tmp_path / "made.csv"
    made.write_text("")
    old = [
        FailedJob("a", "PS", "PS-1", "a.log", "", str(made)),
        FailedJob("b", "PS", "PS-1", "b.log", "", str(tmp_path / "missing.csv")),
        FailedJob("c", "PS", "PS-2", "c.log", "", str(tmp_path / "again.csv")),
    ]
    now = [FailedJob("c", "PS", "PS-2", "c.log", "new error", str(tmp_path / "again.csv"))]
    assert merged(old, now) == [now[0], old[1]]


def test_a_record_of_the_earlier_layout_reads_without_outputs_or_stamps(tmp_path):
    """failed_jobs.csv before the ledger (five columns): read, and it holds nothing out,
    since its stamp matches no sphere's."""
    shutil.copy(DATA / "failed_jobs_without_ledger.csv", tmp_path / FAILED_JOBS)
    (job,) = read_failed_jobs(tmp_path / FAILED_JOBS)
    assert job.outputs == job.data_stamp == "" and job.sphere == "PS-corrupt"
