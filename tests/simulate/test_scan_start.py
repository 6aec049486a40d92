"""A scan value's pressures as its neighbour's start (amontons.simulate.scan_start): what is
written is read back to the bit, matched load by load and on the grid; whatever does not
match starts as it would without a neighbour (None), and a value that solved nothing leaves a
file with no load."""

import numpy as np

from amontons.simulate.scan_start import read_scan_start, write_scan_start

LOADS_N = [5e-3, 10e-3, 20e-3]
PIXEL_M = 128e-9


def _pressures(shape=(16, 16)):
    rng = np.random.default_rng(3)
    return [rng.random(shape) * 1e8 for _ in LOADS_N]


def test_the_pressures_come_back_to_the_bit(tmp_path):
    path = tmp_path / "start.h5"
    pressures = _pressures()
    write_scan_start(path, LOADS_N, pressures, PIXEL_M, 120.0)
    starts, started = read_scan_start(path, LOADS_N, (16, 16), PIXEL_M)
    assert started == 3
    for got, want in zip(starts, pressures, strict=True):
        assert got.dtype == np.float64
        np.testing.assert_array_equal(got, want)


def test_loads_the_neighbour_did_not_solve_start_without_it(tmp_path):
    path = tmp_path / "start.h5"
    pressures = _pressures()
    write_scan_start(path, LOADS_N[:2], pressures[:2], PIXEL_M, 120.0)
    starts, started = read_scan_start(path, [2.5e-3, *LOADS_N], (16, 16), PIXEL_M)
    assert started == 2
    assert starts[0] is None and starts[3] is None
    np.testing.assert_array_equal(starts[2], pressures[1])


def test_another_grid_starts_nothing(tmp_path):
    path = tmp_path / "start.h5"
    write_scan_start(path, LOADS_N, _pressures(), PIXEL_M, 120.0)
    assert read_scan_start(path, LOADS_N, (16, 16), 2 * PIXEL_M) == ([None] * 3, 0)
    assert read_scan_start(path, LOADS_N, (32, 32), PIXEL_M) == ([None] * 3, 0)


def test_a_value_that_solved_nothing_leaves_an_empty_start(tmp_path):
    path = tmp_path / "start.h5"
    write_scan_start(path, [], [], None, 120.0)
    assert read_scan_start(path, LOADS_N, (16, 16), PIXEL_M) == ([None] * 3, 0)
