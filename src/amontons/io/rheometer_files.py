"""Which reader reads a rheometer file: our own CSV, or one of the config's export maps,
chosen by what the file holds (config/README.md, "Rheometer exports").

1. A file laid out as our own CSV (a column row naming time_s, angle_rad, normal_force_N,
   torque_N_m; :mod:`amontons.io.rheometer`) reads as our CSV, whatever maps the config has.
2. Else the first of the export maps (config ``rheometer_export``, one map or several named
   ones, :func:`amontons.io.export_map.export_maps`; a sheet row may name the one its sphere
   takes) whose columns a line of the file names (:mod:`amontons.io.rheometer_export`).
3. Else the file matches no reader: RheometerError naming the file, every reader tried with
   the columns it looks for, and the columns the file has.

So one config reads a lab's two rheometers, or one program's exports beside our CSVs.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from amontons.io.export_map import ExportMap
from amontons.io.rheometer import (
    COLUMNS,
    RheometerError,
    RheometerTrace,
    has_own_columns,
    read_rheometer_csv,
)
from amontons.io.rheometer_export import holds_mapped_columns, read_rheometer_export, table_columns

# The reader of our own CSV, as choose_reader names it.
OWN_CSV = "csv"


def reader_label(reader: str) -> str:
    """How messages and the data check name a reader: 'our CSV' or "export map 'name'"."""
    return "our CSV" if reader == OWN_CSV else f"export map '{reader}'"


def choose_reader(path: str | Path, maps: Mapping[str, ExportMap]) -> str:
    """The reader of the rheometer file ``path``: :data:`OWN_CSV`, or the name of the first
    of ``maps`` (name → map, in the config's order) whose columns the file names. Raises
    RheometerError naming the file where it is missing, empty or not text, or where no
    reader takes it (each reader tried with its columns, and the file's columns)."""
    path = Path(path)
    if not path.is_file():
        raise RheometerError(f"{path}: no such rheometer file")
    if path.stat().st_size == 0:
        raise RheometerError(
            f"{path}: empty file; expected our rheometer CSV ({', '.join(COLUMNS)}) or a "
            "rheometer program's export"
        )
    if has_own_columns(path):
        return OWN_CSV
    for name, export in maps.items():
        if holds_mapped_columns(path, export):
            return name
    tried = [f"our CSV ({', '.join(COLUMNS)})"] + [
        f"{reader_label(name)} ({', '.join(m.column for m in export.columns.values())})"
        for name, export in maps.items()
    ]
    raise RheometerError(
        f"{path}: matches no rheometer reader: tried {'; '.join(tried)}; the file's columns "
        f"are {table_columns(path)}; expected our CSV's columns, or an export map for its "
        "program in the config's rheometer_export"
    )


def read_rheometer_file(
    path: str | Path, maps: Mapping[str, ExportMap]
) -> tuple[str, RheometerTrace]:
    """The reader :func:`choose_reader` gives ``path``, and the trace it reads (SI units)."""
    reader = choose_reader(path, maps)
    if reader == OWN_CSV:
        return reader, read_rheometer_csv(path)
    return reader, read_rheometer_export(path, maps[reader])
