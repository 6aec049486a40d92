"""Truths from a solver not our own (docs/study.md §7): ContactMechanics' elastic and
penetration-hardness contact of a rough sphere on a free half-space, as the validation study
reads it (amontons.validation.independent), against our own solver on the same indenter,
and the config's truths held to what each solver can solve."""

import numpy as np
import pytest

from amontons.contact import PenetrationHardness, solve_load_series
from amontons.validation.cases import Truth, cases_of
from amontons.validation.independent import (
    IndependentSolverError,
    compressive_pressure,
    contactmechanics_load_series,
    solver_label,
)

E_STAR = 3.5e9
PIXEL = 100e-9
LOADS = [0.1e-3, 0.2e-3, 0.4e-3]


def rough_sphere(n: int = 96, radius: float = 0.3e-3) -> np.ndarray:
    """A sphere (heights m, larger toward the flat) with 5 nm of white roughness."""
    x = (np.arange(n) - n / 2 + 0.5) * PIXEL
    X, Y = np.meshgrid(x, x, indexing="ij")
    return -(X**2 + Y**2) / (2 * radius) + 5e-9 * np.random.default_rng(1).standard_normal((n, n))


@pytest.mark.parametrize("hardness", [None, 40e6])
def test_contactmechanics_gives_our_contact_on_a_rough_sphere(hardness):
    """Both codes solve the same discrete problem (the same Love kernel on the same padded
    grid, the same local plastic update), so at tol 1e-10 their contact sets are the same
    pixels and their pressures agree to 1e-6 of the peak (measured: 1e-10 elastic, 2e-8
    plastic; the margin is for another CPU's rounding and the two codes' stopping rules). Each
    load carries its load, and the plastic truth caps the pressure at p_Y."""
    heights = rough_sphere()
    theirs = contactmechanics_load_series(heights, PIXEL, E_STAR, LOADS, hardness, 1e-10)
    law = None if hardness is None else PenetrationHardness(hardness)
    ours = solve_load_series(heights, PIXEL, E_STAR, LOADS, plasticity=law, tol=1e-10)
    for field, result, load in zip(theirs, ours, LOADS, strict=True):
        assert np.array_equal(field.contact, result.pressure > 0)
        peak = result.pressure.max()
        assert np.abs(field.pressure - result.pressure).max() <= 1e-6 * peak
        assert field.pressure.sum() * PIXEL**2 == pytest.approx(load, rel=1e-6)
        assert field.mean_pressure == pytest.approx(load / field.area, rel=1e-12)
        if hardness is not None:
            assert field.pressure.max() <= hardness * (1 + 1e-9)


def test_forces_that_do_not_carry_the_load_are_named():
    forces = np.array([[1e-6, 2e-6], [0.0, 0.0]])
    assert compressive_pressure(-forces, 3e-6, 1e-6).sum() * 1e-12 == pytest.approx(3e-6)
    with pytest.raises(IndependentSolverError, match="carry 3e-06 N at a load of 4e-06 N"):
        compressive_pressure(forces, 4e-6, 1e-6)


def test_the_solver_is_recorded_with_its_release():
    assert solver_label().startswith("ContactMechanics 1.")


def test_a_truth_names_a_solver_that_has_its_model():
    with pytest.raises(ValueError, match="solver = 'contactmechanics' for a hardening truth"):
        Truth("t", "hardening", 2.0, "clear", "contactmechanics")
    with pytest.raises(ValueError, match="solver = 'tamaas'"):
        Truth("t", "elastic", None, "none", "tamaas")
    validation = {
        "run_truths": ["cm"],
        "truths": {
            "cm": {"model": "elastic", "signal": "none", "solver": "contactmechanics", "ratio": 2.0}
        },  # fmt: skip
        "seeds": 2,
        "first_seed": 7,
        "truth_pixel_ratio": 4.0,
        "comparison_ratios": [1.5],
        "comparison_truths": ["cm"],
    }
    cases = cases_of(validation)
    assert [(c.ratio, c.seed, c.comparison) for c in cases] == [
        (2.0, 7, False), (2.0, 8, False), (1.5, 7, True), (1.5, 8, True)
    ]  # fmt: skip
