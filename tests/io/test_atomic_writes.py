"""Atomic writes (amontons.io.files.atomic_path): a file is complete or absent, and a writer
killed mid-write leaves nothing behind for good. Its temporary beside the output is removed
by the next write of that output on the same host once the killed process is gone; the
temporaries of a running writer, or of another host, are left alone."""

import signal
import socket
import subprocess
import sys

import numpy as np
import pytest

from amontons.io.fields import read_load_series, write_load_series
from amontons.io.files import atomic_path, read_json, remove_stale_temporaries, write_json

# A child that writes the solver fields file and is killed (SIGKILL, as a lost node or an
# out-of-memory kill does it) inside the HDF5 writer, after the first field is written.
KILLED_MID_WRITE = """
import os, signal, sys
import h5py
import numpy as np
from amontons.io.fields import write_load_series

create = h5py.Group.create_dataset
def create_then_die(self, name, **kwargs):
    dataset = create(self, name, **kwargs)
    self.file.flush()
    os.kill(os.getpid(), signal.SIGKILL)
    return dataset
h5py.Group.create_dataset = create_then_die
fields = [{"pressure": np.ones((64, 64)), "gap": np.zeros((64, 64))}]
write_load_series(sys.argv[1], fields, [{"load_mn": 25.0}], {"scene": "killed"})
"""


def _fields():
    return [{"pressure": np.full((8, 8), 2.0), "gap": np.zeros((8, 8))}], [{"load_mn": 25.0}]


def test_a_writer_killed_mid_write_leaves_a_temporary_the_next_write_removes(tmp_path):
    path = tmp_path / "fields.h5"
    child = subprocess.run(
        [sys.executable, "-c", KILLED_MID_WRITE, str(path)], capture_output=True, timeout=120
    )
    assert child.returncode == -signal.SIGKILL, child.stderr.decode()[-2000:]
    # no output, and the killed writer's half-written temporary beside it
    assert not path.exists()
    (left,) = tmp_path.glob(".fields.h5.*.h5")
    assert left.name.startswith(f".fields.h5.{socket.gethostname()}-") and left.stat().st_size > 0
    fields, per_load = _fields()
    write_load_series(path, fields, per_load, {"scene": "rerun"})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fields.h5"]
    read_fields, read_per_load, attrs = read_load_series(path)
    np.testing.assert_array_equal(read_fields[0]["pressure"], fields[0]["pressure"])
    assert attrs["scene"] == "rerun" and read_per_load[0]["load_mn"] == 25.0


def test_a_running_writers_temporary_and_another_hosts_are_left_alone(tmp_path):
    path = tmp_path / "solve.json"
    sleeper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        host = socket.gethostname()
        running = tmp_path / f".solve.json.{host}-{sleeper.pid}.abc123.json"
        other_host = tmp_path / f".solve.json.other-node-{sleeper.pid + 1}.abc123.json"
        unrelated = tmp_path / f".solve.json.{host}-notapid.json"
        for file in (running, other_host, unrelated):
            file.write_text("{")
        write_json(path, {"value": 1})
        assert read_json(path) == {"value": 1}
        assert running.exists() and other_host.exists() and unrelated.exists()
    finally:
        sleeper.kill()
        sleeper.wait()
    # the writer is gone now: its temporary is stale
    assert remove_stale_temporaries(path) == [running]
    assert not running.exists() and other_host.exists()


def test_a_failed_block_leaves_neither_output_nor_temporary(tmp_path):
    path = tmp_path / "table.csv"
    with pytest.raises(RuntimeError), atomic_path(path) as tmp:
        tmp.write_text("half")
        raise RuntimeError("the writer failed")
    assert list(tmp_path.iterdir()) == []
