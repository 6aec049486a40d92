"""Rheometer tests as the instrument programs export them, read through a column map.

An export is a text table: an optional preamble of metadata lines (``key<sep>value``), a row
of column names, optionally a second row of units, then one row per sample. The programs
differ in the separator (comma, semicolon, tab), the decimal mark (a German locale writes
decimal commas), where the unit stands (in brackets after the name, ``Torque(N m)`` or
``Torque [mN·m]``, or on the row below the names) and their column names. The column map
(:class:`amontons.io.export_map.ExportMap`, from config) names each channel's column and unit
and where the rotation radius stands; the separator, the decimal mark, the header and unit
rows are detected, or set by the map.

Units go through the one table of :mod:`amontons.io.units`. The reader returns the same
:class:`RheometerTrace` (SI units) as our own CSV (:mod:`amontons.io.rheometer`), so the
friction measurement does not know which file it came from. The programs' export shapes that
the virtual experiment writes are :mod:`amontons.io.rheometer_export_shapes`.
"""

from __future__ import annotations

import codecs
import csv
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from amontons.io.export_map import CHANNELS, ExportMap, RadiusSource
from amontons.io.rheometer import RheometerError, RheometerTrace
from amontons.io.units import UnitError, canonical_unit, si_factor

MIN_ROWS = 10  # as our own CSV (amontons.io.rheometer): a friction trace needs a record
_NUMBER = re.compile(r"^[+-]?(\d+([.,]\d*)?|[.,]\d+)([eE][+-]?\d+)?$")
_COMMA_NUMBER = re.compile(r"^[+-]?\d*,\d+([eE][+-]?\d+)?$")
_VALUE_WITH_UNIT = re.compile(r"^([+-]?(?:\d+(?:[.,]\d*)?|[.,]\d+)(?:[eE][+-]?\d+)?)\s*(.*)$")
_NAME_WITH_UNIT = re.compile(r"^(.*?)\s*[\[(]([^\[\]()]*)[\])]$")


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


def _separators(export: ExportMap) -> list[str]:
    return [export.separator] if export.separator else ["\t", ";", ","]


def _names(export: ExportMap) -> dict[str, str]:
    """Channel (and rotation_radius where it is a column) → the export's column name."""
    names = {channel: mapped.column for channel, mapped in export.columns.items()}
    radius_source = export.rotation_radius
    if radius_source is not None and radius_source.column is not None:
        names["rotation_radius"] = radius_source.column
    return names


def holds_mapped_columns(path: str | Path, export: ExportMap) -> bool:
    """Whether a line of the text file ``path`` names every column of ``export``: the map
    reads it. False for a file that is not text in the map's encoding."""
    try:
        lines = _decode(Path(path), export.encoding).splitlines()
    except RheometerError:
        return False
    return bool(_headers(lines, _names(export), _separators(export)))


def table_columns(path: str | Path) -> list[str]:
    """The column names a text table ``path`` seems to have: of its first 500 lines, the one
    with the most cells that are not all numbers (under a tab, a semicolon or a comma), for
    an error that says what the file holds. Raises RheometerError naming the file where it
    is not text."""
    lines = _decode(Path(path), None).splitlines()
    best: list[str] = []
    for line in lines[:500]:
        if line.startswith("#"):
            continue
        for separator in ("\t", ";", ","):
            if separator not in line:
                continue
            cells = _cells(line, separator)
            if all(_NUMBER.match(c) or not c for c in cells):
                continue
            if len(cells) > len(best):
                best = cells
    return [cell for cell in best if cell]


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
    separators = _separators(export)
    radius_source = export.rotation_radius
    headers = _headers(lines, _names(export), separators)
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
