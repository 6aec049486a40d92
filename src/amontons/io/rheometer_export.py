"""Rheometer tests as the instrument programs export them, read through a column map.

An export is a text table: an optional preamble of metadata lines (``key<sep>value``), a row
of column names, optionally a second row of units, then one row per sample. The programs
differ in the separator (comma, semicolon, tab), the decimal mark (a German locale writes
decimal commas), where the unit stands (in brackets after the name, ``Torque(N m)`` or
``Torque [mN·m]``, or on the row below the names) and their column names. The
:class:`ExportMap` (from config) names, for time, plate angle (or deflection angle), normal
force and torque, the export's column and, optionally, its unit; optionally where the
rotation radius stands (a preamble key, a column, or a value in the config). The separator,
the decimal mark, the header and unit rows are detected, or set by the map.

Units go through the one table of :mod:`amontons.io.units`. The reader returns the same
:class:`RheometerTrace` (SI units) as our own CSV (:mod:`amontons.io.rheometer`), so the
friction measurement does not know which file it came from.

:data:`EXPORT_SHAPES` are three export shapes written the way the programs write them
(modelled on Malvern rSpace, TA TRIOS and Anton Paar RheoCompass in a German locale), each
with its writer and its column map: the virtual experiment writes them and the tests read them.
"""

from __future__ import annotations

import codecs
import csv
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from amontons.io.files import atomic_path
from amontons.io.rheometer import RheometerError, RheometerTrace
from amontons.io.units import UnitError, canonical_unit, si_factor

# The four channels of a friction test and the quantity (amontons.io.units) of each.
CHANNELS = {"time": "time", "angle": "angle", "normal_force": "force", "torque": "torque"}
SEPARATORS = {"tab": "\t", "\t": "\t", ";": ";", ",": ","}
DECIMALS = (".", ",")
MIN_ROWS = 10  # as our own CSV (amontons.io.rheometer): a friction trace needs a record
_NUMBER = re.compile(r"^[+-]?(\d+([.,]\d*)?|[.,]\d+)([eE][+-]?\d+)?$")
_COMMA_NUMBER = re.compile(r"^[+-]?\d*,\d+([eE][+-]?\d+)?$")
_VALUE_WITH_UNIT = re.compile(r"^([+-]?(?:\d+(?:[.,]\d*)?|[.,]\d+)(?:[eE][+-]?\d+)?)\s*(.*)$")
_NAME_WITH_UNIT = re.compile(r"^(.*?)\s*[\[(]([^\[\]()]*)[\])]$")


class ExportMapError(ValueError):
    """A column map (config) that cannot describe an export."""


@dataclass(frozen=True)
class MappedColumn:
    """One channel's column in the export: its name as the header writes it (without a
    bracketed unit) and its unit (canonical; None: the unit the file gives)."""

    column: str
    unit: str | None


@dataclass(frozen=True)
class RadiusSource:
    """Where the rotation radius stands: a preamble ``key``, a ``column`` (one value), or a
    ``value`` given in the config; ``unit`` a length unit (None: the file's own)."""

    key: str | None = None
    column: str | None = None
    value: float | None = None
    unit: str | None = None


