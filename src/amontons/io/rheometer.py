"""Rheometer torque logs: one CSV per normal load (``<folder>/rheometer/<load in mN>.csv``).

Leading comment lines ``# key: value`` with at least ``# rotation_radius_mm: <value>``, then
the columns time_s, angle_rad, normal_force_N, torque_N_m (SI units in the column names).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from amontons.io.csv_columns import read_numeric_columns
from amontons.io.files import atomic_path

COLUMNS = ("time_s", "angle_rad", "normal_force_N", "torque_N_m")
RADIUS_KEY = "rotation_radius_mm"


class RheometerError(ValueError):
    """A rheometer file or trace from which no friction force can be read."""


@dataclass(frozen=True)
class RheometerTrace:
    """One load's record: time (s), plate angle (rad), normal force (N), torque (N·m)."""

    time_s: np.ndarray
    angle_rad: np.ndarray
    normal_force_n: np.ndarray
    torque_n_m: np.ndarray
    rotation_radius_m: float | None = None
    metadata: dict[str, str] = field(default_factory=dict)
    source: str = "<memory>"


def _metadata(lines: list[str]) -> dict[str, str]:
    metadata = {}
    for line in lines:
        body = line.lstrip("#").strip()
        if ":" in body:
            key, value = body.split(":", 1)
            metadata[key.strip()] = value.strip()
    return metadata


def has_own_columns(path: str | Path) -> bool:
    """Whether ``path`` is laid out as our own CSV: its first line after the ``#`` header
    names one of :data:`COLUMNS` or more (the reader then says which are missing). False for
    a file that is not UTF-8 text or cannot be opened."""
    try:
        with Path(path).open(encoding="utf-8") as handle:
            for line in handle:
                if line.startswith("#") or not line.strip():
                    continue
                return bool({cell.strip() for cell in line.split(",")} & set(COLUMNS))
    except (OSError, UnicodeDecodeError):
        return False
    return False


def read_rheometer_csv(path: str | Path) -> RheometerTrace:
    """Read one load's rheometer CSV with its '# key: value' header.

    Raises RheometerError naming the file for a missing column, missing or invalid
    rotation-radius metadata, non-numeric values, or fewer than 10 rows.
    """
    path = Path(path)
    if not path.is_file():
        raise RheometerError(f"{path}: no such rheometer file")
    if path.stat().st_size == 0:
        raise RheometerError(f"{path}: empty file; expected a rheometer CSV ({', '.join(COLUMNS)})")
    header = []
    try:
        with path.open(encoding="utf-8") as handle:
            for line in handle:
                if not line.startswith("#"):
                    break
                header.append(line)
    except UnicodeDecodeError as error:
        raise RheometerError(
            f"{path}: not UTF-8 text ({error.reason} at byte {error.start}); expected a "
            "rheometer CSV saved as UTF-8"
        ) from error
    metadata = _metadata(header)
    radius_m = _radius_from_metadata(path, metadata)
    columns = read_numeric_columns(
        path, COLUMNS, min_rows=10, record="a friction trace", error_type=RheometerError
    )
    return RheometerTrace(
        time_s=columns["time_s"],
        angle_rad=columns["angle_rad"],
        normal_force_n=columns["normal_force_N"],
        torque_n_m=columns["torque_N_m"],
        rotation_radius_m=radius_m,
        metadata=metadata,
        source=str(path),
    )


def _radius_from_metadata(path: Path, metadata: dict[str, str]) -> float:
    if RADIUS_KEY not in metadata:
        raise RheometerError(
            f"{path}: no '# {RADIUS_KEY}: <value>' line in the header; the rotation radius "
            "is needed to turn torque into force"
        )
    try:
        radius_mm = float(metadata[RADIUS_KEY])
    except ValueError:
        radius_mm = float("nan")
    if not np.isfinite(radius_mm) or radius_mm <= 0:
        raise RheometerError(
            f"{path}: {RADIUS_KEY} = '{metadata[RADIUS_KEY]}'; expected a positive number of mm"
        )
    return radius_mm * 1e-3


def write_rheometer_csv(path: str | Path, trace: RheometerTrace) -> None:
    """Write a trace in the rheometer CSV layout, radius and metadata in the header, atomically."""
    if trace.rotation_radius_m is None:
        raise RheometerError(f"{path}: trace has no rotation radius to write")
    metadata = {**trace.metadata, RADIUS_KEY: f"{trace.rotation_radius_m * 1e3:.6g}"}
    table = pd.DataFrame(
        {
            "time_s": trace.time_s,
            "angle_rad": trace.angle_rad,
            "normal_force_N": trace.normal_force_n,
            "torque_N_m": trace.torque_n_m,
        }
    )
    with atomic_path(path) as tmp, tmp.open("w", encoding="utf-8") as handle:
        for key, value in metadata.items():
            handle.write(f"# {key}: {value}\n")
        table.to_csv(handle, index=False, float_format="%.9g")
