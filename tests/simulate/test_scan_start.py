"""A scan value's pressures as its neighbour's start (amontons.simulate.scan_start): handed on
unchanged to the bit, matched load by load and on the grid; whatever does not match starts as
it would without a neighbour (None), and so does every load after a value that solved
nothing."""

import numpy as np
import pytest

from amontons.simulate.scan_start import ScanStart

LOADS_N = [5e-3, 10e-3, 20e-3]
PIXEL_M = 128e-9


def _pressures(shape=(16, 16)):
    rng = np.random.default_rng(3)
    return [rng.random(shape) * 1e8 for _ in LOADS_N]


def test_the_pressures_are_handed_on_to_the_bit():
    pressures = _pressures()
    starts, started = ScanStart.of(LOADS_N, pressures, PIXEL_M).starts_for(
        LOADS_N, (16, 16), PIXEL_M
    )
    assert started == 3
    for got, want in zip(starts, pressures, strict=True):
        assert got.dtype == np.float64
        np.testing.assert_array_equal(got, want)


def test_loads_the_neighbour_did_not_solve_start_without_it():
    pressures = _pressures()
    start = ScanStart.of(LOADS_N[:2], pressures[:2], PIXEL_M)
    starts, started = start.starts_for([2.5e-3, *LOADS_N], (16, 16), PIXEL_M)
    assert started == 2
    assert starts[0] is None and starts[3] is None
    np.testing.assert_array_equal(starts[2], pressures[1])


def test_another_grid_starts_nothing():
    start = ScanStart.of(LOADS_N, _pressures(), PIXEL_M)
    assert start.starts_for(LOADS_N, (16, 16), 2 * PIXEL_M) == ([None] * 3, 0)
    assert start.starts_for(LOADS_N, (32, 32), PIXEL_M) == ([None] * 3, 0)


def test_a_value_that_solved_nothing_starts_nothing():
    assert ScanStart().starts_for(LOADS_N, (16, 16), PIXEL_M) == ([None] * 3, 0)


def test_a_start_without_one_pressure_per_load_is_refused():
    with pytest.raises(ValueError, match="3 loads, 2 pressures"):
        ScanStart.of(LOADS_N, _pressures()[:2], PIXEL_M)
