"""The configuration reference: config/README.md's key table and sample-sheet column table,
generated from the ``description`` of every key in the JSON Schemas (workflow/schemas/), so that
each key is described in one place. The schema's words are also what a validation error quotes
(:func:`amontons.config.schema.validate`).

    python -m amontons.config.reference            # print both tables
    python -m amontons.config.reference --write    # rewrite them in config/README.md
    python -m amontons.config.reference --check    # exit 1 where config/README.md is stale

A row names a key by its path: ``optics.psf.stand_in``; a ``<name>`` segment is any key of a
mapping of named entries (the schema's ``additionalProperties``; its ``propertyNames`` may give
the placeholder a ``title``, e.g. ``<preset>``), and ``[]`` an item of a list (``items``). Every
described key gets a row, depth-first in schema order; an ``enum`` that the description does not
spell out in backticks (the contact models, filled in by :func:`load_schema`) is appended.
tests/test_config_reference.py holds the README's tables to this rendering.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import NamedTuple

from amontons.config.schema import load_schema

# A clone or an editable install: src/amontons/config/reference.py -> the repository.
ROOT = Path(__file__).resolve().parents[3]
CONFIG_SCHEMA = Path("workflow/schemas/config.schema.yaml")
SHEET_SCHEMA = Path("workflow/schemas/materials.schema.yaml")
README = Path("config/README.md")

END = "<!-- end of generated table -->"


def begin_marker(schema_path: Path) -> str:
    """The comment that opens the table generated from ``schema_path`` in config/README.md."""
    return (
        f"<!-- generated from {schema_path.as_posix()} by python -m amontons.config.reference; "
        "edit the schema, not this table -->"
    )


class Row(NamedTuple):
    key: str  # e.g. "scenes.<name>.model"
    description: str  # as rendered: one line, allowed values appended where not named


def _join(path: str, segment: str) -> str:
    if segment == "[]":
        return path + segment
    return f"{path}.{segment}" if path else segment


def _placeholder(node: Mapping) -> str:
    names = node.get("propertyNames")
    title = names.get("title", "name") if isinstance(names, Mapping) else "name"
    return f"<{title}>"


def _entries(node: Mapping) -> Iterator[tuple[str, Mapping]]:
    """``node``'s keys as (segment, schema), in schema order: its properties (and those of an
    object among its ``oneOf``/``anyOf`` branches, e.g. ``load_series``), any named entry
    (``<name>``) and the item of a list of mappings (``[]``)."""
    seen = set()
    branches = [node, *node.get("oneOf", []), *node.get("anyOf", [])]
    for branch in branches:
        for key, child in branch.get("properties", {}).items():
            if key not in seen:
                seen.add(key)
                yield key, child
    extra = node.get("additionalProperties")
    if isinstance(extra, Mapping):
        yield _placeholder(node), extra
    items = node.get("items")
    if isinstance(items, Mapping) and (
        items.get("properties") or isinstance(items.get("additionalProperties"), Mapping)
    ):
        yield "[]", items


def _literal(value) -> str:
    return value if isinstance(value, str) else json.dumps(value)


def describe(node: Mapping) -> str:
    """``node``'s description on one line, with its allowed values appended where it does not
    name each of them in backticks."""
    text = " ".join(str(node.get("description", "")).split())
    items = node.get("items")
    allowed = node.get("enum") or (items.get("enum") if isinstance(items, Mapping) else None)
    named = [f"`{_literal(value)}`" for value in allowed or []]
    if any(name not in text for name in named):
        text += "; allowed values: " + ", ".join(named)
    return text


def rows(schema: Mapping) -> list[Row]:
    """A row per key of ``schema`` (a loaded schema, :func:`load_schema`), depth-first in
    schema order. A key without a description raises ValueError naming it."""
    found: list[Row] = []

    def visit(node: Mapping, path: str) -> None:
        for segment, child in _entries(node):
            key = _join(path, segment)
            if not child.get("description"):
                raise ValueError(f"{key}: the schema gives no description")
            found.append(Row(key, describe(child)))
            visit(child, key)

    visit(schema, "")
    return found


def row_key(schema: Mapping, parts: Sequence[str | int]) -> str:
    """The key of the row that describes the config key at ``parts`` (e.g. ``["scenes",
    "elastic", "model"]`` -> ``scenes.<name>.model``; a list index reads as ``[]``). Inside a
    value the schema leaves free (``rheometer_export``'s map), that value's own row. A key
    the schema does not have raises KeyError."""
    node, key = schema, ""
    for part in parts:
        entries = dict(_entries(node))
        if not entries:
            return key
        if isinstance(part, int):
            segment = "[]"
        elif part in entries:
            segment = part
        else:
            segment = next((s for s in entries if s.startswith("<")), "")
        if segment not in entries:
            raise KeyError(f"{_join(key, str(part))}: not a key of the schema")
        node, key = entries[segment], _join(key, segment)
    return key


def _cell(text: str) -> str:
    """``text`` for a Markdown table cell: pipes escaped, and outside code spans the asterisks
    (E*) and tag-like angle brackets."""
    parts = re.split(r"(`[^`]*`)", text)
    for i in range(0, len(parts), 2):
        parts[i] = re.sub(r"<(?=[A-Za-z/])", r"\\<", parts[i].replace("*", r"\*"))
    return "".join(parts).replace("|", r"\|")


def table(schema: Mapping, heading: str) -> str:
    """``schema``'s rows as a Markdown table whose first column is headed ``heading``."""
    lines = [f"| {heading} | meaning |", "| --- | --- |"]
    lines += [f"| `{row.key}` | {_cell(row.description)} |" for row in rows(schema)]
    return "\n".join(lines)


def key_table(config_schema: Mapping) -> str:
    """config/README.md's key table: every key of the workflow configuration."""
    return table(config_schema, "key")


def column_table(sheet_schema: Mapping) -> str:
    """config/README.md's column table: every column of the sample sheet."""
    return table(sheet_schema, "column")


def _block(schema_path: Path, body: str) -> str:
    return f"{begin_marker(schema_path)}\n\n{body}\n\n{END}"


def _span(text: str, schema_path: Path) -> tuple[int, int]:
    begin = text.find(begin_marker(schema_path))
    end = text.find(END, begin)
    if begin < 0 or end < 0:
        raise ValueError(f"{README}: no table between {begin_marker(schema_path)!r} and {END!r}")
    return begin, end + len(END)


def generated(text: str, schema_path: Path) -> str:
    """The table between ``schema_path``'s markers in the README text ``text``."""
    begin, end = _span(text, schema_path)
    block = text[begin:end]
    return block[len(begin_marker(schema_path)) : -len(END)].strip()


def with_tables(text: str, tables: Mapping[Path, str]) -> str:
    """The README text ``text`` with each table (by the schema it is generated from) put
    between that schema's markers; the prose around them stays."""
    for schema_path, body in tables.items():
        begin, end = _span(text, schema_path)
        text = text[:begin] + _block(schema_path, body) + text[end:]
    return text


def tables(root: Path = ROOT) -> dict[Path, str]:
    """Both tables, rendered from the schemas under ``root``, by the schema's path."""
    return {
        CONFIG_SCHEMA: key_table(load_schema(root / CONFIG_SCHEMA)),
        SHEET_SCHEMA: column_table(load_schema(root / SHEET_SCHEMA)),
    }


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help=f"rewrite the tables in {README}")
    parser.add_argument("--check", action="store_true", help=f"exit 1 where {README} is stale")
    parser.add_argument(
        "--root", type=Path, default=ROOT, help="the repository (default: %(default)s)"
    )
    args = parser.parse_args(argv)
    rendered = tables(args.root)
    if not (args.write or args.check):
        print("\n\n".join(rendered.values()))
        return 0
    readme = args.root / README
    text = readme.read_text(encoding="utf-8")
    updated = with_tables(text, rendered)
    if args.check:
        if updated != text:
            print(f"{README} is stale: run python -m amontons.config.reference --write")
            return 1
        return 0
    if updated != text:
        readme.write_text(updated, encoding="utf-8")
    print(f"{README}: {'rewritten' if updated != text else 'up to date'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
