"""tests/cluster/start_slurm.sh where it cannot set up a cluster: it stops at once and says
why, rather than letting the cluster tests skip."""

import shutil
import subprocess
from pathlib import Path

import pytest

START = Path(__file__).with_name("start_slurm.sh")


@pytest.mark.skipif(shutil.which("su") is None, reason="no su to run the script as nobody")
def test_without_root_it_stops_at_once_and_says_why(tmp_path):
    """As the unprivileged user nobody: exit 2 within seconds, naming what it needs, before
    it writes anything (its state folder, which nobody could not create, stays absent)."""
    folder = tmp_path / "state"
    command = f"AMONTONS_SLURM_DIR={folder} {START} preflight"
    result = subprocess.run(
        ["su", "nobody", "-s", "/bin/bash", "-c", command],
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert result.returncode == 2, result.stderr
    assert "needs root" in result.stderr and "slurmctld" in result.stderr
    assert not folder.exists()
