"""Broken files of every kind a user may hand the pipeline: each is refused with the project's
own error, which names the file and says what was expected, never with an error from inside
numpy, pandas, tifffile or SurfaceTopography."""

import pickle

import numpy as np
import pytest
import tifffile

from amontons.io.absorbance import AbsorbanceError, read_absorbance_csv
from amontons.io.heightmap import TopographyError, read_height_map
from amontons.io.rheometer import RheometerError, read_rheometer_csv
from amontons.io.tiff import ImageError, read_image

GWYDDION = "# Channel: Height\n# Width: 10 µm\n# Height: 10 µm\n# Value units: m\n"


def _matrix(n=16, scale=1e-8):
    rows, cols = np.indices((n, n))
    return scale * np.sin(rows / 3.0) * np.cos(cols / 4.0)


def _text(heights, header=GWYDDION):
    return header + "\n".join(" ".join(f"{v:.6e}" for v in row) for row in heights) + "\n"


def truncated_text(path):
    text = _text(_matrix())
    path.write_text(text[: len(text) // 2 - 7])  # cut inside a row


def comma_decimals(path):
    path.write_text(_text(_matrix()).replace(".", ","))


def latin1_text(path):
    path.write_bytes(_text(_matrix()).encode("latin-1"))


def no_value_units(path):
    path.write_text(_text(_matrix(), header="# Width: 10 µm\n# Height: 10 µm\n"))


def unknown_value_units(path):
    path.write_text(_text(_matrix(), header=GWYDDION.replace("units: m", "units: furlong")))


def nanometre_units_on_metres(path):
    # the values are metres (1e-8) but the header says nm: 1e-17 m, no surface
    path.write_text(_text(_matrix(), header=GWYDDION.replace("units: m", "units: nm")))


def empty_npy(path):
    path.write_bytes(b"")


def pickled_npy(path):
    np.save(path, np.array([{"heights": 1}], dtype=object), allow_pickle=True)


def integer_npy(path):
    np.save(path, (_matrix() * 1e10).astype(np.int16))


def complex_npy(path):
    np.save(path, _matrix().astype(complex))


def three_d_npy(path):
    np.save(path, np.stack([_matrix(), _matrix()]))


def all_nan_npy(path):
    np.save(path, np.full((16, 16), np.nan))


def empty_tiff(path):
    path.write_bytes(b"")


def truncated_tiff(path):
    tifffile.imwrite(path, _matrix(64).astype(np.float32))
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 3])


def uint16_tiff(path):
    tifffile.imwrite(path, (_matrix() * 1e12).astype(np.uint16))


def display_dpi_tiff(path):
    # image software's default 72 dpi: not a pixel size, and the sheet gives none here
    tifffile.imwrite(path, _matrix().astype(np.float32), resolution=(72, 72), resolutionunit=2)


def pickle_as_tiff(path):
    path.write_bytes(pickle.dumps(_matrix()))


def unknown_suffix(path):
    path.write_text("1 2 3")


HEIGHT_MAPS = [
    ("afm.txt", truncated_text, r"data row \d+ holds \d+ numbers.*truncated"),
    ("afm.txt", comma_decimals, r"decimal commas"),
    ("afm.txt", latin1_text, r"not UTF-8 text"),
    ("afm.txt", no_value_units, r"no height unit"),
    ("afm.txt", unknown_value_units, r"'furlong', which is not a length"),
    ("afm.txt", nanometre_units_on_metres, r"heights span 1\.99e-17 m"),
    ("afm.npy", empty_npy, r"not a readable \.npy array"),
    ("afm.npy", pickled_npy, r"not a readable \.npy array"),
    ("afm.npy", integer_npy, r"dtype int16; expected float heights in m"),
    ("afm.npy", complex_npy, r"dtype complex128; expected float heights in m"),
    ("afm.npy", three_d_npy, r"shape \(2, 16, 16\); expected 2-D"),
    ("afm.npy", all_nan_npy, r"every pixel is NaN"),
    ("afm.tif", empty_tiff, r"not a readable TIFF"),
    ("afm.tif", truncated_tiff, r"not a readable TIFF"),
    ("afm.tif", uint16_tiff, r"uint16 pixels and not a vendor TIFF"),
    ("afm.tif", display_dpi_tiff, r"no pixel size in the file and none in the sample sheet"),
    ("afm.tif", pickle_as_tiff, r"not a readable TIFF"),
    ("afm.xyz1", unknown_suffix, r"unknown height-map format '\.xyz1'"),
]


@pytest.mark.parametrize(
    ("name", "make", "expected"), HEIGHT_MAPS, ids=[m.__name__ for _, m, _ in HEIGHT_MAPS]
)
def test_broken_height_map_is_a_named_topography_error(tmp_path, name, make, expected):
    path = tmp_path / name
    make(path)
    # the sheet's pixel is given where the file has none, so that each case fails for its own
    # reason (except the display-dpi TIFF, whose point is that nothing gives a pixel)
    pixel = None if make is display_dpi_tiff else 40e-9
    with pytest.raises(TopographyError, match=expected) as info:
        read_height_map(path, fallback_pixel_m=pixel, nan_policy="fill")
    assert str(path) in str(info.value)


def test_file_and_sheet_pixels_that_disagree_name_both(tmp_path):
    path = tmp_path / "afm.tif"
    tifffile.imwrite(path, _matrix().astype(np.float32), resolution=(1e5, 1e5), resolutionunit=3)
    with pytest.raises(TopographyError, match=r"file's pixel is 100 nm, .*afm_pixel_nm 32 nm"):
        read_height_map(path, fallback_pixel_m=32e-9)
    assert read_height_map(path, fallback_pixel_m=100e-9).pixel_m == pytest.approx(100e-9)


def _rheometer_text():
    rows = "\n".join(f"{0.1 * i},{0.01 * i},0.05,{1e-4 * i}" for i in range(20))
    return "# rotation_radius_mm: 5\ntime_s,angle_rad,normal_force_N,torque_N_m\n" + rows + "\n"


RAW_FILES = [
    ("25.tif", lambda p: p.write_bytes(b"II*\x00garbage"), read_image, ImageError, "TIFF"),
    ("25.tif", empty_tiff, read_image, ImageError, "not a readable TIFF"),
    ("25.csv", lambda p: p.write_bytes(b""), read_rheometer_csv, RheometerError, "empty file"),
    (
        "25.csv",
        lambda p: p.write_bytes(_rheometer_text().replace("5", "\xb5").encode("latin-1")),
        read_rheometer_csv,
        RheometerError,
        "not UTF-8 text",
    ),
    (
        "absorbance.csv",
        lambda p: p.write_bytes(bytes(range(256)) * 4),
        read_absorbance_csv,
        AbsorbanceError,
        "no column 'wavelength_nm'",
    ),
    (
        "absorbance.csv",
        lambda p: p.write_text('wavelength_nm,absorbance\n400,"0.1\n'),
        read_absorbance_csv,
        AbsorbanceError,
        "not a readable CSV table",
    ),
]


@pytest.mark.parametrize(
    ("name", "make", "read", "error", "expected"),
    RAW_FILES,
    ids=[
        "garbage-fluorescence-tiff",
        "empty-fluorescence-tiff",
        "empty-rheometer-csv",
        "latin1-rheometer-csv",
        "binary-absorbance-csv",
        "unclosed-quote-absorbance-csv",
    ],
)
def test_broken_raw_data_file_is_a_named_error(tmp_path, name, make, read, error, expected):
    path = tmp_path / name
    make(path)
    with pytest.raises(error, match=expected) as info:
        read(path)
    assert str(path) in str(info.value)
