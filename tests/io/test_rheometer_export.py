"""Rheometer exports as the programs write them, read through a column map: the three export
shapes (units in brackets; units on a second header row; semicolons with decimal commas and a
preamble) give the friction of our own CSV on the same trace, detection and config agree, and
every kind of bad export or map is refused naming the file (or the key), the value and what
was expected."""

import codecs
import dataclasses

import numpy as np
import pytest

from amontons.io.export_map import ExportMap, ExportMapError
from amontons.io.layout import RawDataError, rheometer_files, rheometer_name
from amontons.io.rawdata import read_rheometer_traces
from amontons.io.rheometer import RheometerError, read_rheometer_csv, write_rheometer_csv
from amontons.io.rheometer_export import read_rheometer_export
from amontons.io.rheometer_export_shapes import EXPORT_SHAPES, write_rheometer_export
from amontons.measure.friction import static_friction
from amontons.virtual.rheometer import rheometer_trace

LOAD_N, RADIUS_MM = 0.025, 5.0


def _trace(seed=0):
    return rheometer_trace(
        LOAD_N, 0.010, 0.008, RADIUS_MM * 1e-3, 1e-5, 20.0, 100.0, rng=np.random.default_rng(seed)
    )


def _export(tmp_path, shape, trace=None):
    path = tmp_path / f"25{EXPORT_SHAPES[shape].suffix}"
    write_rheometer_export(path, trace or _trace(), shape)
    return path


def _map(shape, **changes):
    return ExportMap.from_config({**EXPORT_SHAPES[shape].column_map(RADIUS_MM), **changes})


def _csv_friction(tmp_path, trace):
    write_rheometer_csv(tmp_path / "ours.csv", trace)
    return static_friction(read_rheometer_csv(tmp_path / "ours.csv"))


def test_the_shapes_are_written_the_way_the_programs_write_them(tmp_path):
    brackets = _export(tmp_path, "brackets").read_text(encoding="utf-8").splitlines()
    assert brackets[0].startswith("Action Name,Time (action)(s),")
    assert "Torque(N m)" in brackets[0] and brackets[1].startswith("Friction test,0,")
    units_row = _export(tmp_path, "units_row").read_text(encoding="utf-8").splitlines()
    names = units_row.index("Step time\tDisplacement\tAxial force\tTorque")
    assert units_row[names + 1] == "s\tmrad\tN\tµN.m" and "[step]" in units_row[:names]
    semicolons = _export(tmp_path, "semicolons").read_bytes().decode("utf-8")
    assert "\r\n" in semicolons and "Rotation radius:;5 mm" in semicolons
    lines = semicolons.splitlines()
    names = next(i for i, line in enumerate(lines) if line.startswith("Interval data:;"))
    assert lines[names + 1] == ";[];[s];[mrad];[N];[mN·m];[]"
    assert lines[names + 3].startswith(";2;0,01;")  # decimal commas


def test_an_export_in_si_units_gives_the_csv_friction_to_the_last_bit(tmp_path):
    # The brackets shape writes SI units with the same 9 significant digits as our CSV: the
    # same numbers, so the same friction, speed, distance and peak.
    trace = _trace(1)
    from_export = static_friction(
        read_rheometer_export(_export(tmp_path, "brackets", trace), _map("brackets"))
    )
    assert from_export == _csv_friction(tmp_path, trace)


@pytest.mark.parametrize("shape", ["units_row", "semicolons"])
def test_an_export_in_other_units_gives_the_csv_friction_to_1e_12(tmp_path, shape):
    # Both files hold the same 9 significant digits (decimal rounding commutes with the powers
    # of ten between mN·m and N·m, mrad and rad); the unit conversion adds one float rounding
    # (1e-16), which the medians and means carry to at most a few 1e-16: 1e-12 leaves room.
    trace = _trace(2)
    reference = _csv_friction(tmp_path, trace)
    read = read_rheometer_export(_export(tmp_path, shape, trace), _map(shape))
    assert read.rotation_radius_m == pytest.approx(5e-3, rel=1e-15)
    measured = static_friction(read)
    for field in dataclasses.fields(measured):
        assert getattr(measured, field.name) == pytest.approx(
            getattr(reference, field.name), rel=1e-12
        ), field.name


