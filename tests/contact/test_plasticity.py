"""Plasticity laws (appendix B.2.3): limits, conservation, the Winkler oracle, hard cases.

Problem sizes are small (64²–128²) so the file runs in seconds; tolerances say why."""

import numpy as np
import pytest

from amontons.contact import (
    ContactHardening,
    ContactInputError,
    ConvergenceError,
    FreeBoundaryError,
    PenetrationHardness,
    api,
    solve,
    solve_load_series,
)
from amontons.contact.surfaces import self_affine, sphere

E_STAR = 3.5e9  # PMMA on glass, Pa
R = 0.75e-3  # 1.5 mm sphere, m
K_PMMA = 7e15  # 7 MPa/nm in Pa/m


def rough_sphere(n=128, spacing=0.2e-6, rms=30e-9, seed=1):
    """A rough sphere on an n² non-periodic window (25.6 µm at the defaults)."""
    return sphere((n, n), spacing, R) + self_affine(
        (n, n), spacing, 0.8, rms_height=rms, rng=seed
    ), spacing


@pytest.fixture(scope="module")
def rough():
    return rough_sphere()


@pytest.fixture(scope="module")
def elastic(rough):
    h, dx = rough
    return solve(h, dx, E_STAR, load=3e-3)


def test_huge_hardness_is_elastic(rough, elastic):
    h, dx = rough
    law = PenetrationHardness(p_y=1e3 * elastic.pressure.max())
    res = solve(h, dx, E_STAR, load=3e-3, plasticity=law)
    # The bound is never active, so the bounded solve is the elastic one to solver tolerance.
    np.testing.assert_allclose(
        res.pressure, elastic.pressure, rtol=0, atol=1e-6 * elastic.pressure.max()
    )
    assert not res.plastic_displacement.any()


def test_tiny_hardness_gives_the_bearing_area_and_carries_exactly_py_times_area(rough):
    h, dx = rough
    p_y = 1e-6 * E_STAR
    load = 200 * p_y * dx**2  # the load of 200 fully plastic pixels
    res = solve(h, dx, E_STAR, load=load, plasticity=PenetrationHardness(p_y))
    plastic = res.pressure >= p_y * (1 - 1e-12)
    partial = res.contact & ~plastic
    # Fully plastic: every contact pixel but at most one (the pixel being filled) is at p_Y.
    assert partial.sum() <= 1
    # Load exact: F = p_Y·A over the plastic pixels plus the partial one.
    assert res.load == pytest.approx(
        p_y * dx**2 * plastic.sum() + res.pressure[partial].sum() * dx**2, rel=1e-12
    )
    assert abs(res.load - load) <= p_y * dx**2
    # Bearing area: the contact is the set of the highest pixels of the indenter. Elastic
    # deflection is ~p_Y·Δx/E* = 1e-6 Δx, far below height differences between pixels.
    highest = np.argsort(h.ravel())[::-1][: res.contact.sum()]
    bearing = np.zeros(h.size, dtype=bool)
    bearing[highest] = True
    assert np.count_nonzero(bearing.reshape(h.shape) != res.contact) == 0


def test_plastic_gap_is_closed_and_plastic_displacement_is_the_penetration(rough, elastic):
    h, dx = rough
    p_y = 0.5 * elastic.pressure.max()
    res = solve(h, dx, E_STAR, load=3e-3, plasticity=PenetrationHardness(p_y))
    # The elastic solve converges on the rms gap of its free set (tol 1e-8·h_rms, cg.py), so
    # a single point may sit a few times deeper; 10× bounds that, 1e-15 m here.
    tol = 10 * 1e-8 * h.std()
    assert res.gap.min() >= -tol
    assert np.all(res.pressure <= p_y * (1 + 1e-12))
    # Plastic flow only where the bound is reached.
    assert np.all(res.pressure[res.plastic_displacement < 0] >= p_y * (1 - 1e-9))
    assert res.load == pytest.approx(3e-3, rel=1e-8)


