"""The virtual instruments write files the analysis reads back unchanged (raw-data layout)."""

import numpy as np
import pytest

from amontons.io.tiff import read_image, write_image
from amontons.measure.lifetime import lifetime_statistics
from amontons.measure.newton_rings import newton_ring_gap
from amontons.measure.psf import measure_psf
from amontons.physics import hertz
from amontons.physics.emission import confined_emission
from amontons.physics.hertz import exterior_gap
from amontons.virtual.bead import render_bead
from amontons.virtual.flim import render_flim
from amontons.virtual.reflection import radial_gap_map, render_reflection

PIXEL = 200e-9


def test_bead_tif_round_trip(tmp_path):
    # Same numbers as tests/measure/test_psf.py: FWHM within 3 % after the file.
    image = render_bead((41, 41), PIXEL, 450e-9, (4e-6, 4e-6), 1000, 50, np.random.default_rng(0))
    write_image(tmp_path / "bead.tif", image, PIXEL)
    read = read_image(tmp_path / "bead.tif")
    assert read.data.dtype == np.uint16
    assert read.pixel_m == pytest.approx(PIXEL, rel=1e-6)
    assert measure_psf(read.data, read.pixel_m).fwhm_m == pytest.approx(450e-9, rel=0.03)


def test_reflection_tif_round_trip(tmp_path):
    radius, e_star, load = 2e-3, 32.8e9, 0.1
    a = hertz.contact_radius(load, radius, e_star)
    centre = (299.0, 299.0)
    gap = radial_gap_map((600, 600), PIXEL, centre, lambda r: exterior_gap(r, load, radius, e_star))
    image = render_reflection(gap, PIXEL, rng=np.random.default_rng(1))
    np.testing.assert_array_equal(
        image, render_reflection(gap, PIXEL, rng=np.random.default_rng(1))
    )
    write_image(tmp_path / "reflection.tif", image, PIXEL)
    read = read_image(tmp_path / "reflection.tif")
    assert read.data.dtype == np.uint16
    # Tolerance as in tests/measure/test_newton_rings.py: 2 nm around the true 0.
    result = newton_ring_gap(read.data, read.pixel_m, centre, a)
    assert result.edge_gap_mean_m == pytest.approx(0.0, abs=2e-9)


def test_reflection_refuses_to_saturate():
    # A bright ring (gap 84.3 nm) at 50 000 mean counts and contrast 0.6 expects 80 000.
    bright = np.full((10, 10), 84.3e-9)
    with pytest.raises(ValueError, match="saturate uint16"):
        render_reflection(bright, PIXEL, background=50_000, rng=np.random.default_rng(2))


def test_flim_tif_round_trip(tmp_path):
    rows, cols = np.indices((64, 64))
    mask = np.hypot(rows - 32, cols - 32) < 20
    arrival = render_flim(mask, rng=np.random.default_rng(3))
    write_image(tmp_path / "flim.tif", arrival, PIXEL)
    read = read_image(tmp_path / "flim.tif")
    assert read.data.dtype == np.float32
    # 1256 contact pixels with 0.1 ns noise: standard error 0.003 ns, so 0.01 ns is > 3 σ.
    assert lifetime_statistics(read.data, mask).inside_mean_ns == pytest.approx(1.3, abs=0.01)


def test_confined_emission_is_root_pressure_above_the_floor_and_dark_outside():
    """√max(p, p_c) in contact (√Pa), 0 outside; p_c = 0 is the bare √p law."""
    pressure = np.array([0.0, 1e6, 100e6, 0.0])
    contact = np.array([True, True, True, False])
    bare = confined_emission(pressure, contact, 0.0)
    np.testing.assert_allclose(bare, [0.0, 1e3, 1e4, 0.0])
    floored = confined_emission(pressure, contact, 25e6)
    np.testing.assert_allclose(floored, [5e3, 5e3, 1e4, 0.0])
    with pytest.raises(ValueError, match="negative"):
        confined_emission(pressure, contact, -1.0)
