"""Otsu contact area on images whose true contact area is known."""

import numpy as np
import pytest

from amontons.optics.area import otsu_contact_area


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


def test_shot_noise_does_not_move_the_area():
    rng = np.random.default_rng(1)
    truth = _disk(200, 40.3, 1500.0, 120.0)
    area = otsu_contact_area(rng.poisson(truth).astype(float), 1.0)
    # Contact and background differ by ~35 standard deviations of the shot noise, so no pixel
    # should be misclassified: the noisy area equals the noiseless one exactly.
    assert area.n_contact_pixels == int(np.count_nonzero(truth > 500))
    assert area.well_separated


def test_image_without_contact_is_flagged():
    rng = np.random.default_rng(2)
    background = rng.poisson(np.full((128, 128), 120.0)).astype(float)
    area = otsu_contact_area(background, 1.0, min_separation=0.8)
    # A single Gaussian population split at its mean has η = 2/π ≈ 0.64.
    assert area.separation == pytest.approx(2 / np.pi, abs=0.05)
    assert not area.well_separated


def test_constant_image_raises():
    with pytest.raises(ValueError, match="constant"):
        otsu_contact_area(np.full((8, 8), 3.0), 1.0)