def test_local_and_volume_conserving_increments_give_the_same_area():
    # 64² and tol 1e-6: B.3 needs ~90 under-relaxed updates per approach, so the 128² case
    # would take half a minute; ~180 contact pixels still resolve a 5 % difference.
    h, dx = rough_sphere(n=64)
    p_y = 0.5 * solve(h, dx, E_STAR, load=4e-4).pressure.max()
    local = solve(h, dx, E_STAR, load=4e-4, plasticity=PenetrationHardness(p_y), tol=1e-6)
    volume = solve(
        h,
        dx,
        E_STAR,
        load=4e-4,
        plasticity=PenetrationHardness(p_y, increment="volume", alpha=0.5),
        tol=1e-6,
    )
    assert local.plastic_displacement.any()  # the bound is active
    # The appendix reports no difference in total contact area; pile-up makes a few new
    # contacts at patch rims, so a few percent (5 %) is allowed.
    assert volume.area == pytest.approx(local.area, rel=0.05)
    # B.3 moves volume, it does not remove it.
    assert abs(volume.plastic_displacement.sum()) < 1e-9 * np.abs(volume.plastic_displacement).sum()


def ramped_appendix_scheme(h, dx, approaches, substeps, k=K_PMMA):
    """The appendix's iterative hardening scheme (under-relaxed α = 0.5, iterated to a
    non-negative gap), driven quasi-statically: the approach rises from first touch in
    ``substeps`` equal steps per target, each starting from the previous plastic state.
    Returns the state at each target approach."""
    law = ContactHardening(k, alpha=0.5)
    d_prev, plastic, states = -h.max(), None, []
    for target in approaches:
        for d in np.linspace(d_prev, target, substeps + 1)[1:]:
            state = solve(
                h,
                dx,
                E_STAR,
                displacement=d,
                plasticity=law,
                plastic_displacement=plastic,
                method="appendix",
                tol=1e-6,
                max_outer=2000,
            )
            plastic = state.plastic_displacement
        states.append(state)
        d_prev = target
    return states


def test_hardening_matches_the_ramped_appendix_scheme_on_a_load_series():
    h, dx = rough_sphere(n=64)
    loads = [2e-4, 4e-4]
    series = solve_load_series(h, dx, E_STAR, loads, plasticity=ContactHardening(K_PMMA))
    # load control hits its loads to the solver tolerance
    assert [r.load for r in series] == pytest.approx(loads, rel=1e-8)
    # Every contact point sits on its yield surface, p = k·|h_pl|.
    for res in series:
        np.testing.assert_allclose(
            res.pressure[res.contact], -K_PMMA * res.plastic_displacement[res.contact], rtol=1e-9
        )
    # The history is carried: plastic depth never recovers from one load to the next, and
    # the deformed topography is h + h_pl.
    assert np.all(series[1].plastic_displacement <= series[0].plastic_displacement)
    np.testing.assert_array_equal(series[1].deformed_heights, h + series[1].plastic_displacement)
    approaches = [r.displacement for r in series]
    coarse = ramped_appendix_scheme(h, dx, approaches, substeps=20)
    fine = ramped_appendix_scheme(h, dx, approaches, substeps=80)
    for res, c, f in zip(series, coarse, fine, strict=True):
        # A finite jump of the approach lets the under-relaxed scheme overshoot (points flow,
        # then open as neighbours load): the quasi-static limit is the Winkler state. With
        # 80 sub-steps per load the area is within 1 % and the load within 1 % (measured:
        # 0.6 % and 0.2 %), and refining the ramp moves the oracle toward the Winkler state.
        assert f.area == pytest.approx(res.area, rel=0.01)
        assert f.load == pytest.approx(res.load, rel=0.01)
        assert abs(f.area - res.area) <= abs(c.area - res.area)


def test_stiff_hardening_tends_to_elastic(rough, elastic):
    h, dx = rough
    res = solve(h, dx, E_STAR, load=3e-3, plasticity=ContactHardening(1e6 * E_STAR / dx))
    # The Winkler layer's compliance is 1e-6 of a pixel's elastic compliance.
    np.testing.assert_allclose(
        res.pressure, elastic.pressure, rtol=0, atol=1e-4 * elastic.pressure.max()
    )


