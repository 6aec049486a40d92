"""Atomic writes of records (JSON) and tables (CSV): a file is either complete or absent.

Standard library only: the workflow's helpers import it without the numerical stack.
"""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; move it into place only if the block succeeds."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=path.suffix)
    os.close(handle)
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def write_json(path: str | Path, record: Mapping[str, Any]) -> None:
    """Write ``record`` as indented JSON, atomically. Refuses NaN and infinities (JSON has
    none; a silent ``NaN`` token would not parse elsewhere): use None for a missing value."""
    text = json.dumps(record, indent=2, allow_nan=False)
    with atomic_path(path) as tmp:
        tmp.write_text(text)


def read_json(path: str | Path) -> dict:
    """Read a JSON record written by :func:`write_json`."""
    with open(path, encoding="utf-8") as stream:
        return json.load(stream)


def write_table(path: str | Path, table: Any) -> None:
    """Write a pandas DataFrame as CSV without its index, atomically."""
    with atomic_path(path) as tmp:
        table.to_csv(tmp, index=False)
