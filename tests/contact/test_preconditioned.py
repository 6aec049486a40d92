"""The preconditioned bound-constrained CG (``iteration="preconditioned"``; docs/models.md
§2.2, "The preconditioned iteration") is held to what Polonsky and Keer's iteration is held
to: the analytic oracles (Hertz, Westergaard, the flat punch), the hard cases, and the same
contact sets and fields as the default iteration on the golden record's kinds of solve.

The oracle and hard-case modules are run as they are, their ``solve`` and
``solve_load_series`` bound to the preconditioned iteration: the same assertions, the same
tolerances (each module states them and why).
"""

import functools
import importlib.util
import inspect
from pathlib import Path

import numpy as np
import pytest

from amontons.contact import (
    ContactHardening,
    ContactInputError,
    IgnoredOptionWarning,
    PenetrationHardness,
    self_affine,
    solve,
    solve_load_series,
    solve_scan,
    sphere,
)

HERE = Path(__file__).parent
PRECONDITIONED = {"iteration": "preconditioned"}


def _module(name):
    """A test module of this folder, loaded afresh with the solver's calls bound to the
    preconditioned iteration (its own objects: the module pytest collects is untouched)."""
    spec = importlib.util.spec_from_file_location(f"preconditioned_{name}", HERE / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    for call in ("solve", "solve_load_series"):
        if hasattr(module, call):
            setattr(module, call, functools.partial(getattr(module, call), **PRECONDITIONED))
    return module


def _cases(name, skip=()):
    """``(module, test name)`` of every test function of a module that takes no fixture
    (parametrized ones with their parameter sets), less ``skip``."""
    module = _module(name)
    out = []
    for test_name, func in vars(module).items():
        if not test_name.startswith("test_") or test_name in skip or not callable(func):
            continue
        marks = [m for m in getattr(func, "pytestmark", []) if m.name == "parametrize"]
        if not marks:
            if not inspect.signature(func).parameters:
                out.append(pytest.param(func, {}, id=f"{name}::{test_name}"))
            continue
        (mark,) = marks
        names = mark.args[0]
        names = [n.strip() for n in names.split(",")] if isinstance(names, str) else list(names)
        if set(inspect.signature(func).parameters) - set(names):
            continue  # it takes a fixture
        for values in mark.args[1]:
            values = getattr(values, "values", values)  # a pytest.param's own values
            values = tuple(values) if len(names) > 1 else (values,)
            kwargs = dict(zip(names, values, strict=True))
            out.append(pytest.param(func, kwargs, id=f"{name}::{test_name}{list(values)}"))
    return out


# The hard cases that test options or refusals rather than a solve (no iteration runs)
# or that hold Polonsky and Keer's own bookkeeping are left out.
HARD_SKIPPED = (
    "test_non_finite_pixel_is_refused_by_the_load_series",
    "test_zero_negative_and_non_finite_loads_in_a_series_are_refused",
    "test_load_series_that_is_not_increasing_is_refused",
)


@pytest.mark.parametrize(
    ("test", "kwargs"),
    _cases("test_westergaard")
    + _cases("test_hard_cases", skip=HARD_SKIPPED)
    + _cases("test_hardness_bounded", skip=()),
)
def test_the_oracles_and_hard_cases_hold_under_the_preconditioned_iteration(test, kwargs):
    test(**kwargs)


@pytest.fixture(scope="module")
def preconditioned_hertz_case(hertz_case):
    """conftest.py's Hertz case, solved again by the preconditioned iteration."""
    case = hertz_case
    result = solve(case["heights"], case["dx"], case["e_star"], load=case["load"], **PRECONDITIONED)
    return {**case, "result": result}


HERTZ = _module("test_hertz")


@pytest.mark.parametrize(
    "name", [n for n in vars(HERTZ) if n.startswith("test_") and callable(getattr(HERTZ, n))]
)
def test_hertz_holds_under_the_preconditioned_iteration(name, preconditioned_hertz_case):
    getattr(HERTZ, name)(preconditioned_hertz_case)


def _rough_periodic(n=128):
    return self_affine((n, n), 1.0, 0.8, rms_slope=0.1, rng=3)


def _rough_sphere(n=96, spacing=0.2e-6):
    h = sphere((n, n), spacing, 0.75e-3) + self_affine(
        (n, n), spacing, 0.8, rms_height=30e-9, rng=1
    )
    return h, spacing


E_PMMA, K_PMMA, P_Y, LOAD = 3.5e9, 7e15, 30e6, 1e-4  # Pa, Pa/m, Pa, N


def _golden_kinds():
    """The golden record's kinds of CG solve (tests/contact/golden/record.py), each a
    callable of the iteration's keyword arguments."""
    hp = _rough_periodic()
    n = hp.shape[0]
    hs, dx = _rough_sphere()
    return {
        "elastic_periodic_load": lambda **kw: solve(
            hp, 1.0, 1.0, load=0.005 * n * n, periodic=True, **kw
        ),
        "elastic_periodic_displacement": lambda **kw: solve(
            hp, 1.0, 1.0, displacement=-np.quantile(hp, 0.9), periodic=True, **kw
        ),
        "elastic_sphere_padded": lambda **kw: solve(hs, dx, E_PMMA, load=LOAD, **kw),
        "elastic_sphere_numpy": lambda **kw: solve(
            hs, dx, E_PMMA, load=LOAD, backend="numpy", **kw
        ),
        "hardness_bounded_load": lambda **kw: solve(
            hs, dx, E_PMMA, load=LOAD, plasticity=PenetrationHardness(P_Y), **kw
        ),
        "hardness_bounded_displacement": lambda **kw: solve(
            hs, dx, E_PMMA, displacement=-1.9e-8, plasticity=PenetrationHardness(P_Y), **kw
        ),
        "hardness_bounded_periodic": lambda **kw: solve(
            hp,
            1.0,
            1.0,
            load=0.005 * n * n,
            periodic=True,
            plasticity=PenetrationHardness(0.1),
            **kw,
        ),
        "hardening_winkler_load": lambda **kw: solve(
            hs, dx, E_PMMA, load=LOAD, plasticity=ContactHardening(K_PMMA), **kw
        ),
        "series_hardening": lambda **kw: solve_load_series(
            hs, dx, E_PMMA, [0.25 * LOAD, LOAD, 2 * LOAD], plasticity=ContactHardening(K_PMMA), **kw
        ),
        "scan_hardness": lambda **kw: solve_scan(
            hs,
            dx,
            E_PMMA,
            [0.25 * LOAD, LOAD],
            [PenetrationHardness(2 * P_Y), PenetrationHardness(P_Y)],
            **kw,
        ),
    }


def _flat(results):
    if isinstance(results, list):
        return [r for item in results for r in _flat(item)]
    return [results]


# Both iterations stop where the complementarity and the relative pressure change are below
# tol = 1e-8; each field then lies within a few tol of the exact solution of the discrete
# problem, so the two agree to 1e-7 of their peak (measured: at most 4.9e-8, on the periodic
# penetration-hardness case) and on every contact pixel.
FIELD_AGREEMENT = 1e-7


@pytest.mark.parametrize("kind", sorted(_golden_kinds()))
def test_the_same_contact_sets_and_fields_as_polonsky_keer(kind):
    run = _golden_kinds()[kind]
    ours = _flat(run(**PRECONDITIONED))
    theirs = _flat(run())
    for a, b in zip(ours, theirs, strict=True):
        assert a.success, a.message
        assert a.info.iteration == "preconditioned"
        np.testing.assert_array_equal(a.contact, b.contact)
        for field in ("pressure", "gap", "plastic_displacement"):
            x, y = getattr(a, field), getattr(b, field)
            scale = float(np.abs(y).max()) or 1.0
            assert float(np.abs(x - y).max()) <= FIELD_AGREEMENT * scale, field
        assert a.load == pytest.approx(b.load, rel=FIELD_AGREEMENT)


def test_the_two_iterations_meet_at_one_fixed_point():
    """At tol 1e-11 the two iterations' pressures agree to 1e-9 of their peak (at 1e-8,
    to 1e-7 above): the difference shrinks with the tolerance, so it is the tolerance's,
    not a second solution's."""
    h = _rough_periodic(64)
    kw = {"load": 0.005 * h.size, "periodic": True, "tol": 1e-11}
    a = solve(h, 1.0, 1.0, **kw, **PRECONDITIONED)
    b = solve(h, 1.0, 1.0, **kw)
    assert np.abs(a.pressure - b.pressure).max() <= 1e-9 * b.pressure.max()


def test_fewer_iterations_than_polonsky_keer_on_a_rough_surface():
    """The point of the preconditioner: on the periodic self-affine surface of benchmark 3
    at 256² (about 10 % contact) it converges in under 0.6 of Polonsky and Keer's
    iterations (measured 31 against 64; benchmarks/README.md, benchmark 3, gives the
    counts to 4096²)."""
    h = self_affine((256, 256), 1.0, 0.8, rms_slope=0.1, rng=1)
    kw = {"load": 0.005 * h.size, "periodic": True}
    ours = solve(h, 1.0, 1.0, **kw, **PRECONDITIONED)
    theirs = solve(h, 1.0, 1.0, **kw)
    assert ours.iterations < 0.6 * theirs.iterations


@pytest.mark.parametrize("fraction", [0.5, 0.8, 0.95])
def test_near_full_contact_converges(fraction):
    """A rough surface pressed to 50, 80 and 95 % contact converges, and to the default
    iteration's contact set (the regime where the free set is almost everything)."""
    h = _rough_periodic(64)
    # mean pressure / (E* h'_rms) that presses this surface to the fraction (measured)
    loads = {0.5: 0.25, 0.8: 0.55, 0.95: 0.9}
    load = loads[fraction] * 0.1 * h.size
    ours = solve(h, 1.0, 1.0, load=load, periodic=True, **PRECONDITIONED)
    theirs = solve(h, 1.0, 1.0, load=load, periodic=True)
    assert ours.success
    assert ours.contact_fraction == pytest.approx(fraction, abs=0.05)
    np.testing.assert_array_equal(ours.contact, theirs.contact)


def test_periodic_displacement_control_at_full_contact_fails_loudly():
    """Full contact under periodic displacement control leaves the mean pressure
    undetermined: the iteration says so (status 2) instead of returning a pressure."""
    h = _rough_periodic(32)
    res = solve(
        h,
        1.0,
        1.0,
        displacement=-h.min() + 1.0,
        periodic=True,
        raise_on_failure=False,
        **PRECONDITIONED,
    )
    assert not res.success and res.status == 2
    assert "full contact" in res.message


def test_the_appendix_route_says_it_ignores_the_preconditioned_iteration():
    """The appendix's scheme runs Polonsky and Keer's iteration whatever is asked: a warning
    says so, and the result's info names the iteration that ran."""
    h, dx = _rough_sphere(48)
    with pytest.warns(IgnoredOptionWarning, match="iteration='preconditioned' is ignored"):
        res = solve(
            h, dx, E_PMMA, load=0.1 * LOAD, plasticity=PenetrationHardness(P_Y),
            method="appendix", **PRECONDITIONED,
        )  # fmt: skip
    assert res.info.iteration == "polonsky-keer"


def test_an_unknown_iteration_is_refused_by_name():
    with pytest.raises(ContactInputError, match="iteration must be one of.*'cg'"):
        solve(_rough_periodic(16), 1.0, 1.0, load=1.0, periodic=True, iteration="cg")


def test_the_array_backends_refuse_the_preconditioned_iteration():
    with pytest.raises(ContactInputError, match="numpy-array"):
        solve(
            _rough_periodic(16),
            1.0,
            1.0,
            load=1.0,
            periodic=True,
            backend="numpy-array",
            **PRECONDITIONED,
        )
