"""A run killed mid-write (SIGKILL to Snakemake and its jobs, as a lost node or an
out-of-memory kill does it), unlocked and run again, gives the bytes of a run that was never
killed, and leaves no temporary behind (amontons.io.files.atomic_path): the killed writer's
temporary beside its output is removed when the rerun writes that output.

The kill does not race the writer: every job of the killed run imports a ``sitecustomize``
(through PYTHONPATH) that stops its process (SIGSTOP) just before a temporary of
atomic_path is moved into place, so the temporary is on disk when the kill comes however
loaded the machine is (a poller alone missed every temporary once, on a busy CI machine)."""

import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.workflow

REPO = Path(__file__).resolve().parents[2]
SPHERE = Path("resources/synthetic/small/PS")
TARGET = str(SPHERE / "truth.json")
# the temporaries atomic_path names on this host: .<name>.<host>-<pid>.<random><suffix>
MARK = f".{socket.gethostname()}-"
# stops a writer at its first move of a temporary into place beside a file output of
# ``folder`` (SIGSTOP: it cannot clean up, as a writer killed there cannot); the test's
# process group kill then ends it. Temporaries inside a directory output are let through.
STOP_AT_THE_MOVE = """import os, signal
_replace = os.replace
def _stop_before_the_move(src, dst, *args, **kwargs):
    beside = os.path.abspath(os.path.dirname(os.fspath(dst))) == {folder!r}
    if beside and {mark!r} in os.path.basename(os.fspath(src)):
        os.kill(os.getpid(), signal.SIGSTOP)
    return _replace(src, dst, *args, **kwargs)
os.replace = _stop_before_the_move
"""


def _command(project: Path, *args: str) -> list[str]:
    # --configfile takes every word after it: the targets come before
    return [sys.executable, "-m", "snakemake", "-s", str(REPO / "Snakefile"), "-d",
            str(project), *args, "--configfile", "config/test.yaml"]  # fmt: skip


def _temporaries(folder: Path) -> list[Path]:
    return [p for p in folder.rglob(".*") if MARK in p.name] if folder.exists() else []


def _beside_the_outputs(folder: Path) -> list[Path]:
    """The writers' temporaries in ``folder`` itself, beside its file outputs (those inside
    a directory output go with it: Snakemake removes an incomplete job's outputs)."""
    return [p for p in folder.glob(".*") if MARK in p.name] if folder.exists() else []


def _stopping_environment(hook: Path, folder: Path) -> dict[str, str]:
    """This process's environment with ``hook`` (a folder holding the sitecustomize that
    stops a writer before its move into ``folder``) first on PYTHONPATH, for Snakemake and
    its jobs."""
    hook.mkdir()
    text = STOP_AT_THE_MOVE.format(folder=str(folder.resolve()), mark=MARK)
    (hook / "sitecustomize.py").write_text(text)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(hook), env.get("PYTHONPATH")]))
    return env


def _kill_at_the_first_temporary(project: Path, hook: Path, timeout_s: float = 600) -> list[Path]:
    """Start the virtual experiment of PS with its writers stopped before their move, and
    kill Snakemake with its jobs (their process group) once a writer's temporary is on disk
    beside a file output; the temporaries left behind."""
    proc = subprocess.Popen(
        _command(project, TARGET, "--cores", "1"),
        cwd=project,
        env=_stopping_environment(hook, project / SPHERE),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    deadline = time.monotonic() + timeout_s
    try:
        while proc.poll() is None and time.monotonic() < deadline:
            if _beside_the_outputs(project / SPHERE):
                os.killpg(proc.pid, signal.SIGKILL)
                break
            time.sleep(0.01)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    return _beside_the_outputs(project / SPHERE)


def test_a_killed_run_reruns_to_the_same_bytes_and_leaves_nothing_behind(small_data, tmp_path):
    project = tmp_path / "project"
    shutil.copytree(REPO / "config", project / "config")
    left = _kill_at_the_first_temporary(project, tmp_path / "hook")
    assert left, "the run finished before any writer's temporary was seen"
    assert not (project / TARGET).exists()
    unlock = subprocess.run(_command(project, "--unlock"), cwd=project, capture_output=True)
    assert unlock.returncode == 0, unlock.stderr[-2000:]
    rerun = subprocess.run(
        _command(project, TARGET, "--cores", "1"), cwd=project, capture_output=True, text=True,
        timeout=900,
    )  # fmt: skip
    assert rerun.returncode == 0, rerun.stderr[-3000:]
    assert _temporaries(project) == []
    uninterrupted = small_data / SPHERE
    made = sorted(p.relative_to(project / SPHERE) for p in (project / SPHERE).rglob("*"))
    assert made == sorted(p.relative_to(uninterrupted) for p in uninterrupted.rglob("*"))
    differ = [
        str(name)
        for name in made
        if (project / SPHERE / name).is_file()
        and (project / SPHERE / name).read_bytes() != (uninterrupted / name).read_bytes()
    ]
    assert differ == []
