"""The scene's indenter from an AFM map: area averaging to the solver pixel, the window about the
fitted apex, and the refusal of a window that leaves the scan."""

import numpy as np
import pytest
from skimage.transform import downscale_local_mean

from amontons.config import geometry
from amontons.contact.surfaces import self_affine
from amontons.measure.topography import sphere_cap
from amontons.physics.hertz import contact_radius
from amontons.physics.roughness import roughness_statistics
from amontons.simulate.scene import SceneError, scene_for_sphere
from amontons.simulate.surface import (
    afm_indenter,
    afm_scene,
    area_average,
    level_afm_map,
    scan_window_m,
)

SCENE = {
    "surface": "afm_before",
    "geometry": "sphere",
    "model": "elastic",
    "loads": "measured",
    "pixel_nm": 250.0,
    "window_factor": 1.5,
    "side_px": None,
    "max_side_px": 512,
    "tol": 1e-8,
    "optics": "none",
    "rendering": "emission",
    "confinement_floor_mpa": 0.0,
    "p_y_mpa": None,
    "k_mpa_per_nm": None,
    "increment": "local",
    "alpha": 1.0,
}


def test_area_average_of_whole_blocks_is_the_block_mean():
    """An independent implementation (scikit-image's block mean) for an integer ratio: exact to
    round-off."""
    rng = np.random.default_rng(3)
    heights = rng.normal(size=(96, 96))
    ours = area_average(heights, 1.0, (0.0, 0.0), 12, 8.0)
    assert np.allclose(ours, downscale_local_mean(heights, (8, 8)), atol=1e-12)


def test_area_average_with_fractional_pixels_weighs_cut_pixels_by_their_covered_fraction():
    """A window of 7 output pixels of 3.7 input pixels starting at 1.3: against a brute-force
    average of the map repeated 10× per axis (every edge then falls on a sub-pixel boundary),
    exact to round-off."""
    rng = np.random.default_rng(4)
    heights = rng.normal(size=(40, 40))
    ours = area_average(heights, 1.0, (1.3, 1.3), 7, 3.7)
    fine = np.repeat(np.repeat(heights, 10, axis=0), 10, axis=1)
    edges = np.round((1.3 + np.arange(8) * 3.7) * 10).astype(int)
    brute = np.array(
        [
            [fine[edges[i] : edges[i + 1], edges[j] : edges[j + 1]].mean() for j in range(7)]
            for i in range(7)
        ]
    )
    assert np.allclose(ours, brute, atol=1e-12)


def test_rms_height_survives_averaging_and_the_slope_drops_to_the_solver_pixel():
    """A self-affine surface (H = 0.8, 10 µm roll-off) on 25 nm pixels averaged to 250 nm: the
    rms height lives in the long waves and survives within 2 %; the rms slope lives in the short
    waves the solver cannot carry, and falls to what the same surface, low-pass filtered to
    the solver's Nyquist wavelength (500 nm), has: within 15 % of it (a box average is not an
    ideal low-pass filter; it keeps some power just below the cut-off)."""
    pixel, factor = 25e-9, 10
    rough = self_affine((1280, 1280), pixel, 0.8, rms_height=30e-9, long_cutoff=10e-6, rng=5)
    coarse = area_average(rough, pixel, (0.0, 0.0), 128, pixel * factor)
    fine_stats = roughness_statistics(rough, pixel)
    coarse_stats = roughness_statistics(coarse, pixel * factor)
    assert coarse_stats.h_rms_m == pytest.approx(fine_stats.h_rms_m, rel=0.02)
    assert coarse_stats.slope_rms < 0.6 * fine_stats.slope_rms
    spectrum = np.fft.fft2(rough)
    q = np.hypot(*np.meshgrid(np.fft.fftfreq(1280, pixel), np.fft.fftfreq(1280, pixel)))
    spectrum[q > 1 / (2 * pixel * factor)] = 0
    band_limited = np.real(np.fft.ifft2(spectrum))
    expected = roughness_statistics(band_limited[::factor, ::factor], pixel * factor)
    assert coarse_stats.slope_rms == pytest.approx(expected.slope_rms, rel=0.15)


def _sphere_map(side_px, pixel, radius, apex_rc_m=(0.0, 0.0)):
    # sphere_cap takes the apex as (x, y) = (col, row)
    return sphere_cap((side_px, side_px), pixel, radius, (apex_rc_m[1], apex_rc_m[0]), 0.0)


def test_window_is_cut_about_the_fitted_apex():
    """An off-centre apex: the indenter's highest point sits at the window centre (within one
    solver pixel) and the window centre is reported where the apex is in the scan."""
    record = {"diameter_mm": 2.0, "e_star_gpa": 2.0, "loads": [5.0, 10.0, 20.0]}
    scene = scene_for_sphere("s", SCENE, "S", record)
    apex = (3.1e-6, -4.7e-6)
    heights = _sphere_map(900, 100e-9, 1e-3, apex)
    indenter = afm_indenter(level_afm_map(heights, 100e-9), scene, "map.tif")
    top = np.unravel_index(np.argmax(indenter.heights), indenter.heights.shape)
    centre = (indenter.heights.shape[0] - 1) / 2
    assert np.abs(np.array(top) - centre).max() <= 1
    # the sphere fit finds the apex to a small fraction of the AFM pixel
    assert indenter.centre_in_scan_m == pytest.approx(apex, abs=5e-9)


