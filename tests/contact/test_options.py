"""Options of solve/solve_load_series: method= routes, warnings for ignored options, and the
explicit FFTW planner effort, whose measured plans every process shares (wisdom on disk)."""

import os
import subprocess
import sys
import warnings

import numpy as np
import pytest

from amontons.contact import (
    CoarseLevel,
    ContactHardening,
    ContactInputError,
    IgnoredOptionWarning,
    PenetrationHardness,
    self_affine,
    solve,
    solve_load_series,
    sphere,
)
from amontons.contact.convolution import get_operator
from amontons.contact.fft import HAVE_PYFFTW

H = sphere((32, 32), 0.01, 1.0)  # R = 1 m, E* = 1 Pa; load 1e-3 N gives a ≈ 9 pixels
H64 = sphere((64, 64), 0.01, 1.0)  # the smallest grid with a coarse level (64 → 32)
LOAD64 = 4 * 0.15**3 / 3  # a = 0.15 m: 15 of the 32 pixels to the edge
E_PMMA, K_PMMA = 3.5e9, 7e15  # Pa, Pa/m


def rough_sphere(n, spacing=0.2e-6):
    """A rough PMMA-scale sphere (R = 0.75 mm, 30 nm rms roughness) on an n² window."""
    return sphere((n, n), spacing, 0.75e-3) + self_affine(
        (n, n), spacing, 0.8, rms_height=30e-9, rng=1
    ), spacing


@pytest.fixture
def no_ignored_option_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error", IgnoredOptionWarning)
        yield


# --- method= --------------------------------------------------------------------------------


@pytest.mark.parametrize("law", [None, ContactHardening(K_PMMA)])
def test_unknown_method_is_an_input_error_naming_the_allowed_values(law):
    h, dx = rough_sphere(32)
    with pytest.raises(
        ContactInputError, match=r"'winkler', 'bounded', 'appendix'.*got 'iterative'"
    ):
        solve(h, dx, E_PMMA, load=1e-5, plasticity=law, method="iterative")


@pytest.mark.parametrize(
    "law",
    [PenetrationHardness(50e6), ContactHardening(K_PMMA, increment="volume", alpha=0.5)],
    ids=["penetration-hardness", "volume-increments"],
)
def test_winkler_method_is_refused_where_it_does_not_apply(law):
    h, dx = rough_sphere(32)
    with pytest.raises(ContactInputError, match="method='winkler'"):
        solve(h, dx, E_PMMA, load=1e-5, plasticity=law, method="winkler")


@pytest.mark.parametrize(
    "law",
    [
        ContactHardening(K_PMMA),
        PenetrationHardness(50e6, increment="volume", alpha=0.5),
    ],
    ids=["contact-hardening", "volume-increments"],
)
def test_bounded_method_is_refused_where_it_does_not_apply(law):
    """The one-solve route is exact for penetration hardness with local increments only:
    pile-up (eq. B.3) moves points that did not yield, and contact hardening's bound grows
    with the flow."""
    h, dx = rough_sphere(32)
    with pytest.raises(ContactInputError, match="method='bounded'"):
        solve(h, dx, E_PMMA, load=1e-5, plasticity=law, method="bounded")


def test_default_method_is_bounded_for_local_penetration_hardness():
    """method=None and method="bounded" are the same solve, bit for bit; max_outer has no
    loop to cap there, so it is ignored with a warning and reported as None."""
    h, dx = rough_sphere(32)
    law = PenetrationHardness(50e6)
    default = solve(h, dx, E_PMMA, load=1e-5, plasticity=law)
    explicit = solve(h, dx, E_PMMA, load=1e-5, plasticity=law, method="bounded")
    assert default.info.route == explicit.info.route == "bounded"
    np.testing.assert_array_equal(default.pressure, explicit.pressure)
    assert default.info.max_outer is None and default.info.outer_iterations == 1
    with pytest.warns(IgnoredOptionWarning, match="max_outer=3 is ignored.*'bounded'"):
        capped = solve(h, dx, E_PMMA, load=1e-5, plasticity=law, max_outer=3)
    assert capped.info.max_outer is None


def test_appendix_method_for_contact_hardening_needs_alpha_below_one():
    h, dx = rough_sphere(32)
    with pytest.raises(ContactInputError, match="alpha < 1"):
        solve(h, dx, E_PMMA, load=1e-5, plasticity=ContactHardening(K_PMMA), method="appendix")


