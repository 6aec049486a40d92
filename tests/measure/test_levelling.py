"""Sphere levelling and roughness statistics of AFM maps."""

import numpy as np
import pytest

from amontons.contact.surfaces import self_affine
from amontons.measure.topography import level_sphere, sphere_cap
from amontons.physics.roughness import roughness_statistics


def test_sphere_levelling_recovers_radius_roughness_and_line_offsets():
    n, pixel = 256, 256e-9  # a 65.5 µm scan, as 2048 px of 32 nm, at a coarser pixel
    # Roughness rolls off above 5 µm, as sandpaper grit leaves it; longer waves would be
    # indistinguishable from the sphere's form and tilt.
    roughness = self_affine((n, n), pixel, 0.8, rms_height=20e-9, long_cutoff=5e-6, rng=4)
    offsets = np.zeros(n)
    offsets[100:] += 15e-9  # two scan-line jumps
    offsets[180:] -= 25e-9
    raw = sphere_cap((n, n), pixel, 0.3e-3, (1e-6, -0.5e-6), 5e-6) + roughness + offsets[:, None]
    fit = level_sphere(raw, pixel)
    # The scan sees a 1.8 µm sag; roughness long waves (20 nm rms) bias the fitted curvature
    # by about h_rms/sag ≈ 1 %: 2 % on R is what the data can tell.
    assert fit.radius_m == pytest.approx(0.3e-3, rel=0.02)
    steps = np.diff(fit.line_offsets)
    assert steps[99] == pytest.approx(15e-9, abs=2e-9) and steps[179] == pytest.approx(
        -25e-9, abs=2e-9
    )
    # What downstream models use are the statistics. Slope and curvature live at short
    # wavelengths, untouched by levelling: 2 %. The rms height also carries the longest waves,
    # which a sphere fit and row alignment cannot tell from form and tilt: 20 %.
    truth = roughness_statistics(roughness, pixel)
    found = roughness_statistics(fit.roughness, pixel)
    assert found.slope_rms == pytest.approx(truth.slope_rms, rel=0.02)
    assert found.curvature_rms_per_m == pytest.approx(truth.curvature_rms_per_m, rel=0.02)
    assert found.h_rms_m == pytest.approx(truth.h_rms_m, rel=0.2)


def test_statistics_of_a_sinusoid():
    n, pixel, amplitude = 256, 32e-9, 10e-9
    wavelength = 64 * pixel
    x = np.arange(n) * pixel
    heights = np.tile(amplitude * np.sin(2 * np.pi * x / wavelength), (n, 1))
    stats = roughness_statistics(heights, pixel)
    k = 2 * np.pi / wavelength
    # Central differences at 64 px per wavelength: relative error (kΔx)²/6 ≈ 1.6e-3; 1 %.
    assert stats.h_rms_m == pytest.approx(amplitude / np.sqrt(2), rel=1e-3)
    assert stats.slope_rms == pytest.approx(amplitude * k / np.sqrt(2), rel=1e-2)
    assert stats.curvature_rms_per_m == pytest.approx(0.5 * amplitude * k**2 / np.sqrt(2), rel=1e-2)
