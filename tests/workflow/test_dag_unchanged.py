"""The DAG of the full and small configs, job by job, against the one recorded in
tests/workflow/dags/: the same rules, wildcards, inputs, outputs, logs, params, threads and
resources. It holds a rewrite of the workflow's wiring (issue 35) to the DAG it replaced, and
makes every later change to the DAG a reviewed change of the recorded files.

A change to the DAG that is meant: record it anew with

    python tests/workflow/test_dag_unchanged.py --write

and say in the commit which jobs changed and why.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.workflow

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
RECORDED = HERE / "dags"
# name of the recording -> (config overlay over config/config.yaml, target or None)
CASES = {
    "config": ("config.yaml", None),
    "config_accuracy": ("config.yaml", "accuracy"),
    "test": ("test.yaml", None),
    "test_accuracy": ("test.yaml", "accuracy"),
}


def current_jobs(project: Path, name: str, extra_configs=()) -> list[dict]:
    """The jobs of case ``name`` as the workflow builds them now, in ``project`` (with the
    config files ``extra_configs`` merged over its own)."""
    overlay, target = CASES[name]
    command = [
        sys.executable,
        str(HERE / "dag_jobs.py"),
        "--workdir",
        str(project),
        "--configfile",
        str(project / "config" / overlay),
        *[arg for path in extra_configs for arg in ("--configfile", str(path))],
        *([target] if target else []),
    ]
    result = subprocess.run(command, capture_output=True, text=True, cwd=project, timeout=300)
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


def recorded_jobs(name: str) -> list[dict]:
    with open(RECORDED / f"{name}.jsonl", encoding="utf-8") as stream:
        return [json.loads(line) for line in stream]


def write_recording(name: str, jobs: list[dict]) -> None:
    with open(RECORDED / f"{name}.jsonl", "w", encoding="utf-8") as stream:
        for job in jobs:
            stream.write(json.dumps(job, sort_keys=True) + "\n")


def _key(job: dict) -> tuple:
    return job["rule"], tuple(job["output"])


def differences(recorded: list[dict], current: list[dict]) -> list[str]:
    """What differs, job by job: jobs missing or added, and each field of a job that changed."""
    before = {_key(job): job for job in recorded}
    after = {_key(job): job for job in current}
    lines = [f"missing job {key[0]} -> {key[1][:2]}" for key in before.keys() - after.keys()]
    lines += [f"new job {key[0]} -> {key[1][:2]}" for key in after.keys() - before.keys()]
    for key in sorted(before.keys() & after.keys()):
        for field, value in before[key].items():
            if after[key].get(field) != value:
                lines.append(
                    f"{key[0]} {key[1][0]}: {field} was {value!r}, now {after[key].get(field)!r}"
                )
    return sorted(lines)


@pytest.fixture
def project(tmp_path):
    shutil.copytree(REPO / "config", tmp_path / "config")
    return tmp_path


def test_a_changed_job_is_reported_field_by_field():
    job = {"rule": "r", "output": ["a"], "params": {"x": 1}}
    assert differences([job], [job]) == []
    assert differences([job], [{**job, "params": {"x": 2}}]) == [
        "r a: params was {'x': 1}, now {'x': 2}"
    ]
    assert differences([job], []) == ["missing job r -> ('a',)"]


@pytest.mark.parametrize("name", sorted(CASES))
def test_the_dag_is_the_recorded_one(project, name):
    found = differences(recorded_jobs(name), current_jobs(project, name))
    assert found == [], "\n".join(found[:40])


# With the solver backend switched to cupy (config solver_backend, config/README.md), every job
# of the solve rules asks for a GPU and passes the backend to its script, and no other job
# changes; the dry run needs no CuPy (only a solve job itself does).
SOLVE_RULES = {"simulate_scene", "simulate_synthetic_scene", "scan_scene"}


@pytest.mark.parametrize("name", ["test", "test_accuracy"])
def test_with_cupy_every_solve_job_asks_for_a_gpu(project, name):
    switch = project / "config" / "gpu.yaml"
    switch.write_text("solver_backend: cupy\n")
    jobs = {_key(job): job for job in current_jobs(project, name, [switch])}
    recorded = {_key(job): job for job in recorded_jobs(name)}
    assert jobs.keys() == recorded.keys()
    solves = 0
    for key, job in jobs.items():
        before = recorded[key]
        if job["rule"] in SOLVE_RULES:
            solves += 1
            assert job["resources"] == {**before["resources"], "gpu": 1}
            assert job["params"] == {**before["params"], "solver_backend": "cupy"}
        else:
            assert job == before, key
    assert solves > 0 or name == "test_accuracy"


if __name__ == "__main__":
    if sys.argv[1:] != ["--write"]:
        sys.exit(__doc__)
    import tempfile

    for case in CASES:
        with tempfile.TemporaryDirectory() as folder:
            shutil.copytree(REPO / "config", Path(folder) / "config")
            write_recording(case, current_jobs(Path(folder), case))
        print(f"recorded {case}")