def test_a_window_larger_than_the_scan_names_the_file_and_sizes():
    record = {"diameter_mm": 2.0, "e_star_gpa": 2.0, "loads": [5.0, 10.0, 80.0]}
    scene = scene_for_sphere("wide", SCENE, "S", record)
    heights = _sphere_map(400, 100e-9, 1e-3)
    with pytest.raises(SceneError, match=r"map\.tif: scene wide: the solver window .* AFM scan"):
        afm_indenter(level_afm_map(heights, 100e-9), scene, "map.tif")


def test_a_map_that_is_no_sphere_apex_is_refused_naming_the_file(tmp_path):
    """A bowl (concave) scanned instead of a sphere's apex: the levelling finds no apex, and
    the error names the file and what was expected."""
    from amontons.io.heightmap import write_height_map
    from amontons.io.layout import RawDataError
    from amontons.simulate.surface import read_and_fit_afm_map

    path = tmp_path / "afm_before.tif"
    write_height_map(path, -_sphere_map(128, 100e-9, 1e-3), 100e-9)
    with pytest.raises(RawDataError, match=r"afm_before\.tif: .*not convex upwards.*sphere's apex"):
        read_and_fit_afm_map(
            path, fallback_pixel_m=None, nan_policy="fail", channel=None, line_levelling="auto"
        )


def test_a_levelled_map_survives_its_hdf5_file(tmp_path):
    """What level_afm_map writes, the scenes read back: heights to the bit, the sphere fit."""
    from amontons.io.fields import write_levelled_map
    from amontons.simulate.surface import load_levelled_map

    levelled = level_afm_map(_sphere_map(256, 100e-9, 1e-3, (1e-6, 2e-6)), 100e-9)
    path = tmp_path / "levelled.h5"
    write_levelled_map(path, levelled.heights_m, levelled.pixel_m, levelled.to_attributes())
    back = load_levelled_map(path)
    assert np.array_equal(back.heights_m, levelled.heights_m)
    assert (back.pixel_m, back.radius_m, back.apex_xy_m) == (
        levelled.pixel_m,
        levelled.radius_m,
        levelled.apex_xy_m,
    )


def test_a_scan_smaller_than_the_largest_window_keeps_the_loads_it_holds():
    """An off-centre apex in a 40 µm scan: the square about the apex is twice its distance to
    the nearest edge (to the bit of the geometry); the loads whose window (1.5 × the Hertz
    diameter, sized as the largest) fits are kept and solved on a window the scan holds, no
    smaller than the largest kept load needs; the others are left out with their windows."""
    record = {"diameter_mm": 2.0, "e_star_gpa": 20.0, "loads": [5.0, 10.0, 20.0, 80.0, 160.0]}
    apex = (3.0e-6, -2.0e-6)  # (row, col) from the map centre
    levelled = level_afm_map(_sphere_map(400, 100e-9, 1e-3, apex), 100e-9)
    # nearest edge: the apex's row is 20 + 3 µm from the top, 17 µm from the bottom edge
    assert scan_window_m(levelled) == pytest.approx(2 * 17e-6, abs=10e-9)
    scene, coverage = afm_scene("s", SCENE, "S", record, levelled)
    hertz = {f: contact_radius(f * 1e-3, 1e-3, 20e9) * 2 for f in record["loads"]}
    held = [f for f in record["loads"] if 1.5 * hertz[f] <= scan_window_m(levelled)]
    assert [f * 1e3 for f in scene.loads_n] == pytest.approx(held) and len(held) == 3
    assert [load.load_n * 1e3 for load in coverage.left_out] == pytest.approx([80.0, 160.0])
    assert all(load.window_m > coverage.largest_window_m for load in coverage.left_out)
    needed = 1.5 * hertz[held[-1]]
    assert needed <= scene.window_m <= coverage.largest_window_m
    assert scene.side_px * scene.pixel_m == pytest.approx(scene.window_m, rel=1e-12)
    indenter = afm_indenter(levelled, scene, "map.tif")  # the window fits: no SceneError
    assert indenter.heights.shape == (scene.side_px, scene.side_px)
    record_out = coverage.to_record()
    assert [row["load_mn"] for row in record_out["outside_scan"]] == pytest.approx([80, 160])
    assert record_out["scan_um"] == pytest.approx([40.0, 40.0])


def test_a_scan_that_holds_every_window_leaves_the_scene_as_configured():
    record = {"diameter_mm": 2.0, "e_star_gpa": 20.0, "loads": [5.0, 10.0, 20.0]}
    levelled = level_afm_map(_sphere_map(900, 100e-9, 1e-3), 100e-9)
    scene, coverage = afm_scene("s", SCENE, "S", record, levelled)
    assert scene == scene_for_sphere("s", SCENE, "S", record)
    assert coverage.left_out == ()


def test_a_scan_that_holds_no_window_gives_no_scene_and_every_load_left_out():
    record = {"diameter_mm": 2.0, "e_star_gpa": 20.0, "loads": [20.0, 80.0]}
    levelled = level_afm_map(_sphere_map(200, 100e-9, 1e-3), 100e-9)
    scene, coverage = afm_scene("s", SCENE, "S", record, levelled)
    assert scene is None
    assert [load.load_n for load in coverage.left_out] == pytest.approx([0.02, 0.08])


def test_a_fixed_window_keeps_every_load_or_none():
    """side_px fixes the window whatever the load: a scan holds it for all loads or none."""
    fixed = {**SCENE, "side_px": 100}  # 25 µm at 250 nm
    record = {"diameter_mm": 2.0, "e_star_gpa": 20.0, "loads": [5.0, 10.0]}
    frame = geometry.sphere_frame(fixed, record)
    assert geometry.frame_in_scan("f", fixed, frame, 30e-6).left_out == ()
    cut = geometry.frame_in_scan("f", fixed, frame, 20e-6)
    assert cut.frame.loads_n == () and len(cut.left_out) == 2
