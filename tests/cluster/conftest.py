"""The one-node SLURM of tests/cluster/start_slurm.sh, started once for the cluster tests and
stopped after them. Only ``make test-cluster`` (pytest --cluster) collects this folder:
installing and starting system services is not something ``make test`` may do."""

import subprocess
from pathlib import Path

import pytest

START = Path(__file__).with_name("start_slurm.sh")


@pytest.fixture(scope="session")
def slurm():
    """A running SLURM with accounting; a cluster that cannot start fails the tests (it never
    skips them), with the script's reason."""
    started = subprocess.run([str(START), "start"], capture_output=True, text=True, timeout=600)
    if started.returncode != 0:
        subprocess.run([str(START), "stop"], capture_output=True, timeout=120)
        pytest.fail(f"the one-node SLURM did not start:\n{started.stderr[-3000:]}")
    yield started.stderr.strip().splitlines()[-1]
    subprocess.run([str(START), "stop"], capture_output=True, timeout=120)
