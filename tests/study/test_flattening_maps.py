"""Fig. B.9's pieces (amontons.study.flattening_maps) on small arrays, in-process: the
model's surface with its sphere taken off, and a flattened region's table row."""

import numpy as np
import pytest

from amontons.contact.surfaces import sphere as sphere_cap
from amontons.study.flattening_maps import Flattening, simulated_surface

PIXEL_M = 50e-9
RADIUS_M = 1e-3


def test_the_sphere_and_the_median_come_off_the_models_surface():
    """A deformed surface that is the sphere plus a 4 nm flat in a 10 × 10 square and 1 nm
    elsewhere leaves the flat's 3 nm step about a zero median (to round-off of the sphere's
    heights, ~1e-6 m at the edge: 1e-15 m)."""
    shape = (40, 40)
    heights = sphere_cap(shape, PIXEL_M, RADIUS_M) + 1e-9
    heights[15:25, 15:25] += 3e-9
    surface = simulated_surface({"deformed_heights": heights}, PIXEL_M, RADIUS_M)
    assert np.median(surface) == pytest.approx(0.0, abs=1e-15)
    assert surface[20, 20] == pytest.approx(3e-9, abs=1e-15)
    assert surface[0, 0] == pytest.approx(0.0, abs=1e-15)


def test_a_flattened_regions_row_states_its_depth_area_and_centre():
    core = np.zeros((21, 21), bool)
    core[12:15, 4:8] = True  # 12 pixels
    row = Flattening(5e-9, core, (13.0, 5.5), PIXEL_M).describe("measured")
    assert row["flattening_depth_nm"] == pytest.approx(5.0, rel=1e-12)
    assert row["flattened_area_um2"] == pytest.approx(12 * (PIXEL_M * 1e6) ** 2, rel=1e-12)
    # the centre 3 rows below and 4.5 columns left of the grid's centre (10, 10)
    assert row["centre_row_um"] == pytest.approx(3 * PIXEL_M * 1e6, rel=1e-12)
    assert row["centre_col_um"] == pytest.approx(-4.5 * PIXEL_M * 1e6, rel=1e-12)


def test_no_flattening_is_a_row_of_none_not_of_zeros():
    row = Flattening(None, np.zeros((5, 5), bool), None, PIXEL_M).describe("model")
    assert row["flattening_depth_nm"] is None and row["centre_row_um"] is None
    assert row["flattened_area_um2"] == 0.0
