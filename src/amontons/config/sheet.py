"""The sample sheet (config/materials.tsv): one row per sphere, read, typed and checked before
any job: loads strictly increasing, unique sphere ids, selected materials present and not named
like a workflow target. Standard library and jsonschema only: the workflow reads it to build
its DAG."""

from __future__ import annotations

import csv
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

from amontons.config.errors import ConfigError
from amontons.config.schema import validate


def parse_loads_mn(text: str, where: str) -> list[float]:
    """Parse a comma-separated, strictly increasing list of positive loads in mN."""
    try:
        loads = [float(part) for part in str(text).split(",")]
    except ValueError as exc:
        raise ConfigError(
            f"{where}: loads_mn = {text!r} is not a comma-separated list of numbers"
        ) from exc
    if any(load <= 0 for load in loads):
        raise ConfigError(f"{where}: loads_mn = {text!r}; every load must be positive (mN)")
    steps = [b - a for a, b in zip(loads, loads[1:], strict=False)]
    if any(step <= 0 for step in steps):
        raise ConfigError(
            f"{where}: loads_mn = {text!r} is not strictly increasing; loads are stepped upward "
            "and carry plastic history, so list them in increasing order without repeats"
        )
    return loads


# A power-law fit with standard errors (load-area, intensity-pressure) needs this many loads.
MIN_LOADS = 3
_BOOLEAN_WORDS = {"true": True, "false": False, "yes": True, "no": False, "1": True, "0": False}
# Names of the workflow's wildcard-free target rules: a material of the same name would make a
# second rule of that name (each material gets its own target, `snakemake PS`).
RESERVED_NAMES = frozenset(
    {"all", "optics", "surface", "friction", "fits", "figures", "virtual_experiment", "scenes"}
    | {"scans", "study", "accuracy", "validation", "validation_spheres"}
    | {"synthetic"}  # the folder of the synthetic scenes, results/<run>/synthetic/
)


def _typed(value: str, kind: str | None):
    """A sheet cell as the schema's type: numbers stay text when they do not parse, so that
    the schema names the cell rather than this function."""
    if kind in ("number", "integer"):
        try:
            number = float(value)
        except ValueError:
            return value
        return int(number) if kind == "integer" and number.is_integer() else number
    if kind == "boolean":
        return _BOOLEAN_WORDS.get(value.strip().lower(), value)
    return value


def _row_record(row: Mapping[str, str], schema: Mapping) -> dict:
    """A sheet row without its empty cells, each value of the schema's type."""
    properties = schema.get("properties", {})
    record = {}
    for key, value in row.items():
        if value is None or value.strip() == "":
            continue
        record[key] = _typed(value.strip(), properties.get(key, {}).get("type"))
    return record


def _sheet_rows(path: Path) -> list[dict[str, str]]:
    """The sheet's rows (tab-separated, '#' comment lines skipped) with their line numbers."""
    with open(path, encoding="utf-8", newline="") as stream:
        lines = [(n, line) for n, line in enumerate(stream, start=1) if not line.startswith("#")]
    reader = csv.DictReader((line for _, line in lines), delimiter="\t")
    rows = []
    for (number, _), row in zip(lines[1:], reader, strict=False):
        if None in row:
            raise ConfigError(f"{path}, line {number}: more cells than columns: {row[None]}")
        rows.append({"_line": number, **row})
    return rows


def check_sheet_loads(sphere: str, record: Mapping, where: str) -> None:
    """The reflection and FLIM loads of a sphere must be among its loads_mn."""
    for column in ("reflection_load_mn", "flim_load_mn"):
        value = record.get(column)
        if value is None:
            continue
        if not any(abs(float(value) - load) < 1e-9 for load in record["loads"]):
            raise ConfigError(
                f"{where}, sphere {sphere}: {column} = {value:g} is not one of loads_mn "
                f"{record['loads']}; expected the load of an existing image"
            )


