"""Atomic writes of records (JSON) and tables (CSV): a file is either complete or absent,
and a writer killed mid-write leaves no temporary behind for good (:func:`atomic_path`).

Standard library only: the workflow's helpers import it without the numerical stack.
"""

from __future__ import annotations

import contextlib
import glob
import json
import os
import socket
import tempfile
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; move it into place only if the block succeeds.

    The temporary is named ``.<name>.<host>-<pid>.<random><suffix>``: a writer killed before
    it could clean up (SIGKILL, a node lost) leaves it behind, and the next write of ``path``
    on the same host removes it once that process is gone (:func:`remove_stale_temporaries`).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    remove_stale_temporaries(path)
    handle, tmp = tempfile.mkstemp(
        dir=path.parent, prefix=f"{_temporary_prefix(path)}{os.getpid()}.", suffix=path.suffix
    )
    os.close(handle)
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def _temporary_prefix(path: Path) -> str:
    """The start of the name of every temporary of ``path`` written on this host."""
    return f".{path.name}.{socket.gethostname()}-"


def remove_stale_temporaries(path: str | Path) -> list[Path]:
    """Remove the temporaries of ``path`` (:func:`atomic_path`) whose writer on this host is
    no longer running, and return them. A temporary of a live process, or of another host
    (whose processes this one cannot see), is left alone."""
    path = Path(path)
    prefix = _temporary_prefix(path)
    removed = []
    for candidate in path.parent.glob(f"{glob.escape(prefix)}*{glob.escape(path.suffix)}"):
        pid_text = candidate.name[len(prefix) :].split(".", 1)[0]
        if pid_text.isdigit() and not _running(int(pid_text)):
            with contextlib.suppress(FileNotFoundError):
                candidate.unlink()
            removed.append(candidate)
    return removed


def _running(pid: int) -> bool:
    """Whether process ``pid`` exists on this host (one of another user's counts)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


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
