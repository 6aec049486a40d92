"""Rheometer files read by what they are (amontons.io.rheometer_files): our own CSV whatever
export maps the config has, each program's export through the map whose columns its header
names, and a file no reader takes refused naming the file, every reader tried and the
columns it has. The exports are the three shapes the programs write
(amontons.io.rheometer_export_shapes), of one trace written also as our CSV."""

import numpy as np
import pytest

from amontons.io.export_map import ExportMapError, export_maps
from amontons.io.rheometer import RheometerError, read_rheometer_csv, write_rheometer_csv
from amontons.io.rheometer_export_shapes import EXPORT_SHAPES, write_rheometer_export
from amontons.io.rheometer_files import OWN_CSV, choose_reader, read_rheometer_file
from amontons.virtual.rheometer import rheometer_trace

RADIUS_MM = 5.0
# The config's maps, one per program a lab exports from, named as a user names them.
MAPS_CONFIG = {
    "trios": EXPORT_SHAPES["units_row"].column_map(),
    "rheocompass": EXPORT_SHAPES["semicolons"].column_map(),
    "rspace": EXPORT_SHAPES["brackets"].column_map(RADIUS_MM),
}
SHAPE_OF = {"trios": "units_row", "rheocompass": "semicolons", "rspace": "brackets"}
# The exports hold 9 significant digits in another unit than our CSV's SI: one rounding of
# the unit conversion on each side (a few 1e-16 relative), well inside 1e-12, while one
# digit more or less in a file (1e-9 of a sample) would be far outside.
SAME_VALUES = 1e-12


def _trace():
    return rheometer_trace(
        0.025, 0.010, 0.008, RADIUS_MM * 1e-3, 1e-5, 20.0, 100.0, rng=np.random.default_rng(3)
    )


def test_our_csv_reads_as_ours_under_any_maps(tmp_path):
    path = tmp_path / "25.csv"
    write_rheometer_csv(path, _trace())
    for config in (None, MAPS_CONFIG["rheocompass"], MAPS_CONFIG):
        reader, trace = read_rheometer_file(path, export_maps(config))
        assert reader == OWN_CSV
        np.testing.assert_array_equal(trace.torque_n_m, read_rheometer_csv(path).torque_n_m)


@pytest.mark.parametrize("program", sorted(SHAPE_OF))
def test_each_export_is_read_by_the_map_its_header_names(tmp_path, program):
    """Three programs' exports and our CSV in one folder, one config: each file gets its own
    reader, and every one gives our CSV's trace."""
    ours = tmp_path / "25.csv"
    write_rheometer_csv(ours, _trace())
    shape = EXPORT_SHAPES[SHAPE_OF[program]]
    path = tmp_path / f"{program}{shape.suffix}"
    write_rheometer_export(path, _trace(), SHAPE_OF[program])
    reader, trace = read_rheometer_file(path, export_maps(MAPS_CONFIG))
    assert reader == program
    reference = read_rheometer_csv(ours)
    for field in ("time_s", "angle_rad", "normal_force_n", "torque_n_m"):
        np.testing.assert_allclose(
            getattr(trace, field), getattr(reference, field), rtol=SAME_VALUES, atol=0
        )
    assert trace.rotation_radius_m == pytest.approx(reference.rotation_radius_m, rel=1e-12)


def test_a_file_no_reader_takes_names_the_readers_tried_and_its_columns(tmp_path):
    path = tmp_path / "25.csv"
    write_rheometer_export(path, _trace(), "semicolons")
    maps = export_maps({"trios": MAPS_CONFIG["trios"]})
    with pytest.raises(RheometerError) as raised:
        choose_reader(path, maps)
    message = str(raised.value)
    assert message.startswith(f"{path}: matches no rheometer reader: tried our CSV (time_s, ")
    assert "export map 'trios' (Step time, Displacement, Axial force, Torque)" in message
    assert "the file's columns are ['Interval data:', 'Point No.', 'Time', 'Deflection Angle'" in (
        message
    )
    # with no map at all, only our CSV is tried
    with pytest.raises(RheometerError, match=r"tried our CSV \(time_s, .*\); the file's"):
        choose_reader(path, {})


@pytest.mark.parametrize(
    "content, message",
    [
        (b"", r"empty file; expected our rheometer CSV"),
        (b"\x89PNG\r\n\x1a\n\x00\x00\x00", r"binary data \(NUL bytes\)"),
    ],
)
def test_a_file_that_is_no_table_is_named(tmp_path, content, message):
    path = tmp_path / "25.csv"
    path.write_bytes(content)
    with pytest.raises(RheometerError, match=rf"{path}: {message}"):
        choose_reader(path, export_maps(MAPS_CONFIG))
    with pytest.raises(RheometerError, match=rf"{tmp_path / 'absent.csv'}: no such"):
        choose_reader(tmp_path / "absent.csv", {})


def test_the_configs_maps_one_or_named(tmp_path):
    assert export_maps(None) == {}
    assert list(export_maps(MAPS_CONFIG["trios"])) == ["export"]
    assert list(export_maps(MAPS_CONFIG)) == ["trios", "rheocompass", "rspace"]
    with pytest.raises(ExportMapError, match=r"rheometer_export\.trios\.columns has no 'torque'"):
        columns = dict(MAPS_CONFIG["trios"]["columns"])
        del columns["torque"]
        export_maps({**MAPS_CONFIG, "trios": {"columns": columns}})
    with pytest.raises(ExportMapError, match=r"has \['separator'\] but no 'columns'"):
        export_maps({"separator": ";", "trios": MAPS_CONFIG["trios"]})
    with pytest.raises(ExportMapError, match=r"rheometer_export = 'trios'; expected null"):
        export_maps("trios")


def test_named_maps_added_over_the_templates_single_map_keep_it_as_export():
    """A lab's config file adds its maps over config/config.yaml's single one, and Snakemake
    merges the two key by key: the single map's keys stay one map, named 'export', beside
    the lab's."""
    merged = {**MAPS_CONFIG["rheocompass"], "trios": MAPS_CONFIG["trios"]}
    maps = export_maps(merged)
    assert list(maps) == ["export", "trios"]
    assert maps["export"] == export_maps(MAPS_CONFIG["rheocompass"])["export"]
    with pytest.raises(ExportMapError, match=r"rheometer_export\.export: the name of the single"):
        export_maps({**merged, "export": MAPS_CONFIG["trios"]})