@dataclass(frozen=True)
class ExportMap:
    """How to read one program's export (config ``rheometer_export``; config/README.md).

    ``columns``: time, angle, normal_force, torque; ``separator`` one of ``,``, ``;``, tab
    (None: detected); ``decimal`` ``.`` or ``,`` (None: detected); ``table`` the 1-based
    table to read where several tables (intervals, steps) hold the columns; ``encoding`` of
    the text (None: a byte-order mark, else UTF-8, else Windows-1252).
    """

    columns: Mapping[str, MappedColumn]
    rotation_radius: RadiusSource | None = None
    separator: str | None = None
    decimal: str | None = None
    table: int | None = None
    encoding: str | None = None

    @classmethod
    def from_config(cls, config: Mapping, where: str = "rheometer_export") -> ExportMap:
        """The map from its config slice (plain data); raises ExportMapError naming the key
        (``where`` and below), the value and what was expected, an unknown unit included."""
        if not isinstance(config, Mapping):
            raise ExportMapError(f"{where} = {config!r}; expected a mapping with 'columns'")
        known = {"columns", "rotation_radius", "separator", "decimal", "table", "encoding"}
        _no_other_keys(config, known, where)
        columns_config = config.get("columns")
        if not isinstance(columns_config, Mapping):
            raise ExportMapError(
                f"{where}.columns = {columns_config!r}; expected a mapping of "
                f"{', '.join(CHANNELS)} to {{column, unit}}"
            )
        _no_other_keys(columns_config, set(CHANNELS), f"{where}.columns")
        columns = {}
        for channel, quantity in CHANNELS.items():
            if channel not in columns_config:
                raise ExportMapError(
                    f"{where}.columns has no '{channel}'; expected {{column, unit}} for each of "
                    f"{', '.join(CHANNELS)}"
                )
            columns[channel] = _mapped_column(
                columns_config[channel], quantity, f"{where}.columns.{channel}"
            )
        separator = _choice(config, "separator", SEPARATORS, where)
        decimal = _choice(config, "decimal", {d: d for d in DECIMALS}, where)
        table = config.get("table")
        whole = isinstance(table, int) and not isinstance(table, bool)
        if table is not None and (not whole or table < 1):
            raise ExportMapError(f"{where}.table = {table!r}; expected a table number ≥ 1")
        encoding = config.get("encoding")
        if encoding is not None:
            try:
                codecs.lookup(encoding)
            except (LookupError, TypeError) as error:
                raise ExportMapError(
                    f"{where}.encoding = {encoding!r}; expected a text encoding such as utf-8, "
                    "utf-16 or cp1252"
                ) from error
        radius = config.get("rotation_radius")
        return cls(
            columns=columns,
            rotation_radius=None
            if radius is None
            else _radius_source(radius, f"{where}.rotation_radius"),
            separator=separator,
            decimal=decimal,
            table=table,
            encoding=encoding,
        )


def _no_other_keys(config: Mapping, known: set[str], where: str) -> None:
    unknown = sorted(set(config) - known)
    if unknown:
        raise ExportMapError(f"{where}: unknown keys {unknown}; expected some of {sorted(known)}")


def _choice(config: Mapping, key: str, allowed: Mapping[str, str], where: str) -> str | None:
    value = config.get(key, "auto")
    if value == "auto":
        return None
    if value not in allowed:
        raise ExportMapError(
            f"{where}.{key} = {value!r}; expected 'auto' or one of {sorted(set(allowed))}"
        )
    return allowed[value]


def _checked_unit(unit, quantity: str, where: str) -> str | None:
    if unit is None:
        return None
    if not isinstance(unit, str):
        raise ExportMapError(f"{where}.unit = {unit!r}; expected a {quantity} unit as text")
    try:
        si_factor(unit, quantity)
    except UnitError as error:
        raise ExportMapError(f"{where}.unit: {error}") from error
    return canonical_unit(unit)


def _mapped_column(config, quantity: str, where: str) -> MappedColumn:
    if isinstance(config, str):
        config = {"column": config}
    if not isinstance(config, Mapping) or not isinstance(config.get("column"), str):
        raise ExportMapError(
            f"{where} = {config!r}; expected {{column: <the export's column name>, unit: <its "
            f"{quantity} unit, optional>}}"
        )
    _no_other_keys(config, {"column", "unit"}, where)
    return MappedColumn(config["column"], _checked_unit(config.get("unit"), quantity, where))


