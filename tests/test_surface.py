"""AFM height maps: readers, NaN policy, sphere levelling with scan-line offsets, statistics."""

import numpy as np
import pytest

from amontons.contact.surfaces import self_affine
from amontons.surface import (
    TopographyError,
    level_sphere,
    read_height_map,
    roughness_statistics,
    sphere_cap,
)


def test_gwyddion_text_export_is_read_with_units(tmp_path):
    heights_nm = np.arange(80, dtype=float).reshape(8, 10)
    path = tmp_path / "afm.txt"
    header = "# Channel: Height\n# Width: 0.320 µm\n# Height: 0.256 µm\n# Value units: nm\n"
    path.write_text(header + "\n".join(" ".join(f"{v:g}" for v in row) for row in heights_nm))
    height_map = read_height_map(path)
    np.testing.assert_allclose(height_map.heights, heights_nm * 1e-9, rtol=1e-15)
    assert height_map.pixel_m == pytest.approx(32e-9, rel=1e-12)


def test_non_length_value_units_are_refused(tmp_path):
    path = tmp_path / "phase.txt"
    path.write_text("# Width: 1 µm\n# Value units: deg\n" + "\n".join(["1 2 3 4 5 6 7 8"] * 8))
    with pytest.raises(TopographyError, match="'deg' are not a length"):
        read_height_map(path)


def test_nan_pixels_fail_or_are_filled(tmp_path):
    heights = np.ones((16, 16))
    heights[3, 4] = np.nan
    np.save(tmp_path / "h.npy", heights)
    with pytest.raises(TopographyError, match=r"1 NaN pixels \(first at row, column \(3, 4\)\)"):
        read_height_map(tmp_path / "h.npy", fallback_pixel_m=32e-9)
    filled = read_height_map(tmp_path / "h.npy", fallback_pixel_m=32e-9, nan_policy="fill")
    assert filled.filled == 1 and np.all(filled.heights == 1.0)


def test_unknown_format_is_named(tmp_path):
    (tmp_path / "h.xyz").write_text("1")
    with pytest.raises(TopographyError, match="unknown height-map format '.xyz'"):
        read_height_map(tmp_path / "h.xyz")


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
