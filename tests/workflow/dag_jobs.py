"""Every job of the workflow's DAG as plain data: rule, wildcards, input, output, log,
benchmark, params, threads and resources, sorted, so that two versions of the workflow's code
can be compared job by job (tests/workflow/test_dag_unchanged.py).

Run as a script in its own process (Snakemake's API changes the working directory and keeps
module state):

    python tests/workflow/dag_jobs.py --workdir DIR --configfile config/test.yaml [TARGET ...]

It prints the jobs as JSON. The DAG is built as ``snakemake -n`` builds it, with every job
scheduled (``--forceall``), so that files already made do not hide a job.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from snakemake.api import SnakemakeApi
from snakemake.settings.types import (
    ConfigSettings,
    DAGSettings,
    OutputSettings,
    ResourceSettings,
)

REPO = Path(__file__).resolve().parents[2]
# Resources Snakemake adds itself, whose values depend on the machine, not on the workflow.
MACHINE_RESOURCES = {"tmpdir", "_cores", "_nodes", "mem_mib", "disk_mib", "disk_mb"}


def _plain(value):
    """A params or resources value as JSON-ready data (Snakemake's Namedlist as a dict)."""
    if hasattr(value, "_names") and hasattr(value, "items"):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, str | int | float | bool) or value is None:
        return value
    return repr(value)


def _job_record(job) -> dict:
    resources = {
        name: _plain(value)
        for name, value in job.resources.items()
        if name not in MACHINE_RESOURCES
    }
    return {
        "rule": job.rule.name,
        "wildcards": dict(sorted(job.wildcards_dict.items())),
        "input": sorted(map(str, job.input)),
        "output": sorted(map(str, job.output)),
        "log": sorted(map(str, job.log)),
        "benchmark": str(job.benchmark) if job.benchmark else None,
        "params": {str(k): _plain(v) for k, v in job.params.items()},
        "threads": job.threads,
        "resources": resources,
    }


def dag_jobs(workdir: Path, configfiles: list[Path], targets: list[str]) -> list[dict]:
    """The jobs of the DAG of ``targets`` (default: the workflow's default target)."""
    with SnakemakeApi(OutputSettings(quiet={"all"})) as api:
        workflow_api = api.workflow(
            resource_settings=ResourceSettings(cores=1),
            config_settings=ConfigSettings(configfiles=configfiles),
            snakefile=REPO / "Snakefile",
            workdir=workdir,
        )
        dag_api = workflow_api.dag(dag_settings=DAGSettings(targets=set(targets), forceall=True))
        workflow = dag_api.workflow_api._workflow
        workflow._prepare_dag(forceall=True, ignore_incomplete=True, lock_warn_only=True)
        workflow._build_dag()
        jobs = [_job_record(job) for job in workflow.dag.jobs]
    return sorted(jobs, key=lambda job: (job["rule"], job["output"]))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workdir", type=Path, required=True)
    parser.add_argument("--configfile", type=Path, action="append", default=[])
    parser.add_argument("targets", nargs="*")
    args = parser.parse_args(argv)
    configfiles = [path.resolve() for path in args.configfile]
    jobs = dag_jobs(args.workdir.resolve(), configfiles, args.targets)
    json.dump(jobs, sys.stdout, indent=1, sort_keys=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
