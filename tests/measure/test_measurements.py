"""Measurements from raw files, and the per-sphere and per-material tables built from them."""

import numpy as np
import pandas as pd
import pytest

from amontons.io.layout import RawDataError, fluorescence_images
from amontons.io.tiff import saturated_pixels, write_image
from amontons.measure.area import OtsuSettings, contact_geometry
from amontons.measure.errors import NoContact
from amontons.measure.friction import amontons_table
from amontons.measure.hertz_check import hertz_check_table
from amontons.measure.intensity import background_level, measure_intensity_pressure
from amontons.measure.lifetime import measure_lifetime

LOADS_MN = [25.0, 50.0, 100.0, 200.0]


def _tables(tau_mpa=20.0, alpha=2 / 3, found=(True, True, True, True)):
    """Area ∝ F^alpha and F_s = τ·A exactly, as contact_area.csv and friction.csv hold them."""
    loads = np.array(LOADS_MN)
    area_um2 = 400.0 * (loads / 25.0) ** alpha
    areas = pd.DataFrame({"load_mn": loads, "area_um2": area_um2, "contact_found": list(found)})
    friction = pd.DataFrame(
        {
            "load_mn": loads,
            "normal_force_mn": loads * 1.001,  # the rheometer's measured force, 0.1 % off
            "static_friction_mn": tau_mpa * area_um2 * 1e-3,  # MPa·µm² = 1e-6 N = 1e-3 mN
        }
    )
    return areas, friction


def test_amontons_table_normalises_at_the_reference_load():
    areas, friction = _tables()
    table = amontons_table(["A"], [areas], [friction], 25.0)
    # F_s = τ·A exactly, so both normalised columns agree to round-off and equal (F/25)^(2/3).
    np.testing.assert_allclose(table["friction_over_friction_ref"], table["area_over_area_ref"])
    np.testing.assert_allclose(table["area_over_area_ref"], (np.array(LOADS_MN) / 25) ** (2 / 3))
    np.testing.assert_allclose(table["shear_strength_mpa"], 20.0)
    # μ/μ_ref = (F/25)^(−1/3) · (1.001/1.001): the deviation from Amontons' law.
    np.testing.assert_allclose(table["mu_over_mu_ref"], (np.array(LOADS_MN) / 25) ** (-1 / 3))


def test_amontons_table_leaves_out_ill_determined_areas_and_keeps_spheres_apart():
    areas, friction = _tables(found=(True, True, False, True))
    other_areas, other_friction = _tables(tau_mpa=5.0, alpha=0.9)
    table = amontons_table(["A", "B"], [areas, other_areas], [friction, other_friction], 25.0)
    assert table.loc[table["sphere"] == "A", "load_mn"].tolist() == [25.0, 50.0, 200.0]
    assert len(table[table["sphere"] == "B"]) == 4


def test_amontons_table_needs_the_reference_load():
    areas, friction = _tables(found=(False, True, True, True))
    with pytest.raises(ValueError, match="no load within 10% of the reference 0.025 N"):
        amontons_table(["A"], [areas], [friction], 25.0)


def test_hertz_check_table_units():
    # Areas of the Hertz radius itself: ratio 1 to round-off; 4 mm glass at 25 mN, a = 10.456 µm.
    radius, e_star = 2e-3, 32.8e9
    a = np.array([(3 * f * 1e-3 * radius / (4 * e_star)) ** (1 / 3) for f in LOADS_MN])
    areas = pd.DataFrame(
        {"load_mn": LOADS_MN, "area_um2": np.pi * a**2 * 1e12, "contact_found": True}
    )
    table = hertz_check_table(areas, radius, e_star)
    np.testing.assert_allclose(table["radius_ratio"], 1.0, rtol=1e-12)
    assert table["hertz_radius_um"].iloc[0] == pytest.approx(10.456, abs=0.001)


def test_contact_geometry_of_a_disc():
    # A disc of radius 20 px centred at (40.0, 50.0): centroid exact by symmetry, equal-area
    # radius within 1 % of 20 px (pixelation).
    rows, cols = np.indices((100, 100))
    mask = np.hypot(rows - 40, cols - 50) <= 20
    centre, radius = contact_geometry(mask, 200e-9)
    assert centre == pytest.approx((40.0, 50.0), abs=1e-9)
    assert radius == pytest.approx(20 * 200e-9, rel=0.01)
    with pytest.raises(ValueError, match="contact mask is empty"):
        contact_geometry(np.zeros((4, 4), bool), 200e-9)