def test_hardening_area_grows_sublinearly_and_the_exponent_is_stable_under_refinement():
    loads = np.array([0.5e-3, 1e-3, 2e-3, 4e-3])
    exponents = []
    for n, dx in [(64, 0.4e-6), (128, 0.2e-6)]:
        h = sphere((n, n), dx, R) + coarse_roughness(n)
        series = solve_load_series(h, dx, E_STAR, loads, plasticity=ContactHardening(K_PMMA))
        areas = np.array([r.area for r in series])
        exponents.append(power_law_exponent(loads, areas))
    assert all(0.5 < a < 1 for a in exponents)
    # Same roughness on both grids (band-limited to wavelengths ≥ 4 coarse pixels):
    # refinement changes the exponent by the pixelisation of patch edges only. Measured:
    # 0.812 (64²), 0.814 (128²), 0.818 (256²), i.e. 0.003 per halving of the pixel.
    assert abs(exponents[1] - exponents[0]) < 0.03


def power_law_exponent(x, y):
    """Least-squares slope of log y against log x (the exponent α of y ∝ x^α)."""
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def coarse_roughness(n, window=25.6e-6):
    """The same band-limited roughness sampled on an n² grid over the same window."""
    base = self_affine(
        (64, 64), window / 64, 0.8, rms_height=30e-9, short_cutoff=4 * window / 64, rng=5
    )
    spectrum = np.fft.rfft2(base)
    padded = np.zeros((n, n // 2 + 1), dtype=complex)
    padded[:32, :33] = spectrum[:32, :33]
    padded[-32:, :33] = spectrum[-32:, :33]
    return np.fft.irfft2(padded, s=(n, n)) * (n / 64) ** 2


# --- hard cases: converge, or fail loudly ---------------------------------------------------


def test_near_full_contact_converges():
    n, dx = 64, 0.1e-6
    h = self_affine((n, n), dx, 0.8, rms_height=5e-9, rng=3)
    # Periodic, mean pressure 5× the full-contact scale E*·h'_rms: > 95 % contact.
    res = solve(
        h,
        dx,
        E_STAR,
        load=5 * E_STAR * 0.05 * (n * dx) ** 2,
        periodic=True,
        plasticity=ContactHardening(K_PMMA),
    )
    assert res.contact_fraction > 0.95 and res.converged
    assert np.all(np.isfinite(res.pressure))


def test_single_asperity_contact_converges():
    h, dx = rough_sphere(n=64)
    res = solve(h, dx, E_STAR, load=1e-9, plasticity=ContactHardening(K_PMMA))
    assert 1 <= res.contact.sum() <= 4 and res.load == pytest.approx(1e-9, rel=1e-8)


@pytest.mark.parametrize(
    ("k", "load"),
    [(1e-6 * E_STAR / 0.2e-6, 1e-9), (1e6 * E_STAR / 0.2e-6, 1e-4)],
    ids=["k-tiny", "k-huge"],
)
def test_extreme_hardening_coefficients_stay_finite(k, load):
    """k 1e-6 and 1e6 times a pixel's elastic stiffness E*/Δx: the Winkler layer dominates the
    operator or vanishes beside it. (A tiny k spreads the contact, so its load is smaller
    to keep it inside the window.)"""
    h, dx = rough_sphere(n=64)
    res = solve(h, dx, E_STAR, load=load, plasticity=ContactHardening(k))
    assert res.converged and np.all(np.isfinite(res.pressure))
    assert res.load == pytest.approx(load, rel=1e-8)
    assert res.contact.sum() >= 1


def test_flat_plateau_converges():
    h, dx = rough_sphere(n=64)
    h = np.minimum(h, np.quantile(h, 0.9))  # a flat top over 10 % of the window
    # a flat punch: the elastic pressure is singular at its rim, so the rim flows
    res = solve(h, dx, E_STAR, load=1e-4, plasticity=PenetrationHardness(20e6))
    assert res.converged and res.gap.min() >= -10 * 1e-8 * h.std()  # as in the test above
    assert res.plastic_displacement.any() and res.pressure.max() <= 20e6 * (1 + 1e-12)


def test_contact_reaching_the_window_edge_is_an_error():
    h, dx = rough_sphere(n=64)
    with pytest.raises(FreeBoundaryError, match="window edge"):
        solve(h, dx, E_STAR, load=1.0, plasticity=ContactHardening(K_PMMA))


def test_plastic_iteration_that_cannot_converge_raises():
    h, dx = rough_sphere(n=64)
    law = PenetrationHardness(50e6, increment="volume", alpha=0.5)
    with pytest.raises(ConvergenceError, match="plastic iteration"):
        solve(h, dx, E_STAR, load=1e-3, plasticity=law, max_outer=1)


def test_load_beyond_the_window_at_the_hardness_is_a_window_too_small():
    """Σ p_Y·Δx² is the most the window can carry; more is not a convergence problem. On a
    half-space the contact would outgrow the window (FreeBoundaryError, as when a solution's
    pressure reaches the edge: a scan records the value as outside the window); on a periodic
    surface no state carries the load (an input error)."""
    h, dx = rough_sphere(n=32)
    p_y = 1e5
    load = 1.5 * p_y * h.size * dx**2
    with pytest.raises(FreeBoundaryError, match="needs more than the whole window"):
        solve(h, dx, E_STAR, load=load, plasticity=PenetrationHardness(p_y))
    with pytest.raises(ContactInputError, match="needs more than the whole window"):
        solve(h, dx, E_STAR, load=load, plasticity=PenetrationHardness(p_y), periodic=True)


def test_series_with_a_load_beyond_the_window_is_refused_before_any_step(monkeypatch):
    """A series whose loads pass what the window at the hardness can carry is refused before
    its first step is solved: that step would be refused anyway, and the steps below it
    would be solved for nothing (a p_Y scan's softest values). The error is the one that
    step raises, and names the first load beyond the window (step 2 of 3 here)."""
    h, dx = rough_sphere(n=32)
    p_y = 1e5
    capacity = p_y * h.size * dx**2
    loads = [0.1 * capacity, 1.5 * capacity, 2.0 * capacity]

    def solved(*args, **kwargs):
        raise AssertionError("a step was solved")

    monkeypatch.setattr(api, "run_route", solved)
    with pytest.raises(FreeBoundaryError, match="needs more than the whole window") as info:
        solve_load_series(h, dx, E_STAR, loads, plasticity=PenetrationHardness(p_y))
    assert "load step 2 of 3" in "".join(getattr(info.value, "__notes__", []))


def test_load_controlled_appendix_schemes_reach_their_load():
    """Warm starts from trial approaches exceed the fresh bound k·|h_pl| = 0; the bounded solve
    clips them, so the root find on the approach meets the load (tolerance 1e-8 relative).
    64² sphere with 2 nm noise; local increments on request, volume-conserving ones by
    default (the only route for them)."""
    n, dx = 64, 1e-6
    h = sphere((n, n), dx, 5e-3) + 2e-9 * np.random.default_rng(1).standard_normal((n, n))
    for law, method in (
        (ContactHardening(K_PMMA, alpha=0.5), "appendix"),
        (ContactHardening(K_PMMA, increment="volume", alpha=0.5), None),
    ):
        res = solve(h, dx, 3e9, load=2e-3, plasticity=law, method=method)
        assert res.load == pytest.approx(2e-3, rel=1e-8)
        assert res.info.route == "appendix" and res.success


def test_pile_up_history_is_refused_by_the_winkler_route():
    h, dx = rough_sphere(n=32)
    bump = np.zeros_like(h)
    bump[16, 16] = 5e-9
    with pytest.raises(ContactInputError, match="pile-up"):
        solve(
            h, dx, E_STAR, load=1e-5, plasticity=ContactHardening(K_PMMA), plastic_displacement=bump
        )