def test_default_method_is_winkler_for_local_hardening():
    """method=None and method="winkler" are the same solve, bit for bit."""
    h, dx = rough_sphere(32)
    law = ContactHardening(K_PMMA)
    default = solve(h, dx, E_PMMA, load=1e-5, plasticity=law)
    explicit = solve(h, dx, E_PMMA, load=1e-5, plasticity=law, method="winkler")
    assert default.info.route == explicit.info.route == "winkler"
    np.testing.assert_array_equal(default.pressure, explicit.pressure)


# --- ignored options warn ---------------------------------------------------------------------


def test_method_on_an_elastic_solve_warns():
    with pytest.warns(IgnoredOptionWarning, match="method='appendix' is ignored"):
        res = solve(H, 0.01, 1.0, load=1e-3, method="appendix")
    assert res.info.route == "elastic"


def test_max_outer_on_an_elastic_solve_warns():
    with pytest.warns(IgnoredOptionWarning, match="max_outer=5 is ignored"):
        solve(H, 0.01, 1.0, load=1e-3, max_outer=5)


def test_coarse_to_fine_with_plasticity_warns():
    h, dx = rough_sphere(64)
    with pytest.warns(IgnoredOptionWarning, match="coarse_to_fine=True is ignored.*elastic"):
        solve(h, dx, E_PMMA, load=1e-5, plasticity=ContactHardening(K_PMMA), coarse_to_fine=True)


def test_coarse_to_fine_with_a_warm_start_warns():
    start = solve(H64, 0.01, 1.0, load=LOAD64).pressure
    with pytest.warns(IgnoredOptionWarning, match="coarse_to_fine=True is ignored.*warm_start"):
        res = solve(H64, 0.01, 1.0, load=LOAD64, warm_start=start, coarse_to_fine=True)
    assert res.info.coarse_levels == ()


@pytest.mark.parametrize("shape", [(65, 64), (32, 32)], ids=["odd", "small"])
def test_coarse_to_fine_on_a_grid_without_coarse_level_warns(shape):
    h = sphere(shape, 0.01, 1.0)
    with pytest.warns(IgnoredOptionWarning, match="has no coarse level"):
        res = solve(h, 0.01, 1.0, load=1e-3, coarse_to_fine=True)
    assert res.info.coarse_levels == ()


def test_coarse_to_fine_that_runs_does_not_warn(no_ignored_option_warnings):
    res = solve(H64, 0.01, 1.0, load=LOAD64, coarse_to_fine=True)
    assert [lv.shape for lv in res.info.coarse_levels] == [(32, 32)]
    assert isinstance(res.info.coarse_levels[0], CoarseLevel)


def test_numpy_backend_warns_about_threads_and_planner_effort():
    with pytest.warns(IgnoredOptionWarning) as record:
        solve(H, 0.01, 1.0, load=1e-3, backend="numpy", threads=2, planner_effort="FFTW_ESTIMATE")
    messages = sorted(str(w.message) for w in record)
    assert len(messages) == 2
    assert messages[0].startswith("planner_effort='FFTW_ESTIMATE' is ignored")
    assert messages[1].startswith("threads=2 is ignored")


def test_default_options_do_not_warn(no_ignored_option_warnings):
    solve(H, 0.01, 1.0, load=1e-3)
    h, dx = rough_sphere(32)
    solve(h, dx, E_PMMA, load=1e-5, plasticity=ContactHardening(K_PMMA), max_outer=10)


def test_load_series_warns_once_about_coarse_to_fine_with_plasticity():
    h, dx = rough_sphere(64)
    with pytest.warns(IgnoredOptionWarning) as record:
        solve_load_series(
            h, dx, E_PMMA, [1e-5, 2e-5, 4e-5], plasticity=ContactHardening(K_PMMA),
            coarse_to_fine=True,
        )  # fmt: skip
    assert len(record) == 1 and "coarse_to_fine=True is ignored" in str(record[0].message)


def test_load_series_warns_once_about_method_on_elastic_steps():
    with pytest.warns(IgnoredOptionWarning) as record:
        solve_load_series(H, 0.01, 1.0, [5e-4, 1e-3], method="winkler")
    assert len(record) == 1


