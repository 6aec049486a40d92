"""The one table of units an export may name: every spelling the programs write reaches its SI
factor, and a unit outside the table, or of another quantity, is refused listing the units the
quantity accepts."""

import math

import pytest

from amontons.io.units import UNITS, UnitError, canonical_unit, si_factor


@pytest.mark.parametrize(
    ("spellings", "quantity", "factor"),
    [
        (["N·m", "N.m", "Nm", "N m", "N*m", "[N·m]", "(N m)"], "torque", 1.0),
        (["mN·m", "mN.m", "mNm", "mN m", "[mN·m]"], "torque", 1e-3),
        (["µN·m", "μN·m", "uN.m", "µN m", "µNm"], "torque", 1e-6),
        (["rad", "[rad]"], "angle", 1.0),
        (["mrad", "[mrad]"], "angle", 1e-3),
        (["°", "deg", "degree", "[°]"], "angle", math.pi / 180),
        (["s", "[s]"], "time", 1.0),
        (["min"], "time", 60.0),
        (["N", "[N]"], "force", 1.0),
        (["mN"], "force", 1e-3),
        (["mm"], "length", 1e-3),
    ],
)
def test_every_spelling_reaches_its_si_factor(spellings, quantity, factor):
    for spelling in spellings:
        assert si_factor(spelling, quantity) == factor, spelling


def test_canonical_spellings_are_the_table_keys():
    for table in UNITS.values():
        for unit in table:
            assert canonical_unit(unit) == unit


@pytest.mark.parametrize(
    ("unit", "quantity"),
    [("kgf·cm", "torque"), ("mN", "torque"), ("grad", "angle"), ("h", "time"), ("N·m", "force")],
)
def test_a_unit_outside_its_quantity_is_refused_listing_the_accepted(unit, quantity):
    with pytest.raises(UnitError, match=rf"unknown {quantity} unit '{unit}'; expected one of"):
        si_factor(unit, quantity)
