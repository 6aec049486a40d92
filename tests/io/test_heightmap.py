"""AFM height maps: formats, units and NaN policy."""

import numpy as np
import pytest

from amontons.io.heightmap import TopographyError, read_height_map


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
    with pytest.raises(
        TopographyError, match=r"phase\.txt: Value units in 'deg', which is not a length"
    ):
        read_height_map(path)


def test_nan_pixels_fail_or_are_filled(tmp_path):
    heights = np.full((16, 16), 1e-9)
    heights[0, 0] = 2e-9
    heights[3, 4] = np.nan
    np.save(tmp_path / "h.npy", heights)
    with pytest.raises(TopographyError, match=r"1 NaN pixels \(first at row, column \(3, 4\)\)"):
        read_height_map(tmp_path / "h.npy", fallback_pixel_m=32e-9)
    filled = read_height_map(tmp_path / "h.npy", fallback_pixel_m=32e-9, nan_policy="fill")
    assert filled.filled == 1 and filled.heights[3, 4] == 1e-9


def test_unknown_format_is_named(tmp_path):
    (tmp_path / "h.xyz").write_text("1")
    with pytest.raises(TopographyError, match="unknown height-map format '.xyz'"):
        read_height_map(tmp_path / "h.xyz")