def _radius_source(config, where: str) -> RadiusSource:
    if not isinstance(config, Mapping):
        raise ExportMapError(
            f"{where} = {config!r}; expected one of {{key: <preamble key>}}, {{column: <name>}} "
            "or {value: <number>}, with a length unit"
        )
    _no_other_keys(config, {"key", "column", "value", "unit"}, where)
    given = [name for name in ("key", "column", "value") if config.get(name) is not None]
    if len(given) != 1:
        raise ExportMapError(
            f"{where} gives {given or 'none'} of key, column, value; expected exactly one"
        )
    value = config.get("value")
    if value is not None and (
        isinstance(value, bool) or not isinstance(value, int | float) or not value > 0
    ):
        raise ExportMapError(f"{where}.value = {value!r}; expected a positive length")
    unit = _checked_unit(config.get("unit"), "length", where)
    if value is not None and unit is None:
        raise ExportMapError(f"{where}: a value needs its unit (e.g. unit: mm)")
    return RadiusSource(
        key=config.get("key"),
        column=config.get("column"),
        value=None if value is None else float(value),
        unit=unit,
    )


# --- reading -----------------------------------------------------------------------------------


def _decode(path: Path, encoding: str | None) -> str:
    if not path.is_file():
        raise RheometerError(f"{path}: no such rheometer export")
    raw = path.read_bytes()
    if not raw.strip():
        raise RheometerError(f"{path}: empty file; expected a rheometer export (text table)")
    if encoding is None:
        if raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
            encoding = "utf-16"
        elif raw.startswith(codecs.BOM_UTF8):
            encoding = "utf-8-sig"
        elif b"\x00" in raw:
            raise RheometerError(
                f"{path}: binary data (NUL bytes) without a UTF-16 byte-order mark; expected a "
                "text export of the rheometer program"
            )
        else:
            try:
                return raw.decode("utf-8")
            except UnicodeDecodeError:
                # Windows programs write their 'ANSI' code page, where µ, · and ° are single bytes
                encoding = "cp1252"
    try:
        return raw.decode(encoding)
    except UnicodeDecodeError as error:
        raise RheometerError(
            f"{path}: not {encoding} text ({error.reason} at byte {error.start}); set "
            "rheometer_export.encoding to the export's encoding"
        ) from error


def _cells(line: str, separator: str) -> list[str]:
    return [cell.strip() for cell in next(csv.reader([line], delimiter=separator))]


def _same_name(a: str, b: str) -> bool:
    return " ".join(a.split()).casefold() == " ".join(b.split()).casefold()


def _find_in_header(cells: list[str], column: str) -> tuple[int, str | None] | None:
    """Index of the header cell naming ``column``, and the unit in brackets after the name."""
    for index, cell in enumerate(cells):
        if _same_name(cell, column):
            return index, None
        named = _NAME_WITH_UNIT.match(cell)
        if named and _same_name(named.group(1), column):
            return index, named.group(2)
    return None


@dataclass(frozen=True)
class _Header:
    line: int
    separator: str
    cells: list[str]
    positions: dict[str, int]
    units: dict[str, str | None]


def _headers(lines: list[str], names: dict[str, str], separators) -> list[_Header]:
    """Every line that names all of ``names`` (channel → column) under one separator."""
    found = []
    for number, line in enumerate(lines):
        best = None
        for separator in separators:
            if separator not in line:
                continue
            cells = _cells(line, separator)
            hits = {channel: _find_in_header(cells, name) for channel, name in names.items()}
            if all(hits.values()) and (best is None or len(cells) > len(best.cells)):
                best = _Header(
                    number,
                    separator,
                    cells,
                    {c: hit[0] for c, hit in hits.items()},
                    {c: hit[1] for c, hit in hits.items()},
                )
        if best is not None:
            found.append(best)
    return found


