"""The stamp of a sphere's data: a digest of what its jobs read from outside the run, so
that a changed file, sheet row or config lets a failed sphere back into the tables
(amontons.workflow.ledger)."""

from __future__ import annotations

import hashlib
import json
import os

from amontons.io.layout import folder_files
from amontons.workflow.optional_inputs import ABSORBANCE, BEAD
from amontons.workflow.sheet_rows import SheetRows

# Sheet columns that name a file shared by many spheres, in place of the sphere's own.
SHARED_FILE_COLUMNS = {BEAD: "bead_file", ABSORBANCE: "absorbance_file"}


def data_stamp(rows: SheetRows, sphere: str, salt: str = "") -> str:
    """A digest of what a sphere's jobs read from outside the run: its sheet row and, for
    each file of its raw folder and each shared file its row names, the path, size and
    modification time; ``salt`` is mixed in (the run's config digest)."""
    row = rows.row(sphere)
    digest = hashlib.sha256(salt.encode())
    digest.update(json.dumps(row, sort_keys=True, default=str).encode())
    shared = [row.get(column) for column in SHARED_FILE_COLUMNS.values()]
    for path in folder_files(rows.raw_dir(sphere)) + [p for p in shared if p]:
        if os.path.isfile(path):
            stat = os.stat(path)
            digest.update(f"{path}\0{stat.st_size}\0{stat.st_mtime_ns}\n".encode())
    return digest.hexdigest()
