"""The solver reproduces its golden record to the last bit (tests/contact/golden/record.py:
elastic periodic and padded solves, penetration hardness under load and displacement
control, contact hardening by the Winkler and the appendix's routes, volume-conserving
increments, load series and a scan; recorded on 26f01d4, before the rebuild of issue 38)."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

_SPEC = importlib.util.spec_from_file_location(
    "golden_record", Path(__file__).with_name("golden") / "record.py"
)
record = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(record)


@pytest.fixture(scope="module")
def stored():
    with np.load(record.PATH) as data:
        return {key: data[key] for key in data.files}


@pytest.mark.parametrize("name", list(record.cases()))
def test_case_is_bit_identical(name, stored):
    got = record.compute([name])
    expected = {k: v for k, v in stored.items() if k.split("/")[0] == name}
    assert expected, f"{name} is not in the record: re-record it"
    assert sorted(got) == sorted(expected)
    differ = [k for k in got if not np.array_equal(got[k], expected[k])]
    assert not differ, f"differ from the record: {differ}"
