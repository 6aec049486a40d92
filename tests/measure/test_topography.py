"""The topography measurement: the NaN policy from the config, mismatched scans, and the
flattening read from two scans of a sphere with a known cut."""

from pathlib import Path

import numpy as np
import pytest
import tifffile

from amontons.io.heightmap import HeightMap
from amontons.io.layout import RawDataError, afm_file
from amontons.io.tiff import read_image, write_image
from amontons.measure.flattening import unchanged_level
from amontons.measure.topography import (
    measure_topography,
    read_fit_record,
    read_sphere_fits,
    sphere_cap,
    square_pixels,
    write_fit_records,
    write_sphere_fits,
)
from amontons.simulate.surface import read_and_fit_afm_map

PIXEL = 32e-9


def _scans(tmp_path, rng, cut_nm=40.0):
    """A 0.3 mm sphere with 20 nm bumps; after: the bumps near the apex cut at a plane
    ``cut_nm`` below the highest point."""
    n = 256
    bumps = (
        20e-9
        * np.sin(np.arange(n) * 2 * np.pi / 16)[:, None]
        * np.cos(np.arange(n) * 2 * np.pi / 16)[None, :]
    )
    before = sphere_cap((n, n), PIXEL, 0.3e-3) + bumps
    after = np.minimum(before, before.max() - cut_nm * 1e-9)
    noise = 0.2e-9
    write_image(tmp_path / "afm_before.tif", before + rng.normal(0, noise, before.shape), PIXEL)
    write_image(tmp_path / "afm_after.tif", after + rng.normal(0, noise, before.shape), PIXEL)
    return before, after


def test_flattening_is_the_depth_of_the_cut(tmp_path):
    before, after = _scans(tmp_path, np.random.default_rng(1))
    topo = measure_topography(
        tmp_path / "afm_before.tif", tmp_path / "afm_after.tif", None, nan_policy="fail"
    )
    # Depth of the cut to the noise of two scans (5 σ of √2 × 0.2 nm = 1.4 nm).
    assert -topo.change_m.min() == pytest.approx((before - after).max(), abs=1.5e-9)
    assert topo.before.radius_m == pytest.approx(0.3e-3, rel=0.02)


def test_the_maps_levelled_again_by_the_written_fits_are_the_same_to_the_bit(tmp_path):
    """A later step (Fig. B.9) levels the scans by the fits measure_topography wrote instead
    of fitting again: the same roughness, change and flattening, every array to the bit,
    with scan-line offsets levelled (a row shifted in the before scan) and without."""
    _scans(tmp_path, np.random.default_rng(5))
    image = read_image(tmp_path / "afm_before.tif").data.astype(np.float64)
    image[100:, :] += 3e-9  # a scan-line offset that 'auto' levels
    write_image(tmp_path / "afm_before.tif", image, PIXEL)
    paths = (tmp_path / "afm_before.tif", tmp_path / "afm_after.tif")
    fitted = measure_topography(*paths, None, nan_policy="fail")
    assert fitted.before.line_levelling.applied
    write_sphere_fits(tmp_path / "fits.h5", fitted)
    again = measure_topography(
        *paths, None, nan_policy="fail", known_fits=read_sphere_fits(tmp_path / "fits.h5")
    )
    for name in ("before", "after"):
        ours, theirs = getattr(again, name), getattr(fitted, name)
        assert np.array_equal(ours.roughness, theirs.roughness)
        assert (ours.radius_m, ours.apex_xy_m, ours.apex_height_m) == (
            theirs.radius_m,
            theirs.apex_xy_m,
            theirs.apex_height_m,
        )
        assert np.array_equal(ours.line_offsets, theirs.line_offsets)
    assert np.array_equal(again.change_m, fitted.change_m)
    assert again.to_record() == fitted.to_record()


def test_the_levelling_jobs_fit_of_the_before_scan_gives_the_topography_to_the_bit(tmp_path):
    """measure_topography takes the before scan's fit from level_afm_map's file (the scenes'
    levelling fits the same map, read the same way) and fits only the after scan: the same
    topography, every array and the record, as fitting both, scan-line offsets levelled."""
    _scans(tmp_path, np.random.default_rng(7))
    image = read_image(tmp_path / "afm_before.tif").data.astype(np.float64)
    image[60:, :] -= 2e-9  # a scan-line offset that 'auto' levels
    write_image(tmp_path / "afm_before.tif", image, PIXEL)
    paths = (tmp_path / "afm_before.tif", tmp_path / "afm_after.tif")
    levelled, fit = read_and_fit_afm_map(
        paths[0], fallback_pixel_m=None, nan_policy="fail", channel=None, line_levelling="auto"
    )
    assert fit.line_levelling.applied
    write_fit_records(tmp_path / "before_fit.h5", {"before": fit})
    known = (read_fit_record(tmp_path / "before_fit.h5", "before"), None)
    both = measure_topography(*paths, None, nan_policy="fail")
    given = measure_topography(*paths, None, nan_policy="fail", known_fits=known)
    assert np.array_equal(given.before.roughness, both.before.roughness)
    assert np.array_equal(given.after.roughness, both.after.roughness)
    assert np.array_equal(given.change_m, both.change_m)
    assert given.to_record() == both.to_record()
    assert levelled.radius_m == both.before.radius_m


