"""Penetration hardness with local increments in one bounded CG (route "bounded",
docs/models.md §2.3) against the appendix's root find on the approach (route "appendix",
the oracle), and at its limits.

Tolerances, and why (both routes solve to the default tol = 1e-8):

* pressure: 1e-6 of p_Y, the tolerance the plastic tests put on an elastic comparison
  (test_plasticity.test_huge_hardness_is_elastic); measured 2e-7 on the rough sphere;
* approach and plastic displacement: 10·tol·h_rms, the bound test_plasticity puts on the
  gap (a single point may sit a few times deeper than the rms gap the CG converges on);
  both are gaps of the same converged field;
* contact set: identical; load: 1e-8 relative (the oracle's root find stops at tol; the
  bounded route imposes the load to round-off).

Problem sizes 64²–128², so the file runs in seconds.
"""

from dataclasses import replace

import numpy as np
import pytest

from amontons.contact import (
    ConvergenceError,
    PenetrationHardness,
    solve,
    solve_load_series,
)
from amontons.contact.api import solve_with_options
from amontons.contact.bounded_load import impose_bounded_load
from amontons.contact.options import solve_options
from amontons.contact.surfaces import self_affine, sphere

E_STAR = 3.5e9  # PMMA on glass, Pa
R = 0.75e-3  # 1.5 mm sphere, m
TOL = 1e-8  # the solver's default tolerance (dimensionless)


def rough_sphere(n=128, spacing=0.2e-6, rms=30e-9, seed=1):
    """A rough sphere on an n² non-periodic window (25.6 µm at the defaults), m."""
    h = sphere((n, n), spacing, R) + self_affine((n, n), spacing, 0.8, rms_height=rms, rng=seed)
    return h, spacing


def rough_plane(n=64, seed=7):
    """A periodic self-affine surface, unit pixels, rms slope 0.1 (E* = 1)."""
    return self_affine((n, n), 1.0, 0.8, rms_slope=0.1, rng=seed)


def assert_same_state(new, oracle, p_y, h_rms):
    assert new.info.route == "bounded" and oracle.info.route == "appendix"
    assert new.success and oracle.success
    np.testing.assert_array_equal(new.contact, oracle.contact)
    np.testing.assert_allclose(new.pressure, oracle.pressure, rtol=0, atol=1e-6 * np.max(p_y))
    assert abs(new.displacement - oracle.displacement) <= 10 * TOL * h_rms
    np.testing.assert_allclose(
        new.plastic_displacement, oracle.plastic_displacement, rtol=0, atol=10 * TOL * h_rms
    )
    assert new.load == pytest.approx(oracle.load, rel=1e-8)


@pytest.fixture(scope="module")
def sphere_case():
    h, dx = rough_sphere()
    load = 3e-3
    p_y = 0.5 * solve(h, dx, E_STAR, load=load).pressure.max()
    return h, dx, load, p_y


def test_rough_sphere_matches_the_root_find(sphere_case):
    h, dx, load, p_y = sphere_case
    law = PenetrationHardness(p_y)
    new = solve(h, dx, E_STAR, load=load, plasticity=law)
    oracle = solve(h, dx, E_STAR, load=load, plasticity=law, method="appendix")
    assert (new.pressure == p_y).sum() > 20  # the bound is active
    assert new.load == pytest.approx(load, rel=1e-12)  # imposed on the field itself
    assert_same_state(new, oracle, p_y, h.std())
    # Plastic flow only where the bound is reached, and there the gap is closed.
    flowed = new.plastic_displacement < 0
    assert flowed.any() and np.all(new.pressure[flowed] == p_y)
    assert new.gap.min() >= -10 * TOL * h.std()


