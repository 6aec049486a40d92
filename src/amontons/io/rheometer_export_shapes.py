"""Three rheometer export shapes, written the way the programs write them (modelled on
Malvern rSpace, TA TRIOS and Anton Paar RheoCompass in a German locale), each with its column
map: the virtual experiment writes them, and the tests read them back through
:mod:`amontons.io.rheometer_export`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from amontons.io.export_map import CHANNELS
from amontons.io.files import atomic_path
from amontons.io.rheometer import RheometerError, RheometerTrace
from amontons.io.units import si_factor


def _number(value: float, decimal: str) -> str:
    # 9 significant digits, as our own CSV (amontons.io.rheometer): decimal rounding commutes
    # with the powers of ten between units, so both files hold the same digits
    text = f"{value:.9g}"
    return text.replace(".", ",") if decimal == "," else text


def _columns_in_units(trace: RheometerTrace, units: Mapping[str, str]) -> dict[str, np.ndarray]:
    si = {
        "time": trace.time_s,
        "angle": trace.angle_rad,
        "normal_force": trace.normal_force_n,
        "torque": trace.torque_n_m,
    }
    return {c: np.asarray(si[c]) / si_factor(units[c], CHANNELS[c]) for c in CHANNELS}


def _radius_mm(trace: RheometerTrace, path: Path) -> float:
    if trace.rotation_radius_m is None:
        raise RheometerError(f"{path}: trace has no rotation radius to write")
    return trace.rotation_radius_m * 1e3


@dataclass(frozen=True)
class ExportShape:
    """One program's export: its column names and units, how it lays them out, and where it
    keeps the rotation radius (``radius_key`` in the preamble, or None: not in the file)."""

    description: str
    names: Mapping[str, str]
    units: Mapping[str, str]
    radius_key: str | None
    suffix: str
    write_lines: Callable[[ExportShape, RheometerTrace, Path], list[str]]

    def column_map(self, rotation_radius_mm: float | None = None) -> dict:
        """The column map (config data,
        :meth:`amontons.io.export_map.ExportMap.from_config`) that reads this shape; a shape
        without the radius in its file takes ``rotation_radius_mm`` as a value."""
        config: dict = {
            "columns": {c: {"column": self.names[c], "unit": self.units[c]} for c in CHANNELS}
        }
        if self.radius_key is not None:
            config["rotation_radius"] = {"key": self.radius_key, "unit": "mm"}
        elif rotation_radius_mm is not None:
            config["rotation_radius"] = {"value": rotation_radius_mm, "unit": "mm"}
        return config


def _brackets_lines(shape: ExportShape, trace: RheometerTrace, path: Path) -> list[str]:
    """Units in brackets after each name, comma-separated, decimal points, no preamble; a
    first column of text (the program's action name)."""
    values = _columns_in_units(trace, shape.units)
    header = ["Action Name"] + [f"{shape.names[c]}({shape.units[c]})" for c in CHANNELS]
    rows = [
        ",".join(["Friction test"] + [_number(values[c][i], ".") for c in CHANNELS])
        for i in range(trace.time_s.size)
    ]
    return [",".join(header), *rows]


def _unit_row_lines(shape: ExportShape, trace: RheometerTrace, path: Path) -> list[str]:
    """Tab-separated: a preamble of ``key<tab>value`` lines with the geometry, a ``[step]``
    section with the step's name, the names row, then the units row below it."""
    values = _columns_in_units(trace, shape.units)
    preamble = [
        "Filename\t" + path.stem,
        "Instrument name\tvirtual rheometer",
        *[f"{key}\t{value}" for key, value in trace.metadata.items()],
        "[Geometry Parameters]",
        f"{shape.radius_key}\t{_radius_mm(trace, path):.6g} mm",
        "[step]",
        "Friction - 1",
    ]
    rows = [
        "\t".join(_number(values[c][i], ".") for c in CHANNELS) for i in range(trace.time_s.size)
    ]
    return [
        *preamble,
        "\t".join(shape.names[c] for c in CHANNELS),
        "\t".join(shape.units[c] for c in CHANNELS),
        *rows,
    ]


def _semicolon_lines(shape: ExportShape, trace: RheometerTrace, path: Path) -> list[str]:
    """Semicolons and decimal commas (a German locale): a preamble of ``key:;value`` lines,
    the names row after an ``Interval data:`` cell with a point number and a status column,
    the units in brackets on the row below, then one row per point."""
    values = _columns_in_units(trace, shape.units)
    radius = _number(_radius_mm(trace, path), ",")
    n = trace.time_s.size
    preamble = [
        "Project:;Friction",
        f"Test:;{path.stem}",
        *[f"{key}:;{value}" for key, value in trace.metadata.items()],
        f"{shape.radius_key}:;{radius} mm",
        f"Interval and data points:;1;{n}",
    ]
    names = ["Interval data:", "Point No."] + [shape.names[c] for c in CHANNELS] + ["Status"]
    units = ["", "[]"] + [f"[{shape.units[c]}]" for c in CHANNELS] + ["[]"]
    rows = [
        ";".join(["", str(i + 1)] + [_number(values[c][i], ",") for c in CHANNELS] + ["Dy_auto"])
        for i in range(n)
    ]
    return [*preamble, ";".join(names), ";".join(units), *rows]


EXPORT_SHAPES: dict[str, ExportShape] = {
    "brackets": ExportShape(
        description="units in brackets after the names (modelled on Malvern rSpace)",
        names={
            "time": "Time (action)",
            "angle": "Angular displacement",
            "normal_force": "Normal force",
            "torque": "Torque",
        },
        units={"time": "s", "angle": "rad", "normal_force": "N", "torque": "N m"},
        radius_key=None,
        suffix=".csv",
        write_lines=_brackets_lines,
    ),
    "units_row": ExportShape(
        description="units on a second header row, tab-separated (modelled on TA TRIOS)",
        names={
            "time": "Step time",
            "angle": "Displacement",
            "normal_force": "Axial force",
            "torque": "Torque",
        },
        units={"time": "s", "angle": "mrad", "normal_force": "N", "torque": "µN.m"},
        radius_key="Rotation radius",
        suffix=".txt",
        write_lines=_unit_row_lines,
    ),
    "semicolons": ExportShape(
        description="semicolons and decimal commas with a metadata preamble and units in "
        "brackets on a second row (modelled on Anton Paar RheoCompass, German locale)",
        names={
            "time": "Time",
            "angle": "Deflection Angle",
            "normal_force": "Normal Force",
            "torque": "Torque",
        },
        units={"time": "s", "angle": "mrad", "normal_force": "N", "torque": "mN·m"},
        radius_key="Rotation radius",
        suffix=".csv",
        write_lines=_semicolon_lines,
    ),
}


def write_rheometer_export(path: str | Path, trace: RheometerTrace, shape: str) -> None:
    """Write ``trace`` as the program of ``shape`` (a key of EXPORT_SHAPES) exports it,
    atomically (UTF-8, the programs' CRLF line ends)."""
    if shape not in EXPORT_SHAPES:
        raise ValueError(f"unknown export shape '{shape}'; expected one of {list(EXPORT_SHAPES)}")
    path = Path(path)
    lines = EXPORT_SHAPES[shape].write_lines(EXPORT_SHAPES[shape], trace, path)
    with atomic_path(path) as tmp:
        tmp.write_bytes(("\r\n".join(lines) + "\r\n").encode("utf-8"))
