"""The simulated flattening's window and region (Fig. B.9), and the mean-field map (B.11)."""

import numpy as np
import pytest

from amontons.simulate.flattening import flattened_region, offset_from_centre_m, window_slices
from amontons.simulate.render import area_fraction_map


def test_window_slices_cut_the_solver_window_about_its_centre():
    # a 100 px scan of 10 nm; a 400 nm window centred 200 nm below and 100 nm right of the
    # scan centre (49.5, 49.5): rows 49.5 + 20 ± 20, cols 49.5 + 10 ± 20 (rounded)
    rows, cols = window_slices((100, 100), 10e-9, (200e-9, 100e-9), 400e-9)
    assert (rows.start, rows.stop) == (50, 90)
    assert (cols.start, cols.stop) == (40, 80)
    # clipped where it would leave the scan
    rows, _ = window_slices((100, 100), 10e-9, (450e-9, 0.0), 400e-9)
    assert rows.stop == 100


def test_a_uniform_flattened_disc_has_its_depth_and_centre():
    """A disc pressed 5 nm deep off-centre: depth 5 nm exactly (the median over the pixels
    that went down by more than half of it), centre at the disc's centre within 0.5 px."""
    rows, cols = np.indices((64, 64))
    disc = np.hypot(rows - 40, cols - 20) < 10
    drop = np.where(disc, 5e-9, 0.0)
    depth, core, centre = flattened_region(drop, smoothing_px=2.0, floor_m=0.1e-9)
    assert depth == pytest.approx(5e-9, rel=1e-12)
    assert centre == pytest.approx((40, 20), abs=0.5)
    assert offset_from_centre_m(centre, (64, 64), 1e-6) == pytest.approx(
        (8.5e-6, -11.5e-6), abs=0.5e-6
    )


def test_no_drop_above_the_floor_is_no_flattening():
    depth, core, centre = flattened_region(np.full((32, 32), 0.05e-9), 2.0, floor_m=0.1e-9)
    assert depth is None and not core.any() and centre is None


def test_area_fraction_map_is_the_profile_about_the_centre_and_zero_beyond():
    r_um = np.array([0.5, 1.5, 2.5])
    phi = np.array([0.3, 0.2, 0.1])
    image = area_fraction_map(r_um, phi, (21, 21), (10, 10), 0.5e-6)
    assert image[10, 10] == pytest.approx(0.3)  # r = 0: the innermost value
    assert image[10, 13] == pytest.approx(0.2)  # r = 1.5 µm
    assert image[10, 20] == 0.0  # r = 5 µm, beyond the profile
