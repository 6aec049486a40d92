"""A scan of plasticity laws warm-started from its neighbours (``solve_scan``): the same
states as independent load series, for fewer CG iterations where neighbours agree.

Tolerances, and why: pressure within 1e-6 of p_Y and the contact set identical, as the
bounded route is held to its root-find oracle (test_hardness_bounded.py): both runs
converge the same problem to tol = 1e-8 from different starts. Problem size 128², so the
file runs in seconds.
"""

import numpy as np
import pytest

from amontons.contact import (
    ContactInputError,
    PenetrationHardness,
    solve_load_series,
    solve_scan,
)
from amontons.contact.surfaces import self_affine, sphere

E_STAR, R, TOL = 3.5e9, 0.75e-3, 1e-8  # Pa, m, the solver's default tolerance
LOADS = [0.5e-3, 1e-3, 2e-3]  # N
# from never binding (the elastic peak at 2 mN is ~106 MPa here) to strongly plastic
P_Y = [300e6, 200e6, 40e6, 20e6]  # Pa


@pytest.fixture(scope="module")
def rough_sphere():
    n, dx = 128, 0.3e-6
    h = sphere((n, n), dx, R) + self_affine((n, n), dx, 0.8, rms_height=30e-9, rng=4)
    return h, dx


@pytest.fixture(scope="module")
def scans(rough_sphere):
    h, dx = rough_sphere
    laws = [PenetrationHardness(p) for p in P_Y]
    independent = [solve_load_series(h, dx, E_STAR, LOADS, plasticity=law) for law in laws]
    return independent, solve_scan(h, dx, E_STAR, LOADS, laws)


def test_a_scan_reaches_the_states_of_independent_series(scans):
    independent, scan = scans
    assert len(scan) == len(P_Y) and all(len(series) == len(LOADS) for series in scan)
    for p_y, ours, theirs in zip(P_Y, scan, independent, strict=True):
        for a, b in zip(ours, theirs, strict=True):
            assert a.success and b.success
            np.testing.assert_array_equal(a.contact, b.contact)
            np.testing.assert_allclose(a.pressure, b.pressure, rtol=0, atol=1e-6 * p_y)
            assert a.load == pytest.approx(b.load, rel=1e-8)


def test_a_neighbour_that_never_binds_costs_almost_nothing(scans):
    """300 and 200 MPa both lie above the elastic peak: the second value's contact is the
    first's, so its warm start is already converged (a few iterations per load, against the
    full count from the previous load's start)."""
    independent, scan = scans
    peak = max(float(r.pressure.max()) for r in independent[0])
    assert peak < P_Y[1], "the test needs two values that never bind"
    assert sum(r.iterations for r in scan[1]) <= 2 * len(LOADS)
    assert sum(r.iterations for r in independent[1]) > 10 * len(LOADS)


def test_a_neighbour_start_saves_iterations_over_the_whole_scan(scans):
    independent, scan = scans
    ours = sum(r.iterations for series in scan for r in series)
    theirs = sum(r.iterations for series in independent for r in series)
    assert ours < theirs


def test_warm_starts_need_one_pressure_per_load(rough_sphere):
    h, dx = rough_sphere
    with pytest.raises(ContactInputError, match=r"one pressure per load \(3\), got 2"):
        solve_load_series(h, dx, E_STAR, LOADS, warm_starts=[np.zeros(h.shape)] * 2)


def test_a_scan_sets_the_law_itself(rough_sphere):
    h, dx = rough_sphere
    with pytest.raises(ContactInputError, match="solve_scan sets plasticity itself"):
        solve_scan(h, dx, E_STAR, LOADS, [PenetrationHardness(1e8)], plasticity=None)


def test_a_missing_start_is_the_series_own_previous_load(rough_sphere, scans):
    """A start of None at a load (a neighbour that did not solve it) starts that load as a
    series without neighbours does: from its previous load scaled up, the first from nothing.
    The same starts give the same iterates: results equal to the last bit."""
    h, dx = rough_sphere
    law = PenetrationHardness(P_Y[2])
    independent = scans[0][2]
    with_none = solve_load_series(h, dx, E_STAR, LOADS, plasticity=law, warm_starts=[None] * 3)
    for a, b in zip(with_none, independent, strict=True):
        np.testing.assert_array_equal(a.pressure, b.pressure)
        assert a.iterations == b.iterations
    neighbour = scans[1][1]  # 200 MPa's series in the scan
    mixed = solve_load_series(
        h, dx, E_STAR, LOADS, plasticity=law, warm_starts=[None, neighbour[1].pressure, None]
    )
    assert [r.success for r in mixed] == [True] * 3
    np.testing.assert_array_equal(mixed[0].pressure, independent[0].pressure)
    for a, b in zip(mixed, independent, strict=True):
        np.testing.assert_array_equal(a.contact, b.contact)
        np.testing.assert_allclose(a.pressure, b.pressure, rtol=0, atol=1e-6 * P_Y[2])
