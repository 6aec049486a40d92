"""The small-data run, once per session: the workflow tests of test_workflow.py read its
results, and test_executor.py compares a run through a cluster executor with it."""

import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def small_run(tmp_path_factory):
    """A project folder after the small-data run (config/test.yaml: PS and glass), local
    executor, 2 cores. Tests only read its results (one edits its config, for dry runs)."""
    project = tmp_path_factory.mktemp("small")
    shutil.copytree(REPO / "config", project / "config")
    start = time.perf_counter()
    result = subprocess.run(
        [sys.executable, "-m", "snakemake", "-s", str(REPO / "Snakefile"), "-d", str(project)]
        + ["--cores", "2", "--configfile", "config/test.yaml"],
        cwd=project,
        capture_output=True,
        text=True,
        timeout=1200,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    print(f"small-data run: {time.perf_counter() - start:.1f} s")
    return project