def _missing_column(path: Path, lines: list[str], export: ExportMap, separators) -> RheometerError:
    """The error for a file in which no line names every mapped column: the columns of the
    line that names most of them (else the widest line) and the first one missing."""
    names = {c: m.column for c, m in export.columns.items()}
    best_cells, best_hits = [], -1
    for line in lines[:500]:
        for separator in separators:
            if separator not in line:
                continue
            cells = _cells(line, separator)
            if all(_NUMBER.match(c) or not c for c in cells):
                continue
            hits = sum(_find_in_header(cells, name) is not None for name in names.values())
            if (hits, len(cells)) > (best_hits, len(best_cells)):
                best_cells, best_hits = cells, hits
    absent = [(c, name) for c, name in names.items() if not _find_in_header(best_cells, name)]
    missing = absent[0] if absent else next(iter(names.items()))
    return RheometerError(
        f"{path}: no column '{missing[1]}' (the column map's {missing[0]}); the file's columns "
        f"are {[c for c in best_cells if c]}"
    )


def _unit_row(lines: list[str], header: _Header) -> dict[str, str | None] | None:
    """The units on the row below the names, if that row holds text where the columns are."""
    if header.line + 1 >= len(lines):
        return None
    cells = _cells(lines[header.line + 1], header.separator)
    found = {c: cells[i] if i < len(cells) else "" for c, i in header.positions.items()}
    if any(_NUMBER.match(text) for text in found.values()) or not any(found.values()):
        return None
    return {c: (text or None) for c, text in found.items()}


def _parse_number(text: str, decimal: str) -> float | None:
    if not _NUMBER.match(text):
        return None
    if decimal == ",":
        if "." in text:
            return None
        text = text.replace(",", ".")
    elif "," in text:
        return None
    return float(text)


def _detect_decimal(rows: list[list[str]], positions: Mapping[str, int], separator: str) -> str:
    if separator == ",":
        return "."
    for cells in rows[:50]:
        for index in positions.values():
            if index < len(cells) and _COMMA_NUMBER.match(cells[index]):
                return ","
    return "."


def _table(
    path: Path, lines: list[str], header: _Header, first: int, decimal: str | None
) -> tuple[dict[str, np.ndarray], str]:
    """The mapped columns' values from line ``first`` to the table's end (a blank line, or a
    line with no number where the columns are: a new section), and the decimal mark used."""
    rows, numbers = [], []
    for line in lines[first:]:
        if not line.strip():
            break
        cells = _cells(line, header.separator)
        texts = [cells[i] if i < len(cells) else "" for i in header.positions.values()]
        if not any(_NUMBER.match(text) for text in texts):
            break
        rows.append(cells)
        numbers.append(len(numbers) + first + 1)
    mark = decimal or _detect_decimal(rows, header.positions, header.separator)
    values = {channel: np.empty(len(rows)) for channel in header.positions}
    for row, (cells, line_number) in enumerate(zip(rows, numbers, strict=True)):
        for channel, index in header.positions.items():
            text = cells[index] if index < len(cells) else ""
            number = _parse_number(text, mark)
            if number is None or not np.isfinite(number):
                raise RheometerError(
                    f"{path}: line {line_number}, column '{header.cells[index]}': {text!r} is not "
                    f"a number with the decimal mark '{mark}'; expected a finite number in every "
                    "row of the table"
                )
            values[channel][row] = number
    return values, mark


def _unit_factor(
    path: Path, channel: str, column: str, mapped: str | None, in_file: str | None
) -> tuple[float, str]:
    quantity = CHANNELS.get(channel, "length")
    if mapped is None and in_file is None:
        raise RheometerError(
            f"{path}: no unit for column '{column}' ({channel}) in the file, and none in the "
            "column map; expected the map to name one"
        )
    if mapped is not None and in_file is not None and canonical_unit(in_file) != mapped:
        try:
            same = si_factor(in_file, quantity) == si_factor(mapped, quantity)
        except UnitError:
            same = False
        if not same:
            raise RheometerError(
                f"{path}: column '{column}' ({channel}) is in {in_file!r} in the file but in "
                f"'{mapped}' in the column map; expected them to agree"
            )
    unit = mapped if mapped is not None else in_file
    try:
        return si_factor(unit, quantity), canonical_unit(unit)
    except UnitError as error:
        raise RheometerError(f"{path}: column '{column}' ({channel}): {error}") from error


