"""The jobs a run could not finish, per sphere: read from Snakemake's log when the run stops
with an error, written to ``failed_jobs.csv`` in the run's results folder and printed, so that
a failure names the sphere, the step and the error, not only a job number (docs/workflow.md,
"When a job fails").

Snakemake logs each failed job as an ``Error in rule <name>:`` block whose indented lines give
its output and log files. A job's sphere and material come from those paths (the run's layout,
amontons.workflow.paths); its error is the last exception line of its own log. A job that a
batch system stopped at one of its resources (SLURM's TIMEOUT and OUT_OF_MEMORY, which the
SLURM executor plugin writes into the block's message) has no exception in its log: its error
names the resource, the value it ran with (from the block that started the job) and the
option that raises it (docs/cluster.md, "When a job runs out of its time or memory"). What
the next run does with the record is amontons.workflow.ledger's.
"""

from __future__ import annotations

import csv
import re
from dataclasses import astuple, dataclass, fields
from pathlib import Path

from amontons.io.files import atomic_path
from amontons.workflow.paths import RunPaths

_BLOCK = re.compile(r"^Error in rule (?P<rule>\S+):\n(?P<body>(?:[ \t]+\S.*\n?)*)", re.MULTILINE)
# The first line of the block Snakemake logs when it starts a job ("rule <name>:" or
# "localrule <name>:"), indented for a job of a group job.
_START_LINE = re.compile(r"^[ \t]*(?:local)?rule (?P<rule>\S+):$")
# The SLURM executor plugin's message for a job that ended in a failed state.
_SLURM_STATE = re.compile(r"SLURM status is: '(?P<state>[A-Z_]+)'")
_ENTRY = re.compile(r"^[ \t]+(?P<key>[\w-]+): (?P<value>.*)$", re.MULTILINE)
# An exception's last line, as Python prints it: "package.module.SomeError: message".
_EXCEPTION = re.compile(r"^(?:[\w.]+\.)?\w*(?:Error|Exception)\b.*$")
FAILED_JOBS = "failed_jobs.csv"
# The job states in which SLURM stopped a job at a resource: the resource and its unit.
RESOURCE_LIMITS = {"TIMEOUT": ("runtime", "min"), "OUT_OF_MEMORY": ("mem_mb", "MB")}


# Snakemake's log lists a job's output files with this between them; the record keeps them so.
OUTPUT_SEPARATOR = ", "


@dataclass(frozen=True)
class FailedJob:
    """One job that failed: its rule, the sphere and material its files belong to ('' for a
    run-wide job), its log file, the error its log ends with, its output files (joined by
    :data:`OUTPUT_SEPARATOR`), the stamp of its sphere's data when it failed
    (amontons.workflow.ledger; '' before it is stamped) and, for a job a batch system stopped
    at one of its resources, that resource (a key of the job's resources, '' otherwise)."""

    rule: str
    material: str
    sphere: str
    log: str
    error: str
    outputs: str = ""
    data_stamp: str = ""
    limit: str = ""

    @property
    def output_files(self) -> list[str]:
        return [path for path in self.outputs.split(OUTPUT_SEPARATOR) if path]


def _entries(body: str) -> dict[str, str]:
    return {m["key"]: m["value"].strip() for m in _ENTRY.finditer(body)}


def _owner(paths: list[str], root: str) -> tuple[str, str]:
    """(material, sphere) of the first path below ``root``/<material>/<sphere>/."""
    for path in paths:
        parts = Path(path).parts
        base = Path(root).parts
        if parts[: len(base)] == base and len(parts) > len(base) + 2:
            return parts[len(base)], parts[len(base) + 1]
    return "", ""


