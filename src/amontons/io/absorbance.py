"""Absorbance spectra of the probe cover slip: CSV with columns wavelength_nm, absorbance
(decadic, dimensionless), as a spectrophotometer exports them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from amontons.io.csv_columns import read_numeric_columns
from amontons.io.files import atomic_path

COLUMNS = ("wavelength_nm", "absorbance")


class AbsorbanceError(ValueError):
    """An absorbance spectrum from which no grafting density can be read."""


def read_absorbance_csv(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Wavelengths (nm) and absorbance from a CSV with columns wavelength_nm, absorbance.

    Raises AbsorbanceError naming the file for a missing column, non-numeric or non-finite
    values, or fewer than 10 rows.
    """
    path = Path(path)
    if not path.is_file():
        raise AbsorbanceError(f"{path}: no such absorbance spectrum")
    values = read_numeric_columns(
        path, COLUMNS, min_rows=10, record="a spectrum", error_type=AbsorbanceError
    )
    order = np.argsort(values["wavelength_nm"])
    return values["wavelength_nm"][order], values["absorbance"][order]


def write_absorbance_csv(path: str | Path, wavelengths_nm: np.ndarray, absorbance: np.ndarray):
    """Write the spectrum as CSV (wavelength_nm, absorbance), atomically."""
    table = pd.DataFrame({"wavelength_nm": wavelengths_nm, "absorbance": absorbance})
    with atomic_path(path) as tmp:
        table.to_csv(tmp, index=False, float_format="%.7g")