def _preamble(lines: list[str], separator: str) -> dict[str, str]:
    metadata = {}
    for line in lines:
        cells = [c for c in _cells(line, separator) if c] if line.strip() else []
        if len(cells) >= 2:
            metadata[cells[0].rstrip(":").strip()] = cells[1]
    return metadata


def _radius(
    path: Path,
    source: RadiusSource,
    metadata: Mapping[str, str],
    table: Mapping[str, np.ndarray],
    column_unit: str | None,
    mark: str,
) -> float:
    """The rotation radius (m) from where the map says it stands (``column_unit``: the unit
    the file gives a radius column)."""
    if source.value is not None:
        return source.value * si_factor(source.unit, "length")
    if source.column is not None:
        values = table["rotation_radius"]
        if np.ptp(values) > 1e-9 * np.abs(values).max():
            raise RheometerError(
                f"{path}: column '{source.column}' (rotation radius) varies from {values.min():g} "
                f"to {values.max():g}; expected one radius for the test"
            )
        factor, _ = _unit_factor(path, "rotation_radius", source.column, source.unit, column_unit)
        radius = float(values[0]) * factor
    else:
        key = next((k for k in metadata if _same_name(k, source.key)), None)
        if key is None:
            raise RheometerError(
                f"{path}: no preamble line '{source.key}' (the column map's rotation radius); "
                f"the preamble has {list(metadata)}"
            )
        parsed = _VALUE_WITH_UNIT.match(metadata[key])
        number = None if parsed is None else _parse_number(parsed.group(1), mark)
        if number is None:
            raise RheometerError(
                f"{path}: '{key}' = {metadata[key]!r}; expected a rotation radius, a number "
                "with its length unit"
            )
        unit_in_file = parsed.group(2).strip() or None
        factor, _ = _unit_factor(path, "rotation_radius", key, source.unit, unit_in_file)
        radius = number * factor
    if not np.isfinite(radius) or radius <= 0:
        raise RheometerError(f"{path}: rotation radius {radius:g} m; expected a positive length")
    return radius


def read_rheometer_export(path: str | Path, export: ExportMap) -> RheometerTrace:
    """One load's friction test from the program's export ``path``, read through ``export``.

    Returns the trace in SI units (s, rad, N, N·m) with the rotation radius where the map says
    it stands (else None: the caller supplies it) and the preamble as metadata. Raises
    RheometerError naming the file for a file that is not a text table, a mapped column the
    file does not have (listing the columns it has), several tables holding the columns where
    the map does not choose one, a unit that is unknown or disagrees with the map, a value
    that is not a number, or fewer than MIN_ROWS rows.
    """
    path = Path(path)
    lines = _decode(path, export.encoding).splitlines()
    separators = [export.separator] if export.separator else ["\t", ";", ","]
    names = {channel: mapped.column for channel, mapped in export.columns.items()}
    radius_source = export.rotation_radius
    if radius_source is not None and radius_source.column is not None:
        names["rotation_radius"] = radius_source.column
    headers = _headers(lines, names, separators)
    if not headers:
        raise _missing_column(path, lines, export, separators)
    if export.table is None and len(headers) > 1:
        raise RheometerError(
            f"{path}: {len(headers)} tables hold the mapped columns (header lines "
            f"{[h.line + 1 for h in headers]}); set rheometer_export.table to the friction test's"
        )
    if export.table is not None and export.table > len(headers):
        raise RheometerError(
            f"{path}: rheometer_export.table = {export.table}, but {len(headers)} tables hold "
            "the mapped columns"
        )
    header = headers[(export.table or 1) - 1]
    unit_row = _unit_row(lines, header)
    first = header.line + (2 if unit_row else 1)
    table, mark = _table(path, lines, header, first, export.decimal)
    rows = next(iter(table.values())).size
    if rows < MIN_ROWS:
        raise RheometerError(
            f"{path}: {rows} rows in the table below line {header.line + 1}; a friction trace "
            f"needs at least {MIN_ROWS}"
        )
    in_file = {c: header.units[c] or (unit_row or {}).get(c) for c in header.positions}
    si, units = {}, {}
    for channel, mapped in export.columns.items():
        factor, units[channel] = _unit_factor(
            path, channel, mapped.column, mapped.unit, in_file[channel]
        )
        si[channel] = table[channel] * factor
    metadata = _preamble(lines[: header.line], header.separator)
    radius = None
    if radius_source is not None:
        column_unit = in_file.get("rotation_radius")
        radius = _radius(path, radius_source, metadata, table, column_unit, mark)
    metadata.update({f"unit_{channel}": unit for channel, unit in units.items()})
    return RheometerTrace(
        time_s=si["time"],
        angle_rad=si["angle"],
        normal_force_n=si["normal_force"],
        torque_n_m=si["torque"],
        rotation_radius_m=radius,
        metadata=metadata,
        source=str(path),
    )


