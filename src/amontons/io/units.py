"""The units an instrument's export may name, and their SI factors: one small table, one place.

Rheometer programs spell a unit in several ways (``mN·m``, ``mN.m``, ``mNm``, ``mN m``;
``µ`` as the micro sign, the Greek mu or ``u``; ``°`` or ``deg``). :func:`canonical_unit`
reduces a spelling to the table's key, and :func:`si_factor` gives the factor to SI of a unit
of a quantity. A unit outside the table, or of another quantity, raises UnitError listing the
units the quantity accepts. Standard library only: the workflow checks a config's units before
any job.
"""

from __future__ import annotations

import math
import re

# SI factor of each accepted unit, per quantity (SI: s, rad, N, N·m, m).
UNITS: dict[str, dict[str, float]] = {
    "time": {"s": 1.0, "ms": 1e-3, "min": 60.0},
    "angle": {"rad": 1.0, "mrad": 1e-3, "µrad": 1e-6, "°": math.pi / 180},
    "force": {"N": 1.0, "mN": 1e-3, "µN": 1e-6},
    "torque": {"N·m": 1.0, "mN·m": 1e-3, "µN·m": 1e-6},
    "length": {"m": 1.0, "mm": 1e-3, "µm": 1e-6},
}
SI_UNIT = {quantity: next(iter(table)) for quantity, table in UNITS.items()}

_MICRO = ("μ", "u")  # the Greek mu and the ASCII stand-in, both written for the micro sign µ
# N·m with any of the separators programs write between N and m (·, ., *, ⋅, space or none)
_TORQUE = re.compile(r"^([mµ]?)N\s*[·.*⋅]?\s*m$")
_DEGREE = ("deg", "degree", "degrees")


class UnitError(ValueError):
    """A unit that is not in the table of its quantity."""


def canonical_unit(text: str) -> str:
    """The table's spelling of the unit ``text`` (brackets and spaces stripped, ``µ`` for the
    micro prefix, ``N·m`` for a torque, ``°`` for degrees); ``text`` itself, stripped, where no
    rule applies (:func:`si_factor` then refuses it)."""
    unit = text.strip().strip("[]()").strip()
    for micro in _MICRO:
        if unit.startswith(micro) and len(unit) > 1:
            unit = "µ" + unit[len(micro) :]
    torque = _TORQUE.match(unit)
    if torque:
        return f"{torque.group(1)}N·m"
    if unit.lower() in _DEGREE:
        return "°"
    return unit


def si_factor(unit: str, quantity: str) -> float:
    """Factor that turns values in ``unit`` (any spelling :func:`canonical_unit` knows) into the
    SI unit of ``quantity`` (time s, angle rad, force N, torque N·m, length m).

    Raises UnitError naming the unit and the units the quantity accepts.
    """
    if quantity not in UNITS:
        raise UnitError(f"unknown quantity '{quantity}'; expected one of {sorted(UNITS)}")
    table = UNITS[quantity]
    canonical = canonical_unit(unit)
    if canonical not in table:
        raise UnitError(
            f"unknown {quantity} unit '{unit}'; expected one of {', '.join(table)} "
            "(also spelled with brackets, µ as μ or u, N·m as N.m, Nm or N m, ° as deg)"
        )
    return table[canonical]


def optional_nm_to_m(value_nm: float | None) -> float | None:
    """A length in nm (a sheet or config value) in m; None, a value left blank, stays None
    (the reader then takes the file's own value, or names what is missing)."""
    return None if value_nm is None else value_nm * 1e-9
