"""The config and the sample sheet against their JSON Schemas (workflow/schemas/): every
violation listed at once, each naming its key, the value and what was expected."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import jsonschema
import yaml

from amontons.config.errors import ConfigError
from amontons.models import field_model_names, model_names, parameter_keys, with_parameter


def load_schema(path: str | Path) -> dict:
    """Read a JSON Schema written as YAML, with what the contact models' records decide
    filled in (:func:`with_models`)."""
    with open(path) as stream:
        return with_models(yaml.safe_load(stream))


def _parameter_property(parameter) -> dict:
    return {
        "type": ["number", "null"],
        "exclusiveMinimum": 0,
        "description": f"{parameter.description}; null takes the sheet's {parameter.sheet_column}.",
    }


def _sheet_column_property(parameter) -> dict:
    return {
        "type": "number",
        "exclusiveMinimum": 0,
        "description": f"{parameter.description}, the prior of the scenes and scans of it.",
    }


def with_models(schema: dict) -> dict:
    """``schema`` with the contact models' records (amontons.models) filled in, in place:
    in the config schema, the allowed models of a scene and parameters of a scan, and each
    parameter as a scene key; in the sample sheet's, each parameter's column. A key the
    schema describes itself keeps its own description."""
    parameters = [m.parameter for m in with_parameter()]
    properties = schema.get("properties", {})
    if "scenes" in properties and "scans" in properties:
        scene = properties["scenes"]["additionalProperties"]
        scene["properties"]["model"]["enum"] = list(model_names())
        properties["scans"]["additionalProperties"]["properties"]["parameter"]["enum"] = list(
            parameter_keys()
        )
        for parameter in parameters:  # optional where the schema does not require it: null
            scene["properties"].setdefault(parameter.key, _parameter_property(parameter))
    elif "sphere" in properties:
        for parameter in parameters:
            properties.setdefault(parameter.sheet_column, _sheet_column_property(parameter))
        if "true_model" in properties:
            properties["true_model"]["enum"] = list(field_model_names())
    if "validation" in properties:
        _fill_validation(properties["validation"]["properties"], parameters)
    return schema


def _fill_validation(validation: dict, parameters: list) -> None:
    """The validation study's keys that the records decide: a truth's models (those solved on
    a grid) and its value's key, the priors' keys and the sheet spheres' values' keys, one
    per parameter, each required."""
    truth = validation["truths"]["additionalProperties"]["properties"]
    truth["model"]["enum"] = list(field_model_names())
    for parameter in parameters:
        truth.setdefault(parameter.key, _value_property(parameter, "a truth of its model"))
    values = validation["spheres"]["properties"]["values"]["additionalProperties"]
    for node, what in ((validation["priors"], "the scan's prior"), (values, "the truth's value")):
        node["required"] = [p.key for p in parameters]
        node.setdefault("properties", {})
        for parameter in parameters:
            node["properties"].setdefault(parameter.key, _value_property(parameter, what))


def _value_property(parameter, what: str) -> dict:
    return {
        "type": "number",
        "exclusiveMinimum": 0,
        "description": f"{parameter.description}: {what}",
    }


def _key_path(error: jsonschema.ValidationError) -> str:
    return ".".join(str(part) for part in error.absolute_path) or "<top level>"


def _schema_at(schema: Mapping, error: jsonschema.ValidationError) -> Mapping:
    node = schema
    for part in error.absolute_path:
        if isinstance(part, int):
            node = node.get("items", {})
        elif part in node.get("properties", {}):
            node = node["properties"][part]
        else:
            extra = node.get("additionalProperties")
            node = extra if isinstance(extra, Mapping) else {}
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