def test_separator_decimal_and_header_rows_set_in_config_read_as_detected(tmp_path):
    path = _export(tmp_path, "semicolons")
    detected = read_rheometer_export(path, _map("semicolons"))
    configured = read_rheometer_export(path, _map("semicolons", separator=";", decimal=","))
    np.testing.assert_array_equal(detected.torque_n_m, configured.torque_n_m)
    with pytest.raises(
        RheometerError,
        match=r"line 9, column '.*': '-?0,\d+' is not a number with the decimal mark '\.'",
    ):
        read_rheometer_export(path, _map("semicolons", decimal="."))
    tab = _export(tmp_path, "units_row")
    assert read_rheometer_export(tab, _map("units_row", separator="tab")).time_s.size == 2000


def test_units_come_from_the_file_where_the_map_names_none(tmp_path):
    config = EXPORT_SHAPES["semicolons"].column_map(RADIUS_MM)
    for channel in config["columns"].values():
        del channel["unit"]
    path = _export(tmp_path, "semicolons")
    assert np.array_equal(
        read_rheometer_export(path, ExportMap.from_config(config)).angle_rad,
        read_rheometer_export(path, _map("semicolons")).angle_rad,
    )


def test_the_rotation_radius_from_a_column_or_the_config(tmp_path):
    trace = _trace(3)
    path = _export(tmp_path, "brackets", trace)
    text = path.read_text(encoding="utf-8").splitlines()
    # add a constant 'Radius(mm)' column as some exports carry the geometry per point
    path.write_text("\n".join([text[0] + ",Radius(mm)"] + [t + ",5" for t in text[1:]]))
    config = EXPORT_SHAPES["brackets"].column_map()
    config["rotation_radius"] = {"column": "Radius"}
    assert read_rheometer_export(path, ExportMap.from_config(config)).rotation_radius_m == 5e-3
    config["rotation_radius"] = {"value": 4.0, "unit": "mm"}
    assert read_rheometer_export(path, ExportMap.from_config(config)).rotation_radius_m == 4e-3
    no_radius = ExportMap.from_config(EXPORT_SHAPES["brackets"].column_map())
    assert read_rheometer_export(path, no_radius).rotation_radius_m is None


@pytest.mark.parametrize("encoding", ["cp1252", "utf-16", "utf-8-sig"])
def test_windows_encodings_read_the_same(tmp_path, encoding):
    # µ (torque) and · are single bytes in cp1252; UTF-16 and UTF-8 files carry a BOM
    path = _export(tmp_path, "units_row")
    reference = read_rheometer_export(path, _map("units_row"))
    text = path.read_text(encoding="utf-8")
    raw = text.encode(encoding)
    if encoding == "utf-16":
        assert raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE))
    path.write_bytes(raw)
    np.testing.assert_array_equal(
        read_rheometer_export(path, _map("units_row")).torque_n_m, reference.torque_n_m
    )


def test_read_through_the_raw_data_reader_with_the_load_check(tmp_path):
    path = _export(tmp_path, "semicolons")
    (trace,) = read_rheometer_traces([path], [25.0], {"semicolons": _map("semicolons")})
    assert trace.normal_force_n.mean() == pytest.approx(LOAD_N, rel=0.01)
    with pytest.raises(RawDataError, match="mean normal force .* the sheet say 50 mN"):
        read_rheometer_traces([path], [50.0], {"semicolons": _map("semicolons")})


def test_the_layout_finds_exports_by_load(tmp_path):
    for load in (25, 50):
        write_rheometer_export(tmp_path / rheometer_name(load, ".txt"), _trace(), "units_row")
    assert [p.name for p in rheometer_files(tmp_path, [25.0, 50.0])] == ["25.txt", "50.txt"]
    write_rheometer_csv(tmp_path / "25.csv", _trace())
    with pytest.raises(RawDataError, match=r"two rheometer files for 25 mN \(25.csv, 25.txt\)"):
        rheometer_files(tmp_path, [25.0, 50.0])
    with pytest.raises(RawDataError, match="suffix '.xls'"):
        rheometer_name(25, ".xls")


# --- bad exports -------------------------------------------------------------------------------


def test_a_missing_mapped_column_names_it_and_lists_the_columns_the_file_has(tmp_path):
    path = _export(tmp_path, "semicolons")
    config = EXPORT_SHAPES["semicolons"].column_map(RADIUS_MM)
    config["columns"]["torque"]["column"] = "Drehmoment"
    with pytest.raises(RheometerError) as error:
        read_rheometer_export(path, ExportMap.from_config(config))
    message = str(error.value)
    assert str(path) in message and "no column 'Drehmoment' (the column map's torque)" in message
    assert "['Interval data:', 'Point No.', 'Time', 'Deflection Angle', 'Normal Force', " in message


