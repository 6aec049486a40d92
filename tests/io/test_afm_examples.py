"""Real AFM files from real instruments (Bruker, Park, Asylum, Nanosurf, Zygo, Digital Surf,
ISO x3p, Gwyddion exports) read as height maps in m.

The files are the reader test data of SurfaceTopography, kept beside the project in
``../shared/afm-examples/`` (not shipped with it); the tests skip, saying so, where that folder
is absent. Each file's grid, physical size and Sq (rms height, mean removed, whole map) are
checked against the values SurfaceTopography's own tests assert (its README table: Sq to 7
significant digits, so a relative tolerance of 1e-6 is the precision of the reference), and
for the other files against the vendor library's own reading of the same file, to 1e-6 as
well: they must agree to round-off once the units are converted and the axes transposed (a
wrong unit is a factor of 1000, a swapped axis a wrong shape or size).
"""

from pathlib import Path

import numpy as np
import pytest

from amontons.io.heightmap import LENGTH_UNITS, TopographyError, read_height_map, read_heights
from amontons.io.pixel_probe import tiff_scan_side_m

EXAMPLES = Path(__file__).resolve().parents[2].parent / "shared" / "afm-examples"
pytestmark = pytest.mark.skipif(
    not EXAMPLES.is_dir(), reason=f"no folder of real AFM files at {EXAMPLES}"
)
REL = 1e-6

# file: (rows, columns), (size along y, size along x) in m, Sq in m (SurfaceTopography's tests)
REFERENCE = {
    "di-5.di": ((512, 512), (1e-6, 1e-6), 5.831926e-9),
    "x3p-2.x3p": ((650, 650), (204.48e-6, 82.98e-6), 7.728033e-8),
    "example_ps.tiff": ((512, 512), (1e-6, 1e-6), 3.933e-9),
    "matrix-3.txt": ((256, 256), (10e-6, 10e-6), 3.5222918750e-8),
}
FILES = sorted(p.name for p in EXAMPLES.glob("*") if p.suffix not in (".md",))


def _sq(heights):
    return float(np.sqrt(np.nanmean((heights - np.nanmean(heights)) ** 2)))


@pytest.mark.parametrize("name", sorted(REFERENCE))
def test_reference_files_give_the_grid_size_and_sq_of_the_reference(name):
    shape, (size_y, size_x), sq = REFERENCE[name]
    raw = read_heights(EXAMPLES / name)
    assert raw.heights.shape == shape
    # x3p-2's sizes are printed to 4 digits in the reference table
    size_rel = 1e-4 if name == "x3p-2.x3p" else REL
    assert raw.pixel_x_m * shape[1] == pytest.approx(size_x, rel=size_rel)
    assert raw.pixel_y_m * shape[0] == pytest.approx(size_y, rel=size_rel)
    # example_ps.tiff's Sq is printed to 4 digits
    assert _sq(raw.heights) == pytest.approx(sq, rel=1e-3 if name == "example_ps.tiff" else REL)


def _library_reading(path):
    from SurfaceTopography import open_topography

    channel = open_topography(str(path)).default_channel
    unit = channel.unit if isinstance(channel.unit, str) else channel.unit[1]
    heights = np.ma.filled(np.ma.asarray(channel.topography().heights(), float), np.nan)
    sizes = np.array(channel.physical_sizes) * LENGTH_UNITS[unit]
    return heights.T * LENGTH_UNITS[unit], sizes[::-1], channel.name


@pytest.mark.parametrize("name", FILES)
def test_every_file_reads_as_the_vendor_library_reads_it(name):
    raw = read_heights(EXAMPLES / name)
    heights, (size_y, size_x), channel = _library_reading(EXAMPLES / name)
    assert raw.heights.shape == heights.shape and raw.channel == channel
    ny, nx = heights.shape
    assert raw.pixel_x_m * nx == pytest.approx(size_x, rel=REL)
    assert raw.pixel_y_m * ny == pytest.approx(size_y, rel=REL)
    assert _sq(raw.heights) == pytest.approx(_sq(heights), rel=REL)


def test_german_gwyddion_export_reads_as_the_english_one():
    english = read_heights(EXAMPLES / "gwyddion-export-english.txt")
    german = read_heights(EXAMPLES / "gwyddion-export-german.txt")
    np.testing.assert_array_equal(german.heights, english.heights)
    assert (german.pixel_x_m, german.pixel_y_m) == (english.pixel_x_m, english.pixel_y_m)
    # "Breite: 12.34 µm" over 3 columns and "Höhe: 5678.9 nm" over 4 rows, not a sheet's pixel
    assert german.heights.shape == (4, 3)
    assert german.pixel_x_m == pytest.approx(12.34e-6 / 3, rel=REL)
    assert german.pixel_y_m == pytest.approx(5678.9e-9 / 4, rel=REL)


def test_park_tiff_reads_its_heights_not_its_8_bit_preview():
    height_map = read_height_map(EXAMPLES / "example_ps.tiff")
    assert height_map.heights.shape == (512, 512)
    assert _sq(height_map.heights) == pytest.approx(3.933e-9, rel=1e-3)


def test_the_dag_leaves_a_park_tiffs_size_to_its_reader():
    """Its first page is a 256² 8-bit preview of the 512² map: sized from the header (with a
    sheet pixel), the scan would be half its size, so the header probe gives none."""
    assert tiff_scan_side_m(EXAMPLES / "example_ps.tiff", 1.953125e-9) is None


def test_non_square_pixels_are_kept_per_axis():
    height_map = read_height_map(EXAMPLES / "x3p-2.x3p")
    assert not height_map.square
    assert height_map.pixel_y_m / height_map.pixel_m == pytest.approx(204.48 / 82.98, rel=1e-4)


def test_a_channel_is_chosen_by_name_and_a_wrong_name_lists_the_channels():
    height_map = read_height_map(EXAMPLES / "nid-1.nid", channel="Scan backward (Z-Axis)")
    assert height_map.channel == "Scan backward (Z-Axis)"
    with pytest.raises(TopographyError, match=r"nid-1\.nid: no channel 'Height'.*'Scan forward"):
        read_height_map(EXAMPLES / "nid-1.nid", channel="Height")


def test_a_channel_without_a_height_unit_is_refused():
    with pytest.raises(TopographyError, match=r"di-1\.di: channel 'Phase' has no height unit"):
        read_height_map(EXAMPLES / "di-1.di", channel="Phase")


def test_a_map_too_small_for_a_sphere_fit_says_so():
    # 4 × 3 is 2-D; it is refused for its size, with the size a fit needs
    with pytest.raises(TopographyError, match=r"matrix-6\.txt: height map of 3 × 4 px.*at least 8"):
        read_height_map(EXAMPLES / "matrix-6.txt")


def test_undefined_points_are_nan_and_follow_the_nan_policy():
    with pytest.raises(TopographyError, match=r"sur-2\.sur: 117 NaN pixels"):
        read_height_map(EXAMPLES / "sur-2.sur")
    assert read_height_map(EXAMPLES / "sur-2.sur", nan_policy="fill").filled == 117
