"""What a failed run leaves for the next one (docs/workflow.md, "When a job fails").

A material's tables, figures, summary and report read every sphere of the material, so while
one sphere's job fails they cannot be made. The run's record of its failed jobs,
``results/<run>/failed_jobs.csv`` (amontons.workflow.failures), is therefore also a ledger
that the next run reads when it builds its DAG: a sphere with a failed job in it is *held
out*. Its material's tables and figures, the summary and the report are then made without it
and say that it failed, with the step, the error and the log, and its failed jobs are run
again, so that the run still exits non-zero while they fail.

An entry stops holding its sphere out, so that the sphere is back in every table of the run
that sees it:

* when the sphere's data change: each entry carries a stamp of the sphere's raw files (name,
  size, modification time), its sheet row and the run's config, taken when the job failed;
* when its job succeeds: an entry whose output files are all there no longer counts. That
  run's tables were made without the sphere, and the next run puts it back, as the run says.

A job that a batch system stopped at one of its resources (its runtime, its memory) holds
nothing out: its sphere's data are not in question, and what the user changes before the
next run, the resource, is not in the data stamp. The next run runs the job again inside the
tables; the run says which resource to raise.

A run that ends rewrites the ledger: this run's failures, and the earlier entries that still
hold (outputs missing, not failed again in this run, e.g. of a material this run did not
target). A run without a failure that leaves no entry removes it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import replace
from pathlib import Path

from amontons.workflow.failures import (
    FAILED_JOBS,
    FailedJob,
    failed_jobs,
    failure_lines,
    read_failed_jobs,
    write_failed_jobs,
)
from amontons.workflow.paths import RunPaths

# A sphere's data stamp (amontons.workflow.run.WorkflowRun.data_stamp).
Stamp = Callable[[str], str]


def ledger_path(paths: RunPaths) -> Path:
    return Path(paths.results) / FAILED_JOBS


def is_pending(job: FailedJob, workdir: Path = Path(".")) -> bool:
    """Whether a failed job has still not made its outputs (a job that names none counts as
    pending)."""
    outputs = job.output_files
    return not outputs or not all((workdir / path).exists() for path in outputs)


def holds(job: FailedJob, stamp: Stamp, workdir: Path = Path(".")) -> bool:
    """Whether a ledger entry holds its sphere out of this run's tables: a sphere's job, still
    pending, on the same data as when it failed, and not stopped at a resource."""
    return (
        bool(job.sphere)
        and not job.limit
        and is_pending(job, workdir)
        and job.data_stamp == stamp(job.sphere)
    )


def held_out(
    jobs: Iterable[FailedJob], spheres: Iterable[str], stamp: Stamp, workdir: Path = Path(".")
) -> dict[str, list[FailedJob]]:
    """The spheres of ``spheres`` (this run's) that the ledger's ``jobs`` hold out, each with
    its failed jobs."""
    selected = set(spheres)
    out: dict[str, list[FailedJob]] = {}
    for job in jobs:
        if job.sphere in selected and holds(job, stamp, workdir):
            out.setdefault(job.sphere, []).append(job)
    return out


def read_held_out(
    paths: RunPaths, spheres: Iterable[str], stamp: Stamp
) -> dict[str, list[FailedJob]]:
    """The spheres the run's ledger holds out (none where it has no ledger)."""
    return held_out(read_failed_jobs(ledger_path(paths)), spheres, stamp)


def _key(job: FailedJob) -> tuple[str, str]:
    return job.rule, job.outputs


def merged(
    earlier: Iterable[FailedJob], failed_now: Iterable[FailedJob], workdir: Path = Path(".")
) -> list[FailedJob]:
    """The ledger after a run: this run's failures, then the earlier entries still pending
    that this run did not fail again."""
    failed_now = list(failed_now)
    again = {_key(job) for job in failed_now}
    kept = [job for job in earlier if _key(job) not in again and is_pending(job, workdir)]
    return failed_now + kept


def write_ledger(paths: RunPaths, jobs: list[FailedJob]) -> None:
    """Write the ledger, or remove it where no entry is left."""
    path = ledger_path(paths)
    if jobs:
        write_failed_jobs(path, jobs)
    elif path.is_file():
        path.unlink()


def _logs_text(snakemake_logs: str | Path | list) -> str:
    logs = [snakemake_logs] if isinstance(snakemake_logs, str | Path) else snakemake_logs
    return "".join(Path(log).read_text() for log in logs if Path(log).is_file())


def _rerun_lines(jobs: list[FailedJob], held: Iterable[str]) -> list[str]:
    """What the next run will do about this run's failed spheres: a job stopped at a resource
    runs again with it raised; a sphere with another failure is held out."""
    by_material: dict[str, set[str]] = {}
    for job in jobs:
        if job.sphere and job.sphere not in held and not job.limit:
            by_material.setdefault(job.material, set()).add(job.sphere)
    limits = sorted({(job.rule, job.limit) for job in jobs if job.limit})
    return [
        f"run again to make {material}'s tables, figures, summary and report without "
        f"{', '.join(sorted(spheres))}, marked as failed (or fix the data first)"
        for material, spheres in sorted(by_material.items())
    ] + [
        f"raise {rule}'s {limit} and run again: only the jobs that are missing run, and no "
        "sphere is held out for it"
        for rule, limit in limits
    ]


def record_failures(
    snakemake_logs: str | Path | list, paths: RunPaths, stamp: Stamp, held: Iterable[str]
) -> list[str]:
    """Snakefile's onerror: read the run's Snakemake log (one path, or a list as Snakemake 9
    gives), stamp each failed sphere job with its sphere's data, rewrite the ledger and return
    the lines to print: one per failed job, then what a rerun does for the spheres this run
    did not already hold out (``held``)."""
    now = [
        replace(job, data_stamp=stamp(job.sphere) if job.sphere else "")
        for job in failed_jobs(_logs_text(snakemake_logs), paths)
    ]
    write_ledger(paths, merged(read_failed_jobs(ledger_path(paths)), now))
    return failure_lines(now) + _rerun_lines(now, set(held))


def settle_ledger(paths: RunPaths, held: Iterable[str]) -> list[str]:
    """Snakefile's onsuccess: drop the entries whose jobs have now made their outputs and
    return a line for each sphere this run held out that no entry holds any more: this run's
    tables were made without it, and the next run puts it back."""
    earlier = read_failed_jobs(ledger_path(paths))
    left = merged(earlier, [])
    write_ledger(paths, left)
    still = {job.sphere for job in left}
    return [
        f"sphere {sphere}: its failed jobs now succeed; this run's tables were made without "
        "it, run again to put it back"
        for sphere in sorted(set(held) - still)
    ]