def test_an_unknown_unit_in_the_file_is_refused_naming_the_column(tmp_path):
    path = _export(tmp_path, "semicolons")
    path.write_text(path.read_text(encoding="utf-8").replace("[mN·m]", "[kgf·cm]"), "utf-8")
    config = EXPORT_SHAPES["semicolons"].column_map(RADIUS_MM)
    del config["columns"]["torque"]["unit"]
    with pytest.raises(RheometerError, match=r"25.csv: column 'Torque' \(torque\): unknown torque"):
        read_rheometer_export(path, ExportMap.from_config(config))


def test_an_unknown_unit_in_the_map_is_refused_naming_the_key():
    config = EXPORT_SHAPES["semicolons"].column_map(RADIUS_MM)
    config["columns"]["angle"]["unit"] = "grad"
    with pytest.raises(ExportMapError, match=r"rheometer_export.columns.angle.unit: unknown angle"):
        ExportMap.from_config(config)


def test_a_unit_that_disagrees_with_the_map_is_refused(tmp_path):
    path = _export(tmp_path, "semicolons")
    with pytest.raises(RheometerError, match=r"'Torque' \(torque\) is in '\[mN·m\]'|in 'mN·m' in"):
        read_rheometer_export(
            path, _map("semicolons", columns=_columns("semicolons", torque="µN·m"))
        )


def _columns(shape, **units):
    columns = EXPORT_SHAPES[shape].column_map()["columns"]
    for channel, unit in units.items():
        columns[channel]["unit"] = unit
    return columns


@pytest.mark.parametrize(
    ("damage", "message"),
    [
        (lambda text: "", "empty file"),
        (lambda text: text.replace(";3;0,02;", ";3;0,02x;", 1), r"line \d+, column 'Time'"),
        (lambda text: "\r\n".join(text.splitlines()[:15]), "rows in the table .* at least 10"),
        (lambda text: text + text[text.index("Interval data:") :], "2 tables hold the mapped"),
        (lambda text: text.replace("Rotation radius:;5 mm", "Rotation radius:;five mm"), "five"),
    ],
    ids=["empty", "not-a-number", "too-few-rows", "two-tables", "bad-radius"],
)
def test_damaged_exports_are_refused_naming_the_file(tmp_path, damage, message):
    path = _export(tmp_path, "semicolons")
    path.write_text(damage(path.read_text(encoding="utf-8")), encoding="utf-8")
    with pytest.raises(RheometerError, match=message) as error:
        read_rheometer_export(path, _map("semicolons"))
    assert str(path) in str(error.value)


def test_a_binary_file_is_not_an_export(tmp_path):
    path = tmp_path / "25.csv"
    path.write_bytes(b"PK\x03\x04\x00\x00 an xlsx")
    with pytest.raises(RheometerError, match="binary data"):
        read_rheometer_export(path, _map("semicolons"))


@pytest.mark.parametrize(
    ("config", "message"),
    [
        ({"columns": {"time": "t"}}, "has no 'angle'"),
        ({"columns": _columns("brackets"), "separator": "|"}, r"separator = '\|'"),
        ({"columns": _columns("brackets"), "decimal": ";"}, "decimal = ';'"),
        ({"columns": _columns("brackets"), "table": 0}, r"table = 0; expected a table number"),
        ({"columns": _columns("brackets"), "encoding": "klingon"}, "encoding = 'klingon'"),
        ({"columns": _columns("brackets"), "rotation_radius": {"value": 5}}, "needs its unit"),
        (
            {"columns": _columns("brackets"), "rotation_radius": {"key": "R", "column": "R"}},
            "exactly one",
        ),
        ({"columns": _columns("brackets"), "radius": 5}, r"unknown keys \['radius'\]"),
    ],
    ids=[
        "missing-channel",
        "separator",
        "decimal",
        "table",
        "encoding",
        "unitless-radius",
        "two-radii",
        "unknown-key",
    ],
)
def test_a_bad_column_map_is_refused_naming_the_key(config, message):
    with pytest.raises(ExportMapError, match=message):
        ExportMap.from_config(config)
