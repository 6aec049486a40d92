"""TIFF reading and writing: pixel size round trip, and clear errors for unusable images."""

import numpy as np
import pytest
import tifffile

from amontons.io.files import atomic_path
from amontons.io.tiff import ImageError, read_image, write_image


def test_pixel_size_round_trips_through_resolution_tags(tmp_path):
    data = np.arange(12, dtype=np.uint16).reshape(3, 4)
    write_image(tmp_path / "a.tif", data, 200e-9)
    image = read_image(tmp_path / "a.tif")
    np.testing.assert_array_equal(image.data, data)
    # Tags store pixels per cm as a rational; 200 nm is 50 000 px/cm, exact.
    assert image.pixel_m == pytest.approx(200e-9, rel=1e-12)


def test_untagged_tiff_takes_the_sheet_pixel(tmp_path):
    tifffile.imwrite(tmp_path / "b.tif", np.ones((4, 4), np.uint16))
    assert read_image(tmp_path / "b.tif", fallback_pixel_m=32e-9).pixel_m == 32e-9
    with pytest.raises(ImageError, match="no pixel size"):
        read_image(tmp_path / "b.tif")


def test_rgb_image_is_rejected_with_its_shape(tmp_path):
    tifffile.imwrite(tmp_path / "rgb.tif", np.ones((5, 6, 3), np.uint8), photometric="rgb")
    with pytest.raises(ImageError, match=r"rgb.tif: image has shape \(5, 6, 3\)"):
        read_image(tmp_path / "rgb.tif", fallback_pixel_m=1e-7)


def test_signed_integer_image_is_rejected_with_its_dtype(tmp_path):
    tifffile.imwrite(tmp_path / "s.tif", np.ones((4, 4), np.int16))
    with pytest.raises(ImageError, match="s.tif: pixel dtype int16"):
        read_image(tmp_path / "s.tif", fallback_pixel_m=1e-7)


def test_nan_pixels_are_counted_in_the_error(tmp_path):
    data = np.ones((4, 4), np.float32)
    data[1, 2] = np.nan
    tifffile.imwrite(tmp_path / "n.tif", data)
    with pytest.raises(ImageError, match="1 NaN or infinite pixels"):
        read_image(tmp_path / "n.tif", fallback_pixel_m=1e-7)


def test_failed_write_leaves_nothing_behind(tmp_path):
    target = tmp_path / "out.csv"
    with pytest.raises(RuntimeError), atomic_path(target) as tmp:
        tmp.write_text("half")
        raise RuntimeError("interrupted")
    assert list(tmp_path.iterdir()) == []