@pytest.mark.parametrize("per_pixel", [False, True])
def test_periodic_rough_surface_matches_the_root_find(per_pixel):
    """Mean pressure 0.005 E*, p_Y = 0.05 E* (a fifth of the elastic peak or so); the
    per-pixel hardness varies by ±25 % in a checkerboard."""
    h = rough_plane()
    load = 0.005 * h.size
    p_y = 0.05
    if per_pixel:
        checker = (np.indices(h.shape).sum(axis=0) % 2).astype(float)
        p_y = 0.05 * (0.75 + 0.5 * checker)
    law = PenetrationHardness(p_y)
    new = solve(h, 1.0, 1.0, load=load, periodic=True, plasticity=law)
    oracle = solve(h, 1.0, 1.0, load=load, periodic=True, plasticity=law, method="appendix")
    assert (new.pressure == np.broadcast_to(p_y, h.shape)).sum() > 20
    assert_same_state(new, oracle, p_y, h.std())


def test_displacement_control_matches_the_appendix_scheme(sphere_case):
    """At a fixed approach the appendix scheme takes two rounds (solve, update, solve); the
    bounded route stops after the first update, which already is its fixed point."""
    h, dx, load, p_y = sphere_case
    law = PenetrationHardness(p_y)
    d = solve(h, dx, E_STAR, load=load, plasticity=law).displacement
    new = solve(h, dx, E_STAR, displacement=d, plasticity=law)
    oracle = solve(h, dx, E_STAR, displacement=d, plasticity=law, method="appendix")
    assert oracle.info.outer_iterations == 2 and new.info.outer_iterations == 1
    assert_same_state(new, oracle, p_y, h.std())


def test_load_series_carries_the_plastic_history_as_the_root_find_does(sphere_case):
    """Three loads, each step on h + h_pl of the one before: the same states as the oracle's
    series; the flow of a step is the penetration at p = p_Y only, on top of the history;
    and a single solve from the previous step's plastic displacement is that step."""
    h, dx, load, p_y = sphere_case
    law = PenetrationHardness(p_y)
    loads = [0.5 * load, load, 2 * load]
    series = solve_load_series(h, dx, E_STAR, loads, plasticity=law)
    oracle = solve_load_series(h, dx, E_STAR, loads, plasticity=law, method="appendix")
    for new, old in zip(series, oracle, strict=True):
        assert_same_state(new, old, p_y, h.std())
    for before, after in zip(series[:-1], series[1:], strict=True):
        flow = after.plastic_displacement - before.plastic_displacement
        assert flow.max() <= 0  # plastic depth never recovers
        assert np.all(after.pressure[flow < 0] == p_y)  # new flow only at the bound
        assert (flow < 0).any()
        np.testing.assert_array_equal(after.deformed_heights, h + after.plastic_displacement)
    # the history enters through the heights only: a fresh solve from the carried state
    # is the series' step (same problem, other starting pressure: same tolerances)
    again = solve(
        h, dx, E_STAR, load=loads[2], plasticity=law,
        plastic_displacement=series[1].plastic_displacement,
    )  # fmt: skip
    np.testing.assert_array_equal(again.contact, series[2].contact)
    np.testing.assert_allclose(again.pressure, series[2].pressure, rtol=0, atol=1e-6 * p_y)
    np.testing.assert_allclose(
        again.plastic_displacement, series[2].plastic_displacement, rtol=0,
        atol=10 * TOL * h.std(),
    )  # fmt: skip


def flat_punch(n=64, radius=12):
    """A flat circular punch (unit pixels) standing 1 above its surroundings: 448 pixels."""
    y, x = np.indices((n, n)) - n / 2 + 0.5
    punch = np.hypot(x, y) < radius
    return np.where(punch, 0.0, -1.0), punch