def started_resources(snakemake_log: str) -> dict[tuple[str, str], dict[str, str]]:
    """Each started job's resources ("resources: mem_mb=2500, ..., runtime=1"; values as
    written), by its rule and output files as the log's start blocks list them. Read line by
    line: the jobs of a group job are listed indented, and a cluster job's own log, appended
    to the run's where it failed, numbers its jobs anew, so neither the indent nor the job id
    tells one job from another."""
    out: dict[tuple[str, str], dict[str, str]] = {}
    rule = outputs = None
    for line in snakemake_log.splitlines():
        started = _START_LINE.match(line)
        if started:
            rule, outputs = started["rule"], None
            continue
        key, _, value = line.strip().partition(": ")
        if rule and key == "output":
            outputs = value
        elif rule and key == "resources":
            pairs = (item.split("=", 1) for item in value.split(", "))
            out[rule, outputs or ""] = {pair[0]: pair[1] for pair in pairs if len(pair) == 2}
            rule = None
    return out


def limit_error(rule: str, message: str, resources: dict[str, str]) -> tuple[str, str]:
    """(resource, error) for a job that SLURM stopped at a resource, as the SLURM executor's
    ``message`` says; ('', '') for any other failure. The error gives the value the job ran
    with and the option that doubles it."""
    state = _SLURM_STATE.search(message)
    if not state or state["state"] not in RESOURCE_LIMITS:
        return "", ""
    resource, unit = RESOURCE_LIMITS[state["state"]]
    value = resources.get(resource, "")
    raise_to = f"{2 * int(value)}" if value.isdigit() else "<more>"
    return resource, (
        f"stopped by SLURM ({state['state']}) at its {resource} of {value or '?'} {unit}: "
        f"raise it, e.g. --set-resources {rule}:{resource}={raise_to}"
    )


def last_error(log_text: str) -> str:
    """The last exception line of a job's log ('' where it has none)."""
    lines = [line.strip() for line in log_text.splitlines()]
    errors = [line for line in lines if _EXCEPTION.match(line)]
    return errors[-1] if errors else ""


def failed_jobs(snakemake_log: str, paths: RunPaths, workdir: Path = Path(".")) -> list[FailedJob]:
    """The failed jobs of a run, from the text of Snakemake's log, with the error read from
    each job's own log (relative to ``workdir``) where it is there. A job is listed once: a
    cluster job's own log, which the run's log repeats where it failed, names it again."""
    jobs: dict[tuple[str, str], FailedJob] = {}
    resources = started_resources(snakemake_log)
    for block in _BLOCK.finditer(snakemake_log):
        entries = _entries(block["body"])
        log = entries.get("log", "").split(" (check log")[0].split(OUTPUT_SEPARATOR)[0]
        outputs = entries.get("output", "")
        material, sphere = _owner([*outputs.split(OUTPUT_SEPARATOR), log], paths.results)
        if not sphere:
            material, sphere = _owner([log], paths.logs)
        job_log = workdir / log if log else None
        key = (block["rule"], outputs)
        limit, error = limit_error(
            block["rule"], entries.get("message", ""), resources.get(key, {})
        )
        if not limit:
            error = last_error(job_log.read_text()) if job_log and job_log.is_file() else ""
        if key not in jobs or (limit and not jobs[key].limit):
            jobs[key] = FailedJob(block["rule"], material, sphere, log, error, outputs, limit=limit)
    return list(jobs.values())


def read_failed_jobs(path: str | Path) -> list[FailedJob]:
    """The jobs of a record written by :func:`write_failed_jobs` (none where there is no
    record). A record of an older layout, without outputs or stamps, reads with them empty."""
    path = Path(path)
    if not path.is_file():
        return []
    with open(path, newline="") as stream:
        return [FailedJob(**row) for row in csv.DictReader(stream)]


def write_failed_jobs(path: str | Path, jobs: list[FailedJob]) -> None:
    """The failed jobs as CSV, one row per job (columns: FailedJob's fields), written whole or
    not at all."""
    with atomic_path(path) as tmp, open(tmp, "w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow([f.name for f in fields(FailedJob)])
        writer.writerows(astuple(job) for job in jobs)


def failure_lines(jobs: list[FailedJob]) -> list[str]:
    """One line per failed job, for the terminal: the sphere, the step, the error, the log."""
    lines = []
    for job in jobs:
        where = f"sphere {job.sphere} ({job.material})" if job.sphere else "run"
        lines.append(f"{where}: {job.rule} failed: {job.error or 'see its log'} [{job.log}]")
    return lines