def test_background_level_ignores_the_contact_and_its_halo():
    rows, cols = np.indices((100, 100))
    mask = np.hypot(rows - 50, cols - 50) <= 20
    image = np.full((100, 100), 120.0)
    image[mask] = 1500.0
    image[np.hypot(rows - 50, cols - 50) <= 23] += 300.0  # PSF halo just outside the mask
    assert background_level(image, mask, margin_px=5) == 120.0
    with pytest.raises(ValueError, match="expected a background region"):
        background_level(image, np.ones((100, 100), bool), margin_px=5)


def test_saturated_image_is_refused_for_intensity_and_counted(tmp_path):
    # A contact whose brightest pixels hit the 16-bit ceiling: its mean intensity would be too
    # low, so the intensity-pressure measurement names the file and the count.
    rows, cols = np.indices((96, 96))
    contact = np.hypot(rows - 48, cols - 48) < 15
    folder = tmp_path / "fluorescence"
    for load, level in ((25, 1500), (50, 65535)):
        image = np.where(contact, level, 120).astype(np.uint16)
        write_image(folder / f"{load}.tif", image, 200e-9)
        assert saturated_pixels(image) == (contact.sum() if level == 65535 else 0)
    with pytest.raises(RawDataError, match=r"50\.tif: 697 saturated pixels"):
        measure_intensity_pressure(
            fluorescence_images(folder, [25, 50]),
            [25, 50],
            None,
            otsu=OtsuSettings(),
            background_margin_px=5,
            pressure_ref_pa=1e8,
        )


def _disc_images(folder, radii_px, rng):
    """One 16-bit image per load: a disc of 1500 counts (radius in px; 0 = no contact) on a
    Poisson background of 120 counts, 200 nm pixels."""
    rows, cols = np.indices((128, 128))
    for load, radius in radii_px.items():
        expected = np.where(np.hypot(rows - 64, cols - 64) < radius, 1500.0, 120.0)
        write_image(folder / f"{load:g}.tif", rng.poisson(expected).astype(np.uint16), 200e-9)


def test_image_without_contact_is_left_out_of_the_intensity_fit(tmp_path):
    """An image with no contact has no contact intensity: its load is left out with the
    reason (Otsu separation ≈ 2/π of pure noise) and the fit runs on the others."""
    folder = tmp_path / "fluorescence"
    _disc_images(folder, {25.0: 10, 50.0: 0, 100.0: 14, 200.0: 18}, np.random.default_rng(3))
    kwargs = dict(otsu=OtsuSettings(), background_margin_px=5, pressure_ref_pa=1e8)
    result, backgrounds, excluded = measure_intensity_pressure(
        fluorescence_images(folder, LOADS_MN), LOADS_MN, None, **kwargs
    )
    assert list(excluded) == [50.0] and "50.tif: the upper class is only" in excluded[50.0]
    assert result.fit.n == 3 and len(backgrounds) == 3
    np.testing.assert_allclose(result.table["load_n"], [25e-3, 100e-3, 200e-3])
    # uniform discs: the same mean intensity at every load, so the exponent is ~0
    assert abs(result.fit.exponent.estimate) < 0.05
    _disc_images(folder, {25.0: 0}, np.random.default_rng(4))
    with pytest.raises(RawDataError, match=r"2 of 4 images show a contact .*\[25\.0, 50\.0\]"):
        measure_intensity_pressure(fluorescence_images(folder, LOADS_MN), LOADS_MN, None, **kwargs)


def test_flim_map_without_contact_is_refused(tmp_path):
    """A FLIM map of one population (no confined molecules) has no contact class: an error
    naming the file, not two means of the same noise."""
    noise = np.random.default_rng(6).normal(0.5, 0.1, (64, 64)).clip(0.05)
    write_image(tmp_path / "flim.tif", noise.astype(np.float32), 200e-9)
    with pytest.raises(NoContact, match=r"flim\.tif: the upper class is only"):
        measure_lifetime(tmp_path / "flim.tif", None, otsu=OtsuSettings(), exclude_edge_px=2)
