"""Otsu contact area on images whose true contact area is known, and the three tests that
decide whether an image shows a contact at all."""

import numpy as np
import pandas as pd
import pytest

from amontons.measure.area import OtsuSettings, image_pixel_m, otsu_contact_area


def _disk(side, radius_px, inside, outside):
    y, x = np.indices((side, side)) - (side - 1) / 2
    return np.where(np.hypot(x, y) <= radius_px, inside, outside).astype(float)


def test_noiseless_disk_area_equals_pixel_count_and_circle():
    image = _disk(200, 40.3, 1000.0, 100.0)
    area = otsu_contact_area(image, 200e-9)
    assert area.n_contact_pixels == int(np.count_nonzero(image > 500))
    # Pixel-centre counting of a 40-px-radius disk differs from πr² by the lattice-point error,
    # O(r^(2/3)) pixels ≈ 0.1 % here; 0.5 % leaves room without hiding a wrong threshold.
    assert area.area_m2 == pytest.approx(np.pi * (40.3 * 200e-9) ** 2, rel=5e-3)
    assert area.separation > 0.99
    assert area.contact_found and area.largest_patch_px == area.n_contact_pixels


def test_shot_noise_does_not_move_the_area():
    rng = np.random.default_rng(1)
    truth = _disk(200, 40.3, 1500.0, 120.0)
    area = otsu_contact_area(rng.poisson(truth).astype(np.uint16), 1.0)
    # Contact and background differ by ~35 standard deviations of the shot noise, so no pixel
    # should be misclassified: the noisy area equals the noiseless one exactly.
    assert area.n_contact_pixels == int(np.count_nonzero(truth > 500))
    assert area.contact_found
    # (1500 − 120)/√121 = 125 shot-noise sd between the classes
    assert area.contrast == pytest.approx(125, rel=0.05)


def test_image_without_contact_is_flagged_by_its_contrast():
    """Shot noise alone: Otsu splits one Gaussian population at its mean (η = 2/π ≈ 0.64, too
    close to a small real contact's ~0.7 to decide); the class means lie 2σ·√(2/π) = 1.6σ
    apart, and σ is the shot noise √120 (the lower class's own sd is only 0.6σ): contrast
    1.6, far below 5."""
    rng = np.random.default_rng(2)
    background = rng.poisson(np.full((128, 128), 120.0)).astype(np.uint16)
    area = otsu_contact_area(background, 1.0)
    assert area.separation == pytest.approx(2 / np.pi, abs=0.05)
    assert area.contrast == pytest.approx(1.6, abs=0.2)
    assert not area.contact_found and "noise sd above the background" in area.flag
    strict = otsu_contact_area(background, 1.0, OtsuSettings(min_separation=0.8))
    assert "Otsu separation 0.6" in strict.flag


def test_photon_counting_dark_frame_is_flagged_by_its_contrast():
    """Mostly 0 and 1 counts: two narrow classes (η ≈ 0.95) one count apart, below the shot
    noise of the lower class (√(0 + 1) = 1): contrast ≈ 1, no contact."""
    dark = np.random.default_rng(3).poisson(0.1, (256, 256)).astype(np.uint16)
    area = otsu_contact_area(dark, 200e-9)
    assert area.separation > 0.9
    assert area.contrast == pytest.approx(1.0, abs=0.3)
    assert not area.contact_found and "noise sd above the background" in area.flag


def test_hot_pixels_are_flagged_by_their_patch_size():
    """20 isolated saturated pixels on a noisy background: well separated and bright, but no
    patch larger than one pixel, so not a contact."""
    rng = np.random.default_rng(4)
    image = rng.poisson(120.0, (128, 128)).astype(np.uint16)
    rows, cols = rng.choice(np.arange(2, 126, 3), size=(2, 20))
    image[rows, cols] = 4000
    area = otsu_contact_area(image, 200e-9)
    assert area.separation > 0.8 and area.contrast > 5
    assert area.largest_patch_px == 1
    assert not area.contact_found and "isolated bright pixels" in area.flag


def test_smallest_contact_the_psf_can_show_is_found():
    """A point-like contact imaged by the PSF (FWHM 450 nm on 200 nm pixels: σ = 0.96 px)
    covers ≥ 4 pixels above Otsu's threshold, so it passes min_patch_px = 4; its separation
    is only ~0.7 (the PSF's wings widen the background class), which is why η alone does
    not decide."""
    rows, cols = np.indices((64, 64))
    spot = 1500.0 * np.exp(-((rows - 31.6) ** 2 + (cols - 32.3) ** 2) / (2 * 0.955**2))
    image = np.random.default_rng(5).poisson(120.0 + spot).astype(np.uint16)
    area = otsu_contact_area(image, 200e-9)
    assert area.contact_found, area.flag
    assert area.largest_patch_px >= OtsuSettings().min_patch_px
    assert 0.6 < area.separation < 0.8


def test_constant_image_raises():
    with pytest.raises(ValueError, match="constant"):
        otsu_contact_area(np.full((8, 8), 3.0), 1.0)


def test_the_render_pixel_is_the_sheets_else_the_one_the_area_table_recorded(tmp_path):
    from_files = tmp_path / "contact_area.csv"
    pd.DataFrame({"load_mn": [25.0, 50.0], "pixel_nm": [250.0, 250.0]}).to_csv(from_files)
    assert image_pixel_m(200.0, []) == 200.0 * 1e-9  # as the scripts convert the sheet's
    assert image_pixel_m(None, [from_files]) == 250.0 * 1e-9
    pd.DataFrame({"load_mn": [25.0, 50.0], "pixel_nm": [250.0, 260.0]}).to_csv(from_files)
    with pytest.raises(ValueError, match=r"contact_area\.csv: pixel_nm \[250\.0, 260\.0\]"):
        image_pixel_m(None, [from_files])