@pytest.mark.parametrize("deficit", [0.0, 0.5, 20.0], ids=["full", "half-pixel", "20-pixels"])
def test_flat_punch_tends_to_full_plasticity(deficit):
    """Load p_Y·(N - deficit) on an N-pixel flat punch (E* = 1, p_Y = 0.01): the contact is
    the punch, the load is met to round-off, and all but the pixels the deficit leaves
    below the bound sit at p_Y. At deficit 0 every contact pixel is at p_Y, so load =
    p_Y × area exactly, the approach is not fixed by the force and the route takes the
    smallest admissible one (bounded_load.fully_bound_approach): the least plastic flow, zero at
    one pixel of the punch. Otherwise the oracle agrees."""
    h, punch = flat_punch()
    p_y = 0.01
    n_punch = int(punch.sum())
    load = p_y * (n_punch - deficit)
    law = PenetrationHardness(p_y)
    res = solve(h, 1.0, 1.0, load=load, plasticity=law)
    assert res.success and res.info.route == "bounded"
    np.testing.assert_array_equal(res.contact, punch)
    assert res.load == pytest.approx(load, rel=1e-12)
    at_bound = res.pressure == p_y
    if deficit == 0:
        assert at_bound.sum() == n_punch
        assert res.load == pytest.approx(p_y * res.area, rel=1e-12)
        assert res.plastic_displacement[punch].max() == 0.0
        assert np.all(res.plastic_displacement[punch].min() < 0)
        assert np.all(res.gap[~punch] >= 0)
    else:
        assert n_punch - at_bound.sum() >= int(np.ceil(deficit))
        oracle = solve(h, 1.0, 1.0, load=load, plasticity=law, method="appendix")
        assert_same_state(res, oracle, p_y, h.std())


def test_infinite_hardness_is_the_elastic_solution(sphere_case):
    """p_Y = 1e3 × the elastic peak is never reached: the bounded solve is the elastic one
    to solver tolerance (1e-6 of the peak, as test_plasticity), with no plastic flow."""
    h, dx, load, _ = sphere_case
    elastic = solve(h, dx, E_STAR, load=load)
    res = solve(
        h, dx, E_STAR, load=load, plasticity=PenetrationHardness(1e3 * elastic.pressure.max())
    )
    assert res.info.route == "bounded"
    np.testing.assert_allclose(
        res.pressure, elastic.pressure, rtol=0, atol=1e-6 * elastic.pressure.max()
    )
    assert abs(res.displacement - elastic.displacement) <= 10 * TOL * h.std()
    assert not res.plastic_displacement.any()


def test_a_bounded_solve_that_cannot_converge_raises(sphere_case):
    """Two CG iterations cannot converge it: ConvergenceError by default, and with
    raise_on_failure=False an unconverged result saying so, never a silent answer."""
    h, dx, load, p_y = sphere_case
    law = PenetrationHardness(p_y)
    with pytest.raises(ConvergenceError, match="did not converge in 2 iterations"):
        solve(h, dx, E_STAR, load=load, plasticity=law, max_iter=2)
    res = solve(h, dx, E_STAR, load=load, plasticity=law, max_iter=2, raise_on_failure=False)
    assert res.success is False and res.status == 1 and res.info.route == "bounded"
    assert np.isfinite(res.pressure).all() and res.pressure.min() >= 0
    assert res.pressure.max() <= p_y


@pytest.mark.parametrize("case", ["sphere", "periodic per-pixel"])
def test_the_fused_load_step_matches_its_numpy_reference(sphere_case, case):
    """The default bounded load step keeps u = K*p by point responses and the rescale
    u <- s·u - (s - 1)·K*p_bound (bounded_load.BoundedLoadSweep); its numpy reference takes
    u afresh after every step. The same step up to one detail (a clipped free point may
    rejoin within the fused step), so the same state to the solver's tolerance (pressure
    1e-6 p_Y as above; measured 3e-8), iterations within 5 % (round-off or that detail can
    move a contact-set change by an iteration), and fewer convolutions: that is its point."""
    if case == "sphere":
        h, dx, load, p_y = sphere_case
        kw = dict(spacing=dx, e_star=E_STAR)
    else:
        h = rough_plane()
        dx, load = 1.0, 0.005 * h.size
        checker = (np.indices(h.shape).sum(axis=0) % 2).astype(float)
        p_y = 0.05 * (0.75 + 0.5 * checker)
        kw = dict(spacing=1.0, e_star=1.0, periodic=True)
    law = PenetrationHardness(p_y)
    new = solve(h, load=load, plasticity=law, **kw)
    numpy_step = replace(
        solve_options(
            h.shape,
            periodic=kw.get("periodic", False),
            tol=1e-8,
            max_iter=None,
            threads=1,
            backend=None,
            planner_effort=None,
            plasticity=law,
            method=None,
            max_outer=None,
            raise_on_failure=True,
        ),
        bounded_load_sweep=False,
    )
    ref = solve_with_options(h, kw["spacing"], kw["e_star"], numpy_step, load=load)
    assert new.success and ref.success
    np.testing.assert_array_equal(new.contact, ref.contact)
    np.testing.assert_allclose(new.pressure, ref.pressure, rtol=0, atol=1e-6 * np.max(p_y))
    assert abs(new.iterations - ref.iterations) <= max(1, 0.05 * ref.iterations)
    assert new.info.convolutions < ref.info.convolutions
    assert new.load == pytest.approx(load, rel=1e-12)


