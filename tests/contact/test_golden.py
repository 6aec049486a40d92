"""The solver reproduces its golden record (tests/contact/golden/record.py: elastic periodic
and padded solves, penetration hardness under load and displacement control, contact
hardening by the Winkler and the appendix's routes, volume-conserving increments, load series
and a scan; the solves of 26f01d4, before the rebuild of issue 38, with the bounded ones
re-made when the bounded reset rule changed on 2026-11-28).

On any machine, each case holds the record to its route's tolerances (golden/compare.py says
each bound and why): the same contact set, fields within a stated fraction of their peak,
iterations within a stated count, a converged residual. It is held to two records: the one
made on the machine named in golden.machine.json, and one made on another kind of machine
(earlier-machine.npz, the developers' machine until 2026-11-26), whose round-off differs from
the first in every case, so that the tolerances are tried against a real other CPU on every
run; the six cases the bounded reset rule changed on 2026-11-28 are not in the earlier
record yet (compare.NOT_ON_THE_EARLIER_MACHINE says why), and their test against it skips
saying so. On a machine of the record's kind (same CPU features and library versions), the
record must also hold to the last bit.

The cases are solved by record.py in a process of its own, without FFTW wisdom and with
FFTW_ESTIMATE plans, so that neither this process's plans nor a wisdom file on the machine
enter the bytes. The same-machine check of a rebuild is same_bits.py (``make golden-bits``).
"""

import functools
import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

GOLDEN = Path(__file__).with_name("golden")
RECORD = GOLDEN / "record.py"
STORED = GOLDEN / "golden.npz"
EARLIER = GOLDEN / "earlier-machine.npz"


def _load_compare():
    """tests/contact/golden/compare.py (tests import helpers by file)."""
    spec = importlib.util.spec_from_file_location("golden_compare", GOLDEN / "compare.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclass looks its module up there
    spec.loader.exec_module(module)
    return module


compare = _load_compare()


@functools.cache
def _record(path: Path) -> dict[str, np.ndarray]:
    """Every array of a record, read once per process (the tests ask for it per case)."""
    with np.load(path) as data:
        return {k: data[k] for k in data.files}


def _arrays(path: Path, name: str | None = None) -> dict[str, np.ndarray]:
    """The arrays of a record (of one case, if ``name`` is given)."""
    return {k: v for k, v in _record(path).items() if name is None or k.split("/")[0] == name}


def _case_names() -> list[str]:
    return sorted({key.split("/")[0] for key in _record(STORED)})


@pytest.fixture(scope="module")
def computed(tmp_path_factory) -> dict[str, np.ndarray]:
    out = tmp_path_factory.mktemp("golden") / "computed.npz"
    subprocess.run([sys.executable, str(RECORD), "--out", str(out)], check=True, timeout=900)
    return _arrays(out)


def test_the_record_holds_every_case_with_a_route():
    """No case of record.py is missing from either record or from the route table, and none
    is left over."""
    source = RECORD.read_text()
    names = _case_names()
    assert all(f'"{name}":' in source for name in names)
    assert source.count(": lambda: solve") == len(names)
    assert sorted(compare.CASE_ROUTES) == names
    assert set(compare.CASE_ROUTES.values()) <= set(compare.ROUTES)
    not_earlier = set(compare.NOT_ON_THE_EARLIER_MACHINE)
    assert not_earlier <= set(names)
    earlier_cases = {key.split("/")[0] for key in _arrays(EARLIER)}
    assert earlier_cases == set(names) - not_earlier
    assert sorted(_arrays(EARLIER)) == sorted(
        key for key in _arrays(STORED) if key.split("/")[0] in earlier_cases
    )


@pytest.mark.parametrize("record", [STORED, EARLIER], ids=["record", "earlier_machine"])
@pytest.mark.parametrize("name", _case_names())
def test_case_holds_the_record_on_any_machine(name, record, computed):
    if record == EARLIER and name in compare.NOT_ON_THE_EARLIER_MACHINE:
        pytest.skip(
            f"{name}: changed by the bounded reset rule of 2026-11-28, not yet recorded on "
            "another kind of machine (compare.NOT_ON_THE_EARLIER_MACHINE)"
        )
    got = {k: v for k, v in computed.items() if k.split("/")[0] == name}
    failures = compare.cross_machine_failures(got, _arrays(record, name), compare.CASE_ROUTES[name])
    assert not failures, failures


def _machine_differences() -> list[str]:
    recorded = json.loads(STORED.with_suffix(".machine.json").read_text())
    return compare.machine_differences(recorded, compare.machine())


@pytest.mark.parametrize("name", _case_names())
def test_case_is_bit_identical_on_the_records_machine(name, computed):
    """Where the machine is of the record's kind, nothing may change a bit: any difference is
    a change of the code, not of the CPU."""
    differences = _machine_differences()
    if differences:
        pytest.skip(f"not the record's kind of machine ({'; '.join(differences)})")
    got = {k: v for k, v in computed.items() if k.split("/")[0] == name}
    differ = compare.exact_failures(got, _arrays(STORED, name))
    assert not differ, f"differ from the record: {differ}"


def _planted(arrays: dict[str, np.ndarray], key: str, change) -> dict[str, np.ndarray]:
    return {k: (change(v) if k == key else v) for k, v in arrays.items()}


def test_the_comparisons_tell_round_off_from_a_change():
    """One ulp on one pressure passes the cross-machine comparison and fails the exact one; a
    wrong sign on a pressure, an extra contact pixel, a residual above the tolerance and
    iterations beyond the slack fail both."""
    name = "hardness_bounded_load"
    want = _arrays(STORED, name)
    key = f"{name}/0/pressure"
    route = compare.CASE_ROUTES[name]

    def one_ulp(p):
        p = p.copy()
        i = np.unravel_index(np.argmax(p), p.shape)
        p[i] = np.nextafter(p[i], np.inf)
        return p

    ulp = _planted(want, key, one_ulp)
    assert compare.cross_machine_failures(ulp, want, route) == []
    assert compare.exact_failures(ulp, want) == [key]

    def negated(p):
        return -p

    def one_more_pixel(p):
        p = p.copy()
        p[0, 0] = 1e-3 * p.max()
        return p

    wrong = [
        _planted(want, key, negated),
        _planted(want, key, one_more_pixel),
        _planted(want, f"{name}/0/residual", lambda r: np.asarray(2 * compare.SOLVE_TOL)),
        _planted(want, f"{name}/0/iterations", lambda n: n + 2),
    ]
    for arrays in wrong:
        assert compare.cross_machine_failures(arrays, want, route)
        assert compare.exact_failures(arrays, want)
