"""Validation of the workflow configuration and the sample sheet, with messages a user can act on.

JSON Schema (via ``jsonschema``) checks structure and types; the checks that a schema cannot
express (strictly increasing loads, unique sphere ids, materials present in the sheet) live here
too, so that every bad configuration fails before any job runs and names the key, the value and
what was expected.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import jsonschema
import pandas as pd
import yaml


class ConfigError(ValueError):
    """A configuration or sample-sheet value is not what the workflow expects."""


def load_schema(path: str | Path) -> dict:
    """Read a JSON Schema written as YAML."""
    with open(path) as stream:
        return yaml.safe_load(stream)


def _key_path(error: jsonschema.ValidationError) -> str:
    return ".".join(str(part) for part in error.absolute_path) or "<top level>"


def _schema_at(schema: Mapping, error: jsonschema.ValidationError) -> Mapping:
    node = schema
    for part in error.absolute_path:
        if isinstance(part, int):
            node = node.get("items", {})
        else:
            node = node.get("properties", {}).get(part, {})
    return node


def _describe(error: jsonschema.ValidationError, schema: Mapping) -> str:
    where = _key_path(error)
    if error.validator == "additionalProperties":
        allowed = sorted(_schema_at(schema, error).get("properties", {}))
        unknown = sorted(set(error.instance) - set(allowed))
        return (
            f"unknown key(s) {', '.join(repr(k) for k in unknown)} in {where}; "
            f"allowed keys: {', '.join(allowed)}"
        )
    if error.validator == "enum":
        allowed = ", ".join(repr(v) for v in error.validator_value)
        return f"{where} = {error.instance!r} is not allowed; allowed values: {allowed}"
    if error.validator == "required":
        return f"{where}: {error.message}"
    description = error.schema.get("description", "")
    expected = f" (expected: {description})" if description else ""
    return f"{where} = {error.instance!r}: {error.message}{expected}"


def validate(data: Mapping, schema: Mapping, source: str) -> None:
    """Raise ConfigError listing every schema violation of ``data``, each naming its key.

    ``source`` names the file the data came from, for the message.
    """
    validator = jsonschema.Draft202012Validator(schema)
    errors = sorted(validator.iter_errors(data), key=lambda e: list(map(str, e.absolute_path)))
    if errors:
        lines = "\n  ".join(_describe(e, schema) for e in errors)
        raise ConfigError(f"{source}: invalid configuration\n  {lines}")


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


_BOOLEAN_WORDS = {"true": True, "false": False, "yes": True, "no": False, "1": True, "0": False}


def _row_record(row: pd.Series) -> dict:
    record = {}
    for key, value in row.items():
        if pd.isna(value):
            continue
        record[key] = value.item() if hasattr(value, "item") else value
    if isinstance(record.get("roughened"), str):
        word = record["roughened"].strip().lower()
        record["roughened"] = _BOOLEAN_WORDS.get(word, record["roughened"])
    if "loads_mn" in record:
        record["loads_mn"] = str(record["loads_mn"])
    return record


def read_sample_sheet(path: str | Path, schema: Mapping) -> pd.DataFrame:
    """Read and validate the sample sheet (TSV, one row per sphere), indexed by sphere id.

    Adds a ``loads`` column holding each row's loads as a list of floats in mN.
    """
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"materials_sheet = {str(path)!r}: no such file")
    table = pd.read_csv(path, sep="\t", dtype={"loads_mn": str, "sphere": str}, comment="#")
    records = []
    for line, (_, row) in enumerate(table.iterrows(), start=2):
        record = _row_record(row)
        validate(record, schema, f"{path}, line {line} (sphere {record.get('sphere')!r})")
        record["loads"] = parse_loads_mn(record["loads_mn"], f"{path}, sphere {record['sphere']}")
        records.append(record)
    sheet = pd.DataFrame.from_records(records)
    duplicated = sorted(set(sheet["sphere"][sheet["sphere"].duplicated()]))
    if duplicated:
        raise ConfigError(f"{path}: sphere ids must be unique; repeated: {', '.join(duplicated)}")
    return sheet.set_index("sphere", drop=False)


def check_selected_materials(selected: Sequence[str], sheet: pd.DataFrame, source: str) -> None:
    """Every material named in the config's ``materials`` must have a row in the sheet."""
    known = sorted(set(sheet["material"]))
    unknown = [m for m in selected if m not in known]
    if unknown:
        raise ConfigError(
            f"{source}: materials = {list(selected)} names unknown material(s) "
            f"{', '.join(repr(m) for m in unknown)}; allowed values (from the sample sheet): "
            f"{', '.join(known)}"
        )


def load_workflow_config(
    config: Mapping, config_schema: Mapping, sheet_schema: Mapping, source: str
) -> pd.DataFrame:
    """Validate a config mapping and its sample sheet; return the sheet rows of the selected
    materials."""
    validate(config, config_schema, source)
    sheet = read_sample_sheet(config["materials_sheet"], sheet_schema)
    check_selected_materials(config["materials"], sheet, source)
    return sheet[sheet["material"].isin(config["materials"])]