def test_nan_pixels_fail_or_are_filled_as_the_config_says(tmp_path):
    _scans(tmp_path, np.random.default_rng(2))
    image = read_image(tmp_path / "afm_after.tif", allow_nan=True).data.astype(np.float32)
    image[10, 20] = np.nan
    write_image(tmp_path / "afm_after.tif", image, PIXEL)
    with pytest.raises(RawDataError, match=r"afm_after\.tif: 1 NaN pixels.*row, column \(10, 20\)"):
        measure_topography(
            tmp_path / "afm_before.tif", tmp_path / "afm_after.tif", None, nan_policy="fail"
        )
    topo = measure_topography(
        tmp_path / "afm_before.tif", tmp_path / "afm_after.tif", None, nan_policy="fill"
    )
    assert topo.filled_pixels == 1 and np.isfinite(topo.change_m).all()


def test_scans_of_different_fields_are_refused(tmp_path):
    _scans(tmp_path, np.random.default_rng(3))
    other = np.random.default_rng(4).normal(0.0, 1e-9, (128, 128)).astype(np.float32)
    write_image(tmp_path / "afm_after.tif", other, PIXEL)
    with pytest.raises(RawDataError, match=r"afm_after\.tif: \(128, 128\) px.*expected the field"):
        measure_topography(
            tmp_path / "afm_before.tif", tmp_path / "afm_after.tif", None, nan_policy="fail"
        )


def test_afm_file_finds_one_format_and_refuses_two(tmp_path):
    np.save(tmp_path / "afm_before.npy", np.zeros((16, 16)))
    assert afm_file(tmp_path, "afm_before").name == "afm_before.npy"
    (tmp_path / "afm_before.txt").write_text("# Width: 1 um\n0 0\n0 0\n")
    with pytest.raises(RawDataError, match="exactly one afm_before height map"):
        afm_file(tmp_path, "afm_before")


def test_unchanged_level_of_scans_that_did_not_flow_is_their_offset():
    # Identical populations: the level is the common offset, not a histogram artefact.
    assert unchanged_level(np.full((64, 64), 2e-9)) == pytest.approx(2e-9, abs=1e-15)
    # 70 % unchanged at 0, 30 % flattened by 1 nm, 0.05 nm noise: the level is 0 to 0.01 nm.
    rng = np.random.default_rng(0)
    change = np.where(rng.random(10000) < 0.7, 0.0, -1e-9) + rng.normal(0, 0.05e-9, 10000)
    assert unchanged_level(change) == pytest.approx(0.0, abs=1e-11)


def _sphere_on_grid(shape, pixel_x, pixel_y, radius_m, rng):
    """Heights (m) of a sphere's cap with a little noise, sampled on pixels of pixel_x × pixel_y."""
    ny, nx = shape
    x = (np.arange(nx) - (nx - 1) / 2) * pixel_x
    y = (np.arange(ny) - (ny - 1) / 2) * pixel_y
    r2 = x[None, :] ** 2 + y[:, None] ** 2
    return np.sqrt(radius_m**2 - r2) - radius_m + rng.normal(0, 0.1e-9, shape)


def test_square_pixels_resample_the_coarse_axis_exactly_for_a_plane():
    # linear interpolation reproduces a plane exactly: the resampling adds no error of its own
    height_map = HeightMap(
        heights=np.add.outer(np.arange(20) * 3e-9, np.arange(30) * 1e-9),
        pixel_m=40e-9,
        pixel_y_m=100e-9,
        path=Path("plane.tif"),
    )
    square = square_pixels(height_map)
    assert square.pixel_m == square.pixel_y_m == 40e-9
    assert square.heights.shape == (48, 30)  # 19 × 100 nm = 1.9 µm spans 48 rows of 40 nm
    rows = np.arange(48) * 40e-9 / 100e-9
    expected = np.add.outer(rows * 3e-9, np.arange(30) * 1e-9)
    np.testing.assert_allclose(square.heights, expected, rtol=0, atol=1e-21)


def test_non_square_pixels_give_the_radius_of_square_ones(tmp_path):
    """The same 0.1 mm sphere scanned on 32 nm × 48 nm pixels (a float TIFF with different X and
    Y resolution tags) and on 32 nm square ones: the levelled radius agrees to 0.2 % (0.1 nm of
    noise on the 90 nm sag of a 6 µm field moves either fit by ~0.1 %; its pixels taken as
    square, the oblong scan gives a radius 3.3 % low), and the record says how the pixels
    were squared."""
    rng = np.random.default_rng(5)
    radius = 0.1e-3
    for name, pixel_y, shape in (("square", 32e-9, (192, 192)), ("oblong", 48e-9, (128, 192))):
        heights = _sphere_on_grid(shape, 32e-9, pixel_y, radius, rng).astype(np.float32)
        for stem in ("afm_before", "afm_after"):
            tifffile.imwrite(
                tmp_path / f"{name}_{stem}.tif",
                heights,
                resolution=(1 / 32e-7, 1 / (pixel_y * 1e2)),
                resolutionunit=3,
            )
    found = {
        name: measure_topography(
            tmp_path / f"{name}_afm_before.tif",
            tmp_path / f"{name}_afm_after.tif",
            None,
            nan_policy="fail",
        )
        for name in ("square", "oblong")
    }
    assert found["oblong"].before.radius_m == pytest.approx(radius, rel=2e-3)
    assert found["oblong"].before.radius_m == pytest.approx(
        found["square"].before.radius_m, rel=2e-3
    )
    record = found["oblong"].to_record()
    assert record["resampled_to_square_pixels"] is True
    assert record["file_pixel_nm"] == {"x": pytest.approx(32.0), "y": pytest.approx(48.0)}
    assert record["pixel_nm"] == pytest.approx(32.0)
    assert found["square"].to_record()["resampled_to_square_pixels"] is False
