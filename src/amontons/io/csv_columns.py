"""Numeric columns of an instrument's CSV export, checked the same way for every format."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd


def read_numeric_columns(
    path: Path, columns: Sequence[str], *, min_rows: int, record: str, error: type[Exception]
) -> dict[str, np.ndarray]:
    """The ``columns`` of the CSV ``path`` ('#' lines are comments) as float arrays.

    Raises ``error`` naming the file for a missing column (listing the ones found), for
    non-numeric or missing values in a column, or for fewer than ``min_rows`` rows (``record``
    names what the rows make, e.g. "a spectrum").
    """
    table = pd.read_csv(path, comment="#")
    for column in columns:
        if column not in table.columns:
            raise error(
                f"{path}: no column '{column}'; found {list(table.columns)}, expected "
                f"{list(columns)}"
            )
    values = {}
    for column in columns:
        numbers = pd.to_numeric(table[column], errors="coerce").to_numpy(dtype=float)
        if not np.all(np.isfinite(numbers)):
            bad = int(np.count_nonzero(~np.isfinite(numbers)))
            raise error(f"{path}: {bad} non-numeric or missing values in '{column}'")
        values[column] = numbers
    if len(table) < min_rows:
        raise error(f"{path}: {len(table)} rows; {record} needs at least {min_rows}")
    return values
