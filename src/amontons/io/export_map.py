"""The column map of a rheometer program's export (config ``rheometer_export``;
config/README.md, "Rheometer exports"): for time, plate angle, normal force and torque the
export's column and, optionally, its unit; optionally where the rotation radius stands (a
preamble key, a column, or a value in the config); and the separator, decimal mark, table and
encoding where they are not to be detected.

:func:`export_maps` reads the config's value: none, one map, or several named maps (one per
program a lab exports from; amontons.io.rheometer_files chooses among them per file). Standard
library only: the workflow checks a config's maps, and a sheet's choice of one, before any job.
"""

from __future__ import annotations

import codecs
from collections.abc import Mapping
from dataclasses import dataclass

from amontons.io.units import UnitError, canonical_unit, si_factor

# The four channels of a friction test and the quantity (amontons.io.units) of each.
CHANNELS = {"time": "time", "angle": "angle", "normal_force": "force", "torque": "torque"}
SEPARATORS = {"tab": "\t", "\t": "\t", ";": ";", ",": ","}
DECIMALS = (".", ",")
# The name a single map (config rheometer_export with its own 'columns') goes by, and the
# keys of a map.
SINGLE_MAP_NAME = "export"
MAP_KEYS = frozenset({"columns", "rotation_radius", "separator", "decimal", "table", "encoding"})


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
        _no_other_keys(config, set(MAP_KEYS), where)
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


def export_maps(config, where: str = "rheometer_export") -> dict[str, ExportMap]:
    """The export maps of the config's ``rheometer_export`` (plain data), by name, in the
    config's order: none for null; a map's own keys (``columns``, ``rotation_radius``, ...)
    make one map named :data:`SINGLE_MAP_NAME`, and every other key names a map of its own.
    Both may stand side by side: a config file that adds named maps over config/config.yaml's
    single one (Snakemake merges the files key by key) keeps that one as ``export``. Raises
    ExportMapError naming the key, the value and what was expected."""
    if config is None:
        return {}
    if not isinstance(config, Mapping) or not config:
        raise ExportMapError(
            f"{where} = {config!r}; expected null, one column map (with 'columns'), or named "
            "maps {<name>: {columns: ...}, ...}"
        )
    own = {key: value for key, value in config.items() if key in MAP_KEYS}
    maps = {}
    if own:
        if "columns" not in own:
            raise ExportMapError(
                f"{where} has {sorted(own)} but no 'columns'; expected one column map (with "
                "'columns') or named maps {<name>: {columns: ...}, ...}"
            )
        maps[SINGLE_MAP_NAME] = ExportMap.from_config(own, where)
    for name, value in config.items():
        if name in MAP_KEYS:
            continue
        if name == SINGLE_MAP_NAME and own:
            raise ExportMapError(
                f"{where}.{name}: the name of the single map given by {where}'s own keys; "
                "expected another name"
            )
        maps[str(name)] = ExportMap.from_config(value, f"{where}.{name}")
    return maps