# --- writing: three export shapes --------------------------------------------------------------


def _number(value: float, decimal: str) -> str:
    # 9 significant digits, as our own CSV (amontons.io.rheometer): decimal rounding commutes
    # with the powers of ten between units, so both files hold the same digits
    text = f"{value:.9g}"
    return text.replace(".", ",") if decimal == "," else text


def _columns_in_units(trace: RheometerTrace, units: Mapping[str, str]) -> dict[str, np.ndarray]:
    si = {
        "time": trace.time_s,
        "angle": trace.angle_rad,
        "normal_force": trace.normal_force_n,
        "torque": trace.torque_n_m,
    }
    return {c: np.asarray(si[c]) / si_factor(units[c], CHANNELS[c]) for c in CHANNELS}


def _radius_mm(trace: RheometerTrace, path: Path) -> float:
    if trace.rotation_radius_m is None:
        raise RheometerError(f"{path}: trace has no rotation radius to write")
    return trace.rotation_radius_m * 1e3


@dataclass(frozen=True)
class ExportShape:
    """One program's export: its column names and units, how it lays them out, and where it
    keeps the rotation radius (``radius_key`` in the preamble, or None: not in the file)."""

    description: str
    names: Mapping[str, str]
    units: Mapping[str, str]
    radius_key: str | None
    suffix: str
    write_lines: Callable[[ExportShape, RheometerTrace, Path], list[str]]

    def column_map(self, rotation_radius_mm: float | None = None) -> dict:
        """The column map (config data, :meth:`ExportMap.from_config`) that reads this shape;
        a shape without the radius in its file takes ``rotation_radius_mm`` as a value."""
        config: dict = {
            "columns": {c: {"column": self.names[c], "unit": self.units[c]} for c in CHANNELS}
        }
        if self.radius_key is not None:
            config["rotation_radius"] = {"key": self.radius_key, "unit": "mm"}
        elif rotation_radius_mm is not None:
            config["rotation_radius"] = {"value": rotation_radius_mm, "unit": "mm"}
        return config


def _brackets_lines(shape: ExportShape, trace: RheometerTrace, path: Path) -> list[str]:
    """Units in brackets after each name, comma-separated, decimal points, no preamble; a
    first column of text (the program's action name)."""
    values = _columns_in_units(trace, shape.units)
    header = ["Action Name"] + [f"{shape.names[c]}({shape.units[c]})" for c in CHANNELS]
    rows = [
        ",".join(["Friction test"] + [_number(values[c][i], ".") for c in CHANNELS])
        for i in range(trace.time_s.size)
    ]
    return [",".join(header), *rows]


