"""The solver reproduces its golden record to the last bit (tests/contact/golden/record.py:
elastic periodic and padded solves, penetration hardness under load and displacement
control, contact hardening by the Winkler and the appendix's routes, volume-conserving
increments, load series and a scan; recorded on 26f01d4, before the rebuild of issue 38).

The cases are solved by record.py in a process of its own, without FFTW wisdom and with
FFTW_ESTIMATE plans, so that neither this process's plans nor a wisdom file on the machine
enter the bytes."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

RECORD = Path(__file__).with_name("golden") / "record.py"
STORED = RECORD.with_name("golden.npz")


def _stored() -> dict[str, np.ndarray]:
    with np.load(STORED) as data:
        return {key: data[key] for key in data.files}


def _case_names() -> list[str]:
    with np.load(STORED) as data:
        return sorted({key.split("/")[0] for key in data.files})


@pytest.fixture(scope="module")
def computed(tmp_path_factory) -> dict[str, np.ndarray]:
    out = tmp_path_factory.mktemp("golden") / "computed.npz"
    subprocess.run([sys.executable, str(RECORD), "--out", str(out)], check=True, timeout=900)
    with np.load(out) as data:
        return {key: data[key] for key in data.files}


def test_the_record_holds_every_case():
    """No case of record.py is missing from the record, and none is left over."""
    source = RECORD.read_text()
    assert all(f'"{name}":' in source for name in _case_names())
    assert source.count(": lambda: solve") == len(_case_names())


@pytest.mark.parametrize("name", _case_names())
def test_case_is_bit_identical(name, computed):
    expected = {k: v for k, v in _stored().items() if k.split("/")[0] == name}
    got = {k: v for k, v in computed.items() if k.split("/")[0] == name}
    assert sorted(got) == sorted(expected)
    differ = [k for k in got if not np.array_equal(got[k], expected[k])]
    assert not differ, f"differ from the record: {differ}"
