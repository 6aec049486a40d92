"""Numeric columns of an instrument's CSV export, checked the same way for every format."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd


def read_numeric_columns(
    path: Path, columns: Sequence[str], *, min_rows: int, record: str, error_type: type[Exception]
) -> dict[str, np.ndarray]:
    """The ``columns`` of the CSV ``path`` ('#' lines are comments) as float arrays.

    Raises ``error_type`` naming the file for a file that is not a CSV table (empty, binary,
    not UTF-8), for a missing column (listing the ones found), for non-numeric or missing
    values in a column, or for fewer than ``min_rows`` rows (``record`` names what the rows
    make, e.g. "a spectrum").
    """
    if path.stat().st_size == 0:
        raise error_type(
            f"{path}: empty file; expected a CSV table with the columns {list(columns)}"
        )
    try:
        table = pd.read_csv(path, comment="#", encoding="utf-8")
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as error:
        reason = " ".join(str(error).split())
        raise error_type(
            f"{path}: not a readable CSV table ({type(error).__name__}: {reason}); expected "
            f"UTF-8 text with the columns {list(columns)}"
        ) from error
    for column in columns:
        if column not in table.columns:
            raise error_type(
                f"{path}: no column '{column}'; found {list(table.columns)}, expected "
                f"{list(columns)}"
            )
    values = {}
    for column in columns:
        numbers = pd.to_numeric(table[column], errors="coerce").to_numpy(dtype=float)
        if not np.all(np.isfinite(numbers)):
            bad = int(np.count_nonzero(~np.isfinite(numbers)))
            raise error_type(f"{path}: {bad} non-numeric or missing values in '{column}'")
        values[column] = numbers
    if len(table) < min_rows:
        raise error_type(f"{path}: {len(table)} rows; {record} needs at least {min_rows}")
    return values
