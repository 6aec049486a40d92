"""A scan value's pressures as its neighbour's start (amontons.simulate.scan_start): handed on
unchanged to the bit, matched load by load and on the window; whatever does not match starts
as it would without a neighbour (None), and so does every load after a value that solved
nothing. The chain's first value starts from the elastic scene's fields file, read back to
the bit."""

import numpy as np
import pytest

from amontons.io.fields import write_load_series
from amontons.simulate.scan_start import ScanStart

LOADS_N = [5e-3, 10e-3, 20e-3]
PIXEL_M = 128e-9
CENTRE_M = (-9.5e-6, 4.25e-6)


def _pressures(shape=(16, 16)):
    rng = np.random.default_rng(3)
    return [rng.random(shape) * 1e8 for _ in LOADS_N]


def _start(loads=LOADS_N, pressures=None):
    pressures = _pressures() if pressures is None else pressures
    return ScanStart.of(loads, pressures, PIXEL_M, CENTRE_M)


def test_the_pressures_are_handed_on_to_the_bit():
    pressures = _pressures()
    starts, started = _start(pressures=pressures).starts_for(LOADS_N, (16, 16), PIXEL_M, CENTRE_M)
    assert started == 3
    for got, want in zip(starts, pressures, strict=True):
        assert got.dtype == np.float64
        np.testing.assert_array_equal(got, want)


def test_loads_the_neighbour_did_not_solve_start_without_it():
    pressures = _pressures()
    start = _start(LOADS_N[:2], pressures[:2])
    starts, started = start.starts_for([2.5e-3, *LOADS_N], (16, 16), PIXEL_M, CENTRE_M)
    assert started == 2
    assert starts[0] is None and starts[3] is None
    np.testing.assert_array_equal(starts[2], pressures[1])


def test_another_window_starts_nothing():
    start = _start()
    nothing = ([None] * 3, 0)
    assert start.starts_for(LOADS_N, (16, 16), 2 * PIXEL_M, CENTRE_M) == nothing
    assert start.starts_for(LOADS_N, (32, 32), PIXEL_M, CENTRE_M) == nothing
    # a window shifted by one pixel holds other points at the same indices
    shifted = (CENTRE_M[0] + PIXEL_M, CENTRE_M[1])
    assert start.starts_for(LOADS_N, (16, 16), PIXEL_M, shifted) == nothing


def test_a_value_that_solved_nothing_starts_nothing():
    assert ScanStart().starts_for(LOADS_N, (16, 16), PIXEL_M, CENTRE_M) == ([None] * 3, 0)


def test_a_start_without_one_pressure_per_load_is_refused():
    with pytest.raises(ValueError, match="3 loads, 2 pressures"):
        ScanStart.of(LOADS_N, _pressures()[:2], PIXEL_M, CENTRE_M)


def test_the_elastic_scene_fields_start_the_same_window_and_loads(tmp_path):
    """Stored through mN, nm and µm (as rule simulate_scene writes them), loads, pixel and
    centre move in their last bits; the start still matches them, and the pressures come
    back to the bit."""
    pressures = _pressures()
    path = tmp_path / "fields.h5"
    write_load_series(
        path,
        [{"pressure": p, "gap": -p * 1e-17} for p in pressures],
        [{"load_mn": f * 1e3} for f in LOADS_N],
        {"pixel_nm": PIXEL_M * 1e9, "window_centre_in_scan_um": [c * 1e6 for c in CENTRE_M]},
    )
    start = ScanStart.from_scene_fields(str(path))
    starts, started = start.starts_for(LOADS_N, (16, 16), PIXEL_M, CENTRE_M)
    assert started == 3
    for got, want in zip(starts, pressures, strict=True):
        np.testing.assert_array_equal(got, want)


def test_a_scene_that_solved_no_load_starts_nothing(tmp_path):
    path = tmp_path / "fields.h5"
    write_load_series(path, [], [], {"status": "outside_scan", "loads_mn": []})
    assert ScanStart.from_scene_fields(str(path)).starts_for(
        LOADS_N, (16, 16), PIXEL_M, CENTRE_M
    ) == ([None] * 3, 0)