def test_elastic_load_series_with_coarse_to_fine_does_not_warn(no_ignored_option_warnings):
    """The series starts coarse-to-fine at its first load and warm-starts the rest: the
    internal warm-started steps must not warn."""
    series = solve_load_series(H64, 0.01, 1.0, [0.5 * LOAD64, LOAD64], coarse_to_fine=True)
    assert len(series[0].info.coarse_levels) == 1 and series[1].info.coarse_levels == ()


# --- planner effort -----------------------------------------------------------------------


def test_unknown_planner_effort_is_an_input_error_naming_the_allowed_values():
    with pytest.raises(ContactInputError, match="FFTW_ESTIMATE.*FFTW_MEASURE.*got 'MEASURE'"):
        solve(H, 0.01, 1.0, load=1e-3, planner_effort="MEASURE")
    with pytest.raises(ContactInputError, match="planner_effort"):
        get_operator((8, 8), 1.0, 1.0, periodic=True, planner_effort="FFTW_WISDOM_ONLY")


def test_unknown_backend_is_an_input_error_naming_the_allowed_values():
    with pytest.raises(ContactInputError, match="'pyfftw', 'numpy'"):
        solve(H, 0.01, 1.0, load=1e-3, backend="mkl")


@pytest.mark.skipif(not HAVE_PYFFTW, reason="pyfftw not installed")
def test_operators_are_cached_per_planner_effort():
    default = get_operator((16, 16), 1.0, 1.0, periodic=False)
    assert get_operator((16, 16), 1.0, 1.0, periodic=False) is default
    estimate = get_operator((16, 16), 1.0, 1.0, periodic=False, planner_effort="FFTW_ESTIMATE")
    assert estimate is not default
    assert (default.planner_effort, estimate.planner_effort) == ("FFTW_MEASURE", "FFTW_ESTIMATE")


@pytest.mark.skipif(not HAVE_PYFFTW, reason="pyfftw not installed")
def test_estimated_plans_give_the_same_solution_to_round_off():
    """Another plan only reorders the FFT's floating-point sums: 1e-9 of the peak pressure
    (as for the backends in test_properties)."""
    ref = solve(H, 0.01, 1.0, load=1e-3, tol=1e-10)
    res = solve(H, 0.01, 1.0, load=1e-3, tol=1e-10, planner_effort="FFTW_ESTIMATE")
    assert (ref.info.planner_effort, res.info.planner_effort) == ("FFTW_MEASURE", "FFTW_ESTIMATE")
    assert np.abs(res.pressure - ref.pressure).max() < 1e-9 * ref.pressure.max()


CHILD = """
import hashlib
from amontons.contact import self_affine, solve, sphere
rough = self_affine((64, 64), 1.0, 0.8, rms_slope=0.1, rng=7)
a = solve(rough, 1.0, 1.0, load=0.005 * 64**2, periodic=True)
b = solve(sphere((64, 64), 0.01, 1.0), 0.01, 1.0, load={load!r})
digest = hashlib.sha256(a.pressure.tobytes() + b.pressure.tobytes()).hexdigest()
print(a.info.planner_effort, digest)
"""


def _pressure_digest(env):
    out = subprocess.run(
        [sys.executable, "-c", CHILD.format(load=LOAD64)],
        capture_output=True,
        text=True,
        env=env,
        check=True,
        timeout=120,
    )
    return out.stdout.split()


def test_default_planner_effort_is_bit_reproducible_across_processes(tmp_path):
    """Two fresh processes give the same pressure bytes for a periodic and a non-periodic
    64² solve. The default FFTW_MEASURE times its plans, and two processes timing on their
    own can choose differently (seen at 1024²); the first writes its choice to the wisdom
    file and the second imports it: it measures nothing, so the file is unchanged. The
    second also sets the retired environment variable AMONTONS_FFTW_EFFORT, which no longer
    changes anything."""
    wisdom = tmp_path / "wisdom.json"
    env = {k: v for k, v in os.environ.items() if k != "AMONTONS_FFTW_EFFORT"}
    env["AMONTONS_FFTW_WISDOM"] = str(wisdom)
    first = _pressure_digest(env)
    stamp = wisdom.stat().st_mtime_ns
    second = _pressure_digest(dict(env, AMONTONS_FFTW_EFFORT="FFTW_ESTIMATE"))
    assert first[0] == "FFTW_MEASURE"
    assert first == second
    assert wisdom.stat().st_mtime_ns == stamp  # nothing new to write: nothing was measured