def check_enough_loads(sphere: str, record: Mapping, where: str) -> None:
    """A sphere needs at least MIN_LOADS loads: its load-area and intensity-pressure power
    laws are fitted with standard errors."""
    if len(record["loads"]) < MIN_LOADS:
        raise ConfigError(
            f"{where}, sphere {sphere}: loads_mn = {record['loads_mn']!r} holds "
            f"{len(record['loads'])} load(s); expected at least {MIN_LOADS}, since the "
            "load-area and intensity-pressure power laws are fitted with standard errors"
        )


def check_reference_load(reference_mn: float, spheres: Mapping[str, dict], source: str) -> None:
    """The load at which areas and friction are normalised must be one of every selected
    sphere's loads (the figures divide by the area and friction measured there)."""
    for sphere, record in spheres.items():
        if not any(abs(reference_mn - load) < 1e-9 for load in record["loads"]):
            raise ConfigError(
                f"{source}: load_area.reference_load_mn = {reference_mn:g} mN is not one of "
                f"sphere {sphere}'s loads_mn {record['loads']} mN; expected a load that every "
                "selected sphere was measured at"
            )


def read_sample_sheet(path: str | Path, schema: Mapping) -> dict[str, dict]:
    """Read and validate the sample sheet (TSV, one row per sphere): sphere id → its record,
    in the sheet's order, each value of its schema type.

    Adds ``loads``, each row's loads as a list of floats in mN. Standard library only, so
    that the workflow builds its DAG without the numerical stack.
    """
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"materials_sheet = {str(path)!r}: no such file")
    sheet: dict[str, dict] = {}
    repeated = []
    for row in _sheet_rows(path):
        line = row.pop("_line")
        record = _row_record(row, schema)
        validate(record, schema, f"{path}, line {line} (sphere {record.get('sphere')!r})")
        record["loads"] = parse_loads_mn(record["loads_mn"], f"{path}, sphere {record['sphere']}")
        check_sheet_loads(record["sphere"], record, str(path))
        check_enough_loads(record["sphere"], record, str(path))
        if record["sphere"] in sheet:
            repeated.append(record["sphere"])
        sheet[record["sphere"]] = record
    if repeated:
        raise ConfigError(
            f"{path}: sphere ids must be unique; repeated: {', '.join(sorted(set(repeated)))}"
        )
    return sheet


def check_selected_materials(selected: Sequence[str], sheet: Mapping[str, dict], source: str):
    """Every material named in the config's ``materials`` must have a row in the sheet, and
    none may take the name of a workflow target."""
    known = sorted({record["material"] for record in sheet.values()})
    unknown = [m for m in selected if m not in known]
    if unknown:
        raise ConfigError(
            f"{source}: materials = {list(selected)} names unknown material(s) "
            f"{', '.join(repr(m) for m in unknown)}; allowed values (from the sample sheet): "
            f"{', '.join(known)}"
        )
    reserved = [m for m in selected if m in RESERVED_NAMES]
    if reserved:
        raise ConfigError(
            f"{source}: material(s) {', '.join(repr(m) for m in reserved)} take the name of a "
            f"workflow target; rename them in the sample sheet (reserved: "
            f"{', '.join(sorted(RESERVED_NAMES))})"
        )


# Sheet columns that name a raw file shared by many spheres (config/README.md).
SHARED_FILE_COLUMNS = ("bead_file", "absorbance_file")


def check_shared_files(sheet: Mapping[str, dict], source: str | Path) -> None:
    """A shared file the sheet names must exist (a path from the project folder): a typo
    stops the run here rather than quietly leaving the spheres without it."""
    for sphere, record in sheet.items():
        for column in SHARED_FILE_COLUMNS:
            path = record.get(column)
            if path is not None and not os.path.isfile(path):
                raise ConfigError(
                    f"{source}, sphere {sphere}: {column} = {path!r} is not a file; expected "
                    f"the path of a file shared by several spheres, from the project folder"
                )