def test_a_start_above_the_bound_is_clipped_after_the_load_rescale(sphere_case):
    """A warm start whose load rescale lifts points past p_Y must not keep them there. Here
    twice the plastic state at half the load: clipped to p_Y first, it carries less than the
    load, and the rescale then lifted its bound points to 1.3 p_Y, where a step that moves
    only free points left them (a bug, fixed by clipping after the rescale). No pressure
    above p_Y, and the state of a cold start (tolerances above)."""
    h, dx, load, p_y = sphere_case
    law = PenetrationHardness(p_y)
    half = solve(h, dx, E_STAR, load=0.5 * load, plasticity=law)
    warm = solve(h, dx, E_STAR, load=load, plasticity=law, warm_start=2 * half.pressure)
    cold = solve(h, dx, E_STAR, load=load, plasticity=law)
    assert warm.pressure.max() <= p_y
    np.testing.assert_array_equal(warm.contact, cold.contact)
    np.testing.assert_allclose(warm.pressure, cold.pressure, rtol=0, atol=1e-6 * p_y)


@pytest.mark.parametrize("deficit_points", [0.4, 3.5, 40.0, 5000.0])
def test_a_deficit_fills_the_points_next_to_touch_in_gap_order(deficit_points):
    """Every loaded point at the bound and load missing: impose_bounded_load gives the
    deficit to the unloaded points with the smallest u - h, each up to its p_max, ties in
    index order (what raising the approach until they touch does). Gaps on a coarse grid of
    values so that ties are many; p_max per pixel between 1 and 2 Pa; deficits from under a
    point to more than every point can take (then all are filled). The result is that of a
    full stable sort, to the bit: the fill orders only the points it can need."""
    rng = np.random.default_rng(3)
    n = 4096
    p_max = 1.0 + rng.random(n)
    gap = np.round(rng.random(n), 2)  # 101 distinct values: ties everywhere
    h = np.zeros(n)
    p = np.zeros(n)
    loaded = rng.random(n) < 0.1
    p[loaded] = p_max[loaded]
    deficit = deficit_points * float(p_max.mean())
    target = float(p.sum()) + deficit
    got = p.copy()
    _, restarted = impose_bounded_load(
        got, np.zeros(n, np.uint8), np.zeros(n), p_max, target, gap.copy(), h
    )
    # the rule, with every unloaded point sorted, for the deficit as the function finds it
    deficit = target - float(p.sum(where=p >= p_max))
    want = p.copy()
    cand = np.flatnonzero(~loaded)
    order = cand[np.argsort(gap[cand], kind="stable")]
    room = np.cumsum(p_max[order])
    k = int(np.searchsorted(room, deficit)) + 1
    want[order[:k]] = p_max[order[:k]]
    if k <= room.size:
        want[order[k - 1]] -= room[k - 1] - deficit
    assert restarted
    np.testing.assert_array_equal(got, want)
    if k <= room.size:
        assert got.sum() == pytest.approx(target, rel=1e-12)  # the load is met
