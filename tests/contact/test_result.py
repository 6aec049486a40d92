"""The result's public face: identity equality, status fields, returning instead of raising on
non-convergence, and one diagnostics structure (SolveInfo) on every route."""

import dataclasses

import numpy as np
import pytest

from amontons.contact import (
    ContactHardening,
    ContactInputError,
    ContactResult,
    FreeBoundaryError,
    PenetrationHardness,
    SolveInfo,
    self_affine,
    solve,
    solve_load_series,
    sphere,
)

H = sphere((32, 32), 0.01, 1.0)  # non-periodic Hertz case of test_errors, R = 1 m, E* = 1 Pa
E_PMMA, K_PMMA = 3.5e9, 7e15  # Pa, Pa/m


def rough_sphere(n, spacing=0.2e-6):
    """A rough PMMA-scale sphere (R = 0.75 mm, 30 nm rms roughness) on an n² window."""
    return sphere((n, n), spacing, 0.75e-3) + self_affine(
        (n, n), spacing, 0.8, rms_height=30e-9, rng=1
    ), spacing


@pytest.fixture(scope="module")
def converged():
    return solve(H, 0.01, 1.0, load=1e-3)


def assert_finite(res):
    for name in ("pressure", "gap", "elastic_displacement", "plastic_displacement"):
        assert np.isfinite(getattr(res, name)).all(), name


# --- equality and status fields ---------------------------------------------------------------


def test_result_equality_is_identity(converged):
    """Array fields made == raise; results now compare by identity, without raising."""
    other = solve(H, 0.01, 1.0, load=1e-3)
    assert converged == converged
    assert (converged == other) is False
    assert converged != other


def test_converged_result_has_status_zero_and_says_so(converged):
    assert converged.success is True and converged.status == 0
    assert "converged" in converged.message and "residual" in converged.message


def test_converged_is_a_read_only_alias_of_success(converged):
    assert converged.converged is converged.success
    with pytest.raises(AttributeError):
        converged.converged = False


def test_status_must_agree_with_success(converged):
    with pytest.raises(ValueError, match="contradicts"):
        dataclasses.replace(converged, status=1)
    with pytest.raises(ValueError, match="status must be one of"):
        dataclasses.replace(converged, success=False, status=7)


# --- raise_on_failure=False -----------------------------------------------------------------


def test_too_small_max_iter_returns_an_unconverged_result():
    """Two iterations cannot reach 1e-8: status 1 and a message naming the iterations and
    the residual; the last iterate is finite and still carries the load (load control
    rescales every iterate, so to round-off, 1e-12)."""
    res = solve(H, 0.01, 1.0, load=1e-3, max_iter=2, raise_on_failure=False)
    assert isinstance(res, ContactResult)
    assert res.success is False and res.converged is False and res.status == 1
    assert res.iterations == 2 and res.residual > 1e-8
    assert "2 iterations" in res.message and f"residual {res.residual:.3e}" in res.message
    assert res.load == pytest.approx(1e-3, rel=1e-12)
    assert_finite(res)


def test_full_contact_under_periodic_displacement_control_returns_stalled():
    """The singular full-contact case stops with status 2 instead of raising."""
    x = np.arange(64) / 64
    h = np.broadcast_to(1e-3 * np.cos(2 * np.pi * x), (4, 64)).copy()
    res = solve(h, 1 / 64, 1.0, displacement=5e-3, periodic=True, raise_on_failure=False)
    assert res.success is False and res.status == 2
    assert "full contact" in res.message and "residual" in res.message
    assert_finite(res)


def test_plastic_iteration_cap_returns_an_unconverged_result():
    """One plastic update cannot converge the volume-conserving scheme: the load control
    returns the failed trial with the iteration-cap status and both reasons."""
    h, dx = rough_sphere(64)
    law = PenetrationHardness(50e6, increment="volume", alpha=0.5)
    res = solve(h, dx, E_PMMA, load=1e-3, plasticity=law, max_outer=1, raise_on_failure=False)
    assert res.success is False and res.status == 1
    assert "load control" in res.message and "plastic iteration" in res.message
    assert "1 updates" in res.message and "residual" in res.message
    assert res.info.route == "appendix" and res.info.outer_iterations == 1
    assert_finite(res)


def test_winkler_iteration_cap_returns_an_unconverged_result():
    h, dx = rough_sphere(32)
    res = solve(
        h, dx, E_PMMA, load=1e-5, plasticity=ContactHardening(K_PMMA), max_iter=2,
        raise_on_failure=False,
    )  # fmt: skip
    assert res.success is False and res.status == 1
    assert "2 iterations" in res.message and res.info.route == "winkler"
    assert_finite(res)


def test_load_series_without_raise_on_failure_returns_every_step():
    series = solve_load_series(H, 0.01, 1.0, [5e-4, 1e-3], max_iter=2, raise_on_failure=False)
    assert len(series) == 2
    assert [r.status for r in series] == [1, 1]
    for res in series:
        assert_finite(res)


def test_free_boundary_error_is_raised_even_without_raise_on_failure():
    """A converged solution reaching the window edge is a window problem, not a convergence
    failure: it raises whatever raise_on_failure says."""
    load = 4 * 1.0 * 0.3**3 / 3  # a = 0.30 m on a 0.32 m window
    with pytest.raises(FreeBoundaryError, match="edge pixel"):
        solve(H, 0.01, 1.0, load=load, raise_on_failure=False)


def test_input_errors_are_raised_even_without_raise_on_failure():
    with pytest.raises(ContactInputError, match="load"):
        solve(H, 0.01, 1.0, load=-1.0, raise_on_failure=False)
    with pytest.raises(ContactInputError, match="max_iter"):
        solve(H, 0.01, 1.0, load=1e-3, max_iter=0, raise_on_failure=False)


# --- info ------------------------------------------------------------------------------------


def test_info_has_the_same_fields_on_every_route():
    """Elastic, penetration-hardness and contact-hardening results carry one SolveInfo
    structure; an elastic solve reports no outer (plastic) iterations."""
    h, dx = rough_sphere(64)
    elastic = solve(h, dx, E_PMMA, load=4e-4)
    p_y = 0.5 * elastic.pressure.max()
    hardness = solve(h, dx, E_PMMA, load=4e-4, plasticity=PenetrationHardness(p_y), tol=1e-6)
    hardening = solve(h, dx, E_PMMA, load=4e-4, plasticity=ContactHardening(K_PMMA))
    results = (elastic, hardness, hardening)
    assert all(type(r.info) is SolveInfo for r in results)
    names = {tuple(f.name for f in dataclasses.fields(r.info)) for r in results}
    assert len(names) == 1
    assert [r.info.route for r in results] == ["elastic", "bounded", "winkler"]
    assert elastic.info.outer_iterations == 0
    assert elastic.info.plasticity is None and elastic.info.max_outer is None
    # the bounded route is one solve and one plastic update: no outer loop to cap
    assert hardness.info.outer_iterations == 1 and hardening.info.outer_iterations >= 1
    assert (hardness.info.max_outer, hardening.info.max_outer) == (None, 50)
    for res in results:
        assert res.info.convolutions >= res.iterations > 0
        assert res.info.planner_effort == "FFTW_MEASURE" and res.info.coarse_levels == ()
        assert res.info.wall_time_s > 0
    with pytest.raises(dataclasses.FrozenInstanceError):
        elastic.info.route = "winkler"
