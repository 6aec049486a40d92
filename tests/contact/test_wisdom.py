"""FFTW wisdom on disk (amontons.contact.wisdom): measured plans shared by the processes of a
machine, so that the default FFTW_MEASURE gives the same bytes in every run."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from amontons.contact.fft import HAVE_PYFFTW, empty, fftw_plan
from amontons.contact.wisdom import WISDOM_ENV, WisdomFileError, machine_key, wisdom_path

pytestmark = pytest.mark.skipif(not HAVE_PYFFTW, reason="pyfftw not installed")

CHILD = """
import hashlib
from amontons.contact import self_affine, solve
rough = self_affine(({n}, {n}), 1.0, 0.8, rms_slope=0.1, rng=3)
res = solve(rough, 1.0, 1.0, load=0.005 * {n}**2, periodic=True, threads={threads})
print(hashlib.sha256(res.pressure.tobytes()).hexdigest())
"""


def _start(wisdom, threads=1, n=96):
    env = dict(os.environ, **{WISDOM_ENV: str(wisdom)})
    return subprocess.Popen(
        [sys.executable, "-c", CHILD.format(threads=threads, n=n)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )


def _digest(proc):
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    return out.strip()


def _plan_new_shape(shape):
    """Build one measured r2c plan of ``shape`` (a shape no other test plans)."""
    src = empty(shape, np.float64, "pyfftw")
    dst = empty((shape[0], shape[1] // 2 + 1), np.complex128, "pyfftw")
    return fftw_plan(src, dst, (0, 1), planner_effort="FFTW_MEASURE")


def test_processes_started_together_share_one_plan(tmp_path):
    """Two processes planning at the same time wait for each other (file lock): the second
    to get the lock imports the first's choice, so both give the same bytes, on one thread
    and on two (at 96² both run one whole-array plan: the next test has slabs), and the
    file is valid wisdom afterwards (written in one rename)."""
    wisdom = tmp_path / "wisdom.json"
    for threads in (1, 2):
        procs = [_start(wisdom, threads) for _ in range(2)]
        first, second = (_digest(p) for p in procs)
        assert first == second
    strings = json.loads(wisdom.read_text())
    assert len(strings) == 3 and strings[0].startswith("(fftw-3")
    assert not list(tmp_path.glob("*.tmp"))


def test_processes_started_together_share_their_slab_plans(tmp_path):
    """The same on two threads at 256², whose transforms run as slabs of one-thread plans
    (amontons.contact.fft.SlabTransform), each slab shape planned and shared: both
    processes give the same bytes."""
    wisdom = tmp_path / "wisdom.json"
    procs = [_start(wisdom, threads=2, n=256) for _ in range(2)]
    first, second = (_digest(p) for p in procs)
    assert first == second
    assert json.loads(wisdom.read_text())[0].startswith("(fftw-3")


def test_a_temporary_a_killed_writer_left_is_removed_by_the_next_write(tmp_path, monkeypatch):
    """The wisdom is written under its lock: a temporary found then is a killed writer's."""
    wisdom = tmp_path / "wisdom.json"
    stale = tmp_path / "wisdom.jsonx8k2_q.tmp"
    stale.write_text('["(fftw-3.3.10 fftw_wisdom')  # cut short
    monkeypatch.setenv(WISDOM_ENV, str(wisdom))
    _plan_new_shape((10, 26))
    assert json.loads(wisdom.read_text())[0].startswith("(fftw-3")
    assert not stale.exists()


def test_a_corrupt_wisdom_file_is_an_error_naming_it(tmp_path, monkeypatch):
    bad = tmp_path / "wisdom.json"
    bad.write_text("this is not wisdom")
    monkeypatch.setenv(WISDOM_ENV, str(bad))
    with pytest.raises(WisdomFileError, match=rf"{bad}.*delete it"):
        _plan_new_shape((10, 14))
    bad.write_text(json.dumps(["(not fftw wisdom)", "", ""]))
    with pytest.raises(WisdomFileError, match=rf"FFTW rejected .* in {bad}"):
        _plan_new_shape((10, 14))


def test_an_empty_variable_keeps_wisdom_in_the_process(tmp_path, monkeypatch):
    monkeypatch.setenv(WISDOM_ENV, "")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert wisdom_path() is None
    _plan_new_shape((10, 18))
    assert not list(tmp_path.rglob("*"))


def test_the_default_file_is_per_machine_in_the_user_cache(tmp_path, monkeypatch):
    monkeypatch.delenv(WISDOM_ENV, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    path = wisdom_path()
    assert path == tmp_path / "amontons" / f"fftw-wisdom-{machine_key()}.json"
    _plan_new_shape((10, 22))
    assert json.loads(path.read_text())[0].startswith("(fftw-3")


def test_an_unwritable_place_warns_and_still_plans(monkeypatch):
    """A cache that cannot be written must not stop a solve: plans are then per process,
    and the warning says what that costs and how to choose another file."""
    monkeypatch.setenv(WISDOM_ENV, "/proc/amontons/wisdom.json")
    with pytest.warns(RuntimeWarning, match="cannot keep FFTW wisdom in /proc/amontons"):
        plan = _plan_new_shape((10, 26))
    plan.input_array[...] = 1.0
    plan()
    assert plan.output_array[0, 0] == pytest.approx(10 * 26)