def _unit_row_lines(shape: ExportShape, trace: RheometerTrace, path: Path) -> list[str]:
    """Tab-separated: a preamble of ``key<tab>value`` lines with the geometry, a ``[step]``
    section with the step's name, the names row, then the units row below it."""
    values = _columns_in_units(trace, shape.units)
    preamble = [
        "Filename\t" + path.stem,
        "Instrument name\tvirtual rheometer",
        *[f"{key}\t{value}" for key, value in trace.metadata.items()],
        "[Geometry Parameters]",
        f"{shape.radius_key}\t{_radius_mm(trace, path):.6g} mm",
        "[step]",
        "Friction - 1",
    ]
    rows = [
        "\t".join(_number(values[c][i], ".") for c in CHANNELS) for i in range(trace.time_s.size)
    ]
    return [
        *preamble,
        "\t".join(shape.names[c] for c in CHANNELS),
        "\t".join(shape.units[c] for c in CHANNELS),
        *rows,
    ]


def _semicolon_lines(shape: ExportShape, trace: RheometerTrace, path: Path) -> list[str]:
    """Semicolons and decimal commas (a German locale): a preamble of ``key:;value`` lines,
    the names row after an ``Interval data:`` cell with a point number and a status column,
    the units in brackets on the row below, then one row per point."""
    values = _columns_in_units(trace, shape.units)
    radius = _number(_radius_mm(trace, path), ",")
    n = trace.time_s.size
    preamble = [
        "Project:;Friction",
        f"Test:;{path.stem}",
        *[f"{key}:;{value}" for key, value in trace.metadata.items()],
        f"{shape.radius_key}:;{radius} mm",
        f"Interval and data points:;1;{n}",
    ]
    names = ["Interval data:", "Point No."] + [shape.names[c] for c in CHANNELS] + ["Status"]
    units = ["", "[]"] + [f"[{shape.units[c]}]" for c in CHANNELS] + ["[]"]
    rows = [
        ";".join(["", str(i + 1)] + [_number(values[c][i], ",") for c in CHANNELS] + ["Dy_auto"])
        for i in range(n)
    ]
    return [*preamble, ";".join(names), ";".join(units), *rows]


EXPORT_SHAPES: dict[str, ExportShape] = {
    "brackets": ExportShape(
        description="units in brackets after the names (modelled on Malvern rSpace)",
        names={
            "time": "Time (action)",
            "angle": "Angular displacement",
            "normal_force": "Normal force",
            "torque": "Torque",
        },
        units={"time": "s", "angle": "rad", "normal_force": "N", "torque": "N m"},
        radius_key=None,
        suffix=".csv",
        write_lines=_brackets_lines,
    ),
    "units_row": ExportShape(
        description="units on a second header row, tab-separated (modelled on TA TRIOS)",
        names={
            "time": "Step time",
            "angle": "Displacement",
            "normal_force": "Axial force",
            "torque": "Torque",
        },
        units={"time": "s", "angle": "mrad", "normal_force": "N", "torque": "µN.m"},
        radius_key="Rotation radius",
        suffix=".txt",
        write_lines=_unit_row_lines,
    ),
    "semicolons": ExportShape(
        description="semicolons and decimal commas with a metadata preamble and units in "
        "brackets on a second row (modelled on Anton Paar RheoCompass, German locale)",
        names={
            "time": "Time",
            "angle": "Deflection Angle",
            "normal_force": "Normal Force",
            "torque": "Torque",
        },
        units={"time": "s", "angle": "mrad", "normal_force": "N", "torque": "mN·m"},
        radius_key="Rotation radius",
        suffix=".csv",
        write_lines=_semicolon_lines,
    ),
}


def write_rheometer_export(path: str | Path, trace: RheometerTrace, shape: str) -> None:
    """Write ``trace`` as the program of ``shape`` (a key of EXPORT_SHAPES) exports it,
    atomically (UTF-8, the programs' CRLF line ends)."""
    if shape not in EXPORT_SHAPES:
        raise ValueError(f"unknown export shape '{shape}'; expected one of {list(EXPORT_SHAPES)}")
    path = Path(path)
    lines = EXPORT_SHAPES[shape].write_lines(EXPORT_SHAPES[shape], trace, path)
    with atomic_path(path) as tmp:
        tmp.write_bytes(("\r\n".join(lines) + "\r\n").encode("utf-8"))
