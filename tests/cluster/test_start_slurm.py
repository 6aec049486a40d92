"""tests/cluster/start_slurm.sh where it cannot set up a cluster: it stops at once and says
why, rather than letting the cluster tests skip."""

import shutil
import subprocess
import tempfile
from pathlib import Path

import pytest

START = Path(__file__).with_name("start_slurm.sh")


@pytest.fixture
def script_for_anyone():
    """A copy of the script that any user can read and run: the checkout, like pytest's
    temporary folders, may be readable by its owner only."""
    folder = Path(tempfile.mkdtemp(prefix="amontons-start-slurm-"))
    folder.chmod(0o755)
    copy = folder / START.name
    shutil.copy(START, copy)
    copy.chmod(0o755)
    yield copy
    shutil.rmtree(folder)


@pytest.mark.skipif(shutil.which("su") is None, reason="no su to run the script as nobody")
def test_without_root_it_stops_at_once_and_says_why(script_for_anyone):
    """As the unprivileged user nobody: exit 2 within seconds, naming what it needs, before
    it writes anything (its state folder, which nobody could not create, stays absent)."""
    folder = script_for_anyone.parent / "state"
    command = f"AMONTONS_SLURM_DIR={folder} {script_for_anyone} preflight"
    result = subprocess.run(
        ["su", "nobody", "-s", "/bin/bash", "-c", command],
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert result.returncode == 2, result.stderr
    assert "needs root" in result.stderr and "slurmctld" in result.stderr
    assert not folder.exists()
