"""The small data set, made once per test session and shared by every test process.

One project folder, deployed as a user deploys the workflow (README, "Use it from a folder of
your own": a Snakefile of its own that declares the repository's as a module), runs the
small data set (config/test.yaml: PS and glass) in two steps:

- ``small_data``: the virtual experiment only, the raw files that the own-data, no-prior and
  load-series tests copy as "measured" spheres (about a minute);
- ``small_run``: the whole run, the accuracy study and the reduced validation study in one
  Snakemake call, then its report; the workflow, deploy, report, accuracy, validation and
  executor tests read what it made;
- ``lab_run``: a lab's project made from the small data (lab.py), which the own-data tests
  read and three other modules go on from.

Under pytest-xdist (``make test`` runs the suite on every core) each worker process asks for
these fixtures; the first to ask makes them under a file lock in the session's shared
temporary folder, and the others wait for it and read the same folder, so the small data set
runs once per session however many workers there are. A failed run is recorded beside the
folder, and every worker that asks then fails with its error instead of running it again.
Tests only read these folders (the rerun test edits a copy of the overlay, rerun.yaml).
"""

import contextlib
import fcntl
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from .lab import make_lab_run, read_lab_run

REPO = Path(__file__).resolve().parents[2]
RUN = "small"
CONFIG = "config/test.yaml"
# Where the README's Snakefile names the clone.
CLONE = "/path/to/amontons"


def readme_snakefile() -> str:
    """The README's Snakefile of a folder of one's own, naming this clone."""
    page = (REPO / "README.md").read_text(encoding="utf-8")
    section = page.split("\n## Use it from a folder of your own\n", 1)[1]
    block = section.split("```python\n", 1)[1].split("```", 1)[0]
    assert CLONE in block
    return block.replace(CLONE, str(REPO))


def _shared_root(tmp_path_factory) -> Path:
    """The session's temporary folder that every xdist worker sees (each worker's own
    basetemp is a child of it); without xdist, the session's own."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


@contextlib.contextmanager
def _exclusive(path: Path):
    """An exclusive lock on ``path`` across processes (POSIX advisory lock)."""
    with open(path, "w") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def _once(root: Path, name: str, make) -> None:
    """``make()`` once per session across processes: the first caller runs it under the
    lock and leaves ``<name>.done`` (or ``<name>.failed`` with the error); later callers
    wait for the lock and read the outcome."""
    done, failed = root / f"{name}.done", root / f"{name}.failed"
    with _exclusive(root / f"{name}.lock"):
        if not done.exists() and not failed.exists():
            try:
                make()
            except BaseException as exc:
                failed.write_text(str(exc))
                raise
            done.touch()
    if failed.exists():
        pytest.fail(f"{name} failed in another test process: {failed.read_text()[-3000:]}")


def _snakemake(project: Path, *args: str, timeout: int) -> None:
    """The deployed folder's Snakemake (its own Snakefile), as a user runs it there, with the
    clone's profile named as docs/deploy.md says (Snakemake finds it only in the clone)."""
    start = time.perf_counter()
    profile = ("--workflow-profile", str(REPO / "profiles" / "default"))
    result = subprocess.run(
        [sys.executable, "-m", "snakemake", *args, *profile, "--configfile", CONFIG],
        cwd=project,
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    assert result.returncode == 0, f"snakemake {' '.join(args)}: {result.stderr[-3000:]}"
    print(f"snakemake {' '.join(args)}: {time.perf_counter() - start:.1f} s")


def _deploy(project: Path) -> None:
    """A user's folder: a copy of config/ and the README's module Snakefile."""
    project.mkdir()
    shutil.copytree(REPO / "config", project / "config")
    (project / "Snakefile").write_text(readme_snakefile(), encoding="utf-8")


@pytest.fixture(scope="session")
def small_data(tmp_path_factory) -> Path:
    """The deployed folder after the small data set's virtual experiment: its raw files are
    resources/synthetic/small/<sphere>/."""
    root = _shared_root(tmp_path_factory)
    project = root / "small"

    def make():
        _deploy(project)
        _snakemake(project, "virtual_experiment", "--cores", "2", timeout=1200)

    _once(root, "small_data", make)
    return project


@pytest.fixture(scope="session")
def small_run(small_data, tmp_path_factory) -> Path:
    """The deployed folder after the whole small-data run, 2 cores, the accuracy study
    (`snakemake accuracy`) and the reduced validation study (`snakemake validation`, and
    `snakemake validation_spheres` on the sheet's PS sphere), with the report at
    results/small/report.html. Tests only read it (the rerun test's dry runs
    read an edited copy of its overlay)."""
    root = _shared_root(tmp_path_factory)

    def make():
        _snakemake(
            small_data,
            "all",
            "accuracy",
            "validation",
            "validation_spheres",
            "--cores",
            "2",
            timeout=2400,
        )
        _snakemake(small_data, "--report", f"results/{RUN}/report.html", timeout=600)

    _once(root, "small_run", make)
    return small_data


@pytest.fixture(scope="session")
def lab_run(small_data, tmp_path_factory) -> tuple[Path, ...]:
    """A lab's project (lab.py: copies of the small data's PS sphere, each lacking a file or
    holding another format) after its dry run, the check and its run, once per session:
    (project, dry run, check, run), the commands as subprocess.CompletedProcess. The own-data
    module reads it; the corrupt-file, cut-scan and prior-free modules go on from it, each in
    whichever test process is free once it is done, side by side."""
    root = _shared_root(tmp_path_factory)
    folder = root / "own_data"
    _once(root, "lab_run", lambda: make_lab_run(small_data, folder))
    return read_lab_run(folder)
