"""Analytic Hertz formulas against published regression values (ContactMechanics' Hertz test,
docs/models.md §2.7): E* = 5, R = 4, F = 7."""

import numpy as np
import pytest

from amontons.physics import hertz


def test_regression_values():
    # The reference values are quoted to 8-9 significant digits.
    assert hertz.contact_radius(7, 4, 5) == pytest.approx(1.61342865, rel=1e-8)
    assert hertz.approach(7, 4, 5) == pytest.approx(0.65078800, rel=1e-7)
    assert hertz.peak_pressure(7, 4, 5) == pytest.approx(1.28392572, rel=1e-8)


def test_pressure_integrates_to_the_load():
    r = np.linspace(0, 2, 200001)
    p = hertz.pressure_profile(r, 7, 4, 5)
    load = np.trapezoid(2 * np.pi * r * p, r)
    # The √ edge singularity limits trapezoid accuracy to ~ (dr/a)^1.5 ≈ 1e-7.
    assert load == pytest.approx(7, rel=1e-6)
