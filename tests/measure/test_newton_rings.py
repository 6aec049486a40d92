"""Newton-ring gap at the contact edge (appendix eq. B.1, Figs. B.6–B.7) and the Hertz gap."""

import numpy as np
import pytest
from scipy.integrate import dblquad

from amontons.measure.newton_rings import (
    FREE_RADIUS,
    NewtonRingError,
    half_profile_angles,
    newton_ring_gap,
)
from amontons.physics import hertz
from amontons.physics.hertz import exterior_gap
from amontons.physics.newton_rings import ring_gap
from amontons.virtual.reflection import expected_reflection, radial_gap_map, render_reflection

# Smooth glass sphere of 4 mm diameter on glass, E* = 32.8 GPa, 100 mN: a = 16.6 µm.
RADIUS, E_STAR, LOAD = 2e-3, 32.8e9, 0.1
A = hertz.contact_radius(LOAD, RADIUS, E_STAR)
PIXEL = 200e-9
SHAPE = (600, 600)  # 120 µm: 4–6 rings along each half-profile
CENTRE = (299.3, 300.6)  # off the pixel grid on purpose
SHEET = "hertz_sheet_radius"


def hertz_reflection(
    seed: int, edge_offset_m: float = 0.0, shape=SHAPE, centre=CENTRE
) -> np.ndarray:
    """Rings of a Hertz gap, shifted by ``edge_offset_m`` outside the contact (0 inside).

    400 mean counts, fringe contrast 0.6: Poisson noise of ~20 counts on fringes of ±240.
    """

    def gap(r):
        return np.where(r > A, exterior_gap(r, LOAD, RADIUS, E_STAR) + edge_offset_m, 0.0)

    gap_map = radial_gap_map(shape, PIXEL, centre, gap)
    return render_reflection(gap_map, PIXEL, rng=np.random.default_rng(seed))


# --- the Hertz gap -----------------------------------------------------------------------------


def test_hertz_gap_is_zero_at_and_inside_the_edge():
    r = np.array([0.0, 0.5 * A, A])
    np.testing.assert_array_equal(exterior_gap(r, LOAD, RADIUS, E_STAR), 0.0)


def test_hertz_gap_is_continuous_with_zero_slope_at_the_edge():
    # Next to the edge g ≈ C·(r − a)^{3/2}: the gap 1.7 nm outside the edge is below 1 pm and
    # its ratio over two steps is 2^{3/2} to 1 %.
    g1, g2 = exterior_gap(np.array([A * (1 + 1e-4), A * (1 + 2e-4)]), LOAD, RADIUS, E_STAR)
    assert 0 < g1 < 1e-12
    assert g2 / g1 == pytest.approx(2**1.5, rel=0.01)


def test_hertz_gap_far_field():
    # g − (r²/2R − d) = u(r) → 4a³/(3πRr) with a relative correction O(a²/r²): 1 % at r = 20a.
    r = 20 * A
    d = hertz.approach(LOAD, RADIUS, E_STAR)
    excess = exterior_gap(np.array([r]), LOAD, RADIUS, E_STAR)[0] - (r**2 / (2 * RADIUS) - d)
    assert excess == pytest.approx(4 * A**3 / (3 * np.pi * RADIUS * r), rel=0.01)


def test_hertz_gap_against_boussinesq_integral():
    # Independent check: u(r) = (1/πE*)∬ p(ρ)/|r − ρ| dA over the Hertz pressure, by quadrature
    # (no singularity for r > a); relative tolerance 1e-6 is the quadrature's accuracy.
    p0 = hertz.peak_pressure(LOAD, RADIUS, E_STAR)
    r = 1.5 * A

    def integrand(phi, rho):
        pressure = p0 * np.sqrt(1 - (rho / A) ** 2)
        return pressure * rho / np.sqrt(r**2 + rho**2 - 2 * r * rho * np.cos(phi))

    integral, _ = dblquad(integrand, 0, A, 0, 2 * np.pi, epsabs=0, epsrel=1e-10)
    u = integral / (np.pi * E_STAR)
    expected = r**2 / (2 * RADIUS) - hertz.approach(LOAD, RADIUS, E_STAR) + u
    assert exterior_gap(np.array([r]), LOAD, RADIUS, E_STAR)[0] == pytest.approx(expected, rel=1e-6)


# --- eq. B.1 and the phase convention ---------------------------------------------------------


def test_ring_gaps_in_formamide():
    # d_m = (m + ½)·488 nm/(2·1.447): 84.32, 252.94, 421.56 nm (to 0.1 nm).
    gaps_nm = ring_gap(np.arange(3), 488e-9, 1.447) * 1e9
    np.testing.assert_allclose(gaps_nm, [84.32, 252.94, 421.56], atol=0.1)


def test_bright_rings_sit_at_eq_b1_and_contact_is_dark():
    gaps = ring_gap(np.arange(4), 488e-9, 1.447)
    bright = expected_reflection(gaps, 488e-9, 1.447, background=400, contrast=0.6)
    np.testing.assert_allclose(bright, 400 * 1.6)
    dark = expected_reflection(np.array([0.0]), 488e-9, 1.447, background=400, contrast=0.6)
    assert dark[0] == pytest.approx(400 * 0.4)


# --- the measurement ---------------------------------------------------------------------------


@pytest.mark.parametrize("seed", [0, 1])
def test_edge_gap_of_a_hertz_contact_is_zero_within_2_nm(seed):
    # Truth: 0 nm at the edge. Over 4 seeds the mean of 40 half-profiles is +0.5 ± 0.1 nm (a
    # small peak-refinement bias on chirped fringes), the per-profile sd ~1 nm: 2 nm holds.
    result = newton_ring_gap(
        hertz_reflection(seed), PIXEL, CENTRE, A, edge_model=SHEET, shape_radius_m=A
    )
    assert result.edge_gap_mean_m == pytest.approx(0.0, abs=2e-9)
    assert result.edge_gap_sd_m < 3e-9
    assert result.edge_gaps_m.size == 40
    assert result.first_ring_gap_m == pytest.approx(84.32e-9, abs=0.1e-9)
    # The innermost ring sits where the Hertz gap is 84.3 nm (r = 27.19 µm), within 0.1 µm.
    first = [p.ring_r_m[0] for p in result.half_profiles]
    assert np.mean(first) == pytest.approx(27.19e-6, abs=0.1e-6)


def test_edge_gap_of_an_offset_contact_is_recovered_within_2_nm():
    # The gap outside the contact is Hertz + 5 nm, so the truth at the edge is 5 nm.
    result = newton_ring_gap(
        hertz_reflection(2, edge_offset_m=5e-9),
        PIXEL,
        CENTRE,
        A,
        edge_model=SHEET,
        shape_radius_m=A,
    )
    assert result.edge_gap_mean_m == pytest.approx(5e-9, abs=2e-9)


def test_an_edge_inside_the_hertz_radius_needs_the_hertz_shape_of_the_load():
    # A patchy contact's fluorescent edge lies inside the radius its far field follows (the
    # rough glass sphere: ~15 % inside). Truth: 0 nm at and inside the Hertz edge A. Fitting
    # the Hertz shape of the load's radius recovers it within 2 nm; a shape of the
    # fluorescent edge's radius misses the rings' curvature and reads several nm too low.
    edge = 0.85 * A
    image = hertz_reflection(4)
    right = newton_ring_gap(image, PIXEL, CENTRE, edge, edge_model=SHEET, shape_radius_m=A)
    wrong = newton_ring_gap(image, PIXEL, CENTRE, edge, edge_model=SHEET, shape_radius_m=edge)
    assert right.edge_gap_mean_m == pytest.approx(0.0, abs=2e-9)
    assert wrong.edge_gap_mean_m < -4e-9


def test_appendix_quadratic_extrapolation_is_biased_on_hertz():
    # Documents why the default is the Hertz-shape fit: a parabola through the rings misses
    # the (r − a)^{3/2} rise at the edge and reports ≈ −18 nm where the truth is 0.
    result = newton_ring_gap(hertz_reflection(3), PIXEL, CENTRE, A, edge_model="quadratic")
    assert -25e-9 < result.edge_gap_mean_m < -10e-9


def test_centre_outside_the_image_is_refused():
    with pytest.raises(NewtonRingError, match=r"centre \(row -3, col 300\) px lies outside"):
        newton_ring_gap(hertz_reflection(4), PIXEL, (-3, 300), A)


def test_too_few_rings_names_the_profile_angle():
    # A 70 µm image holds only the first ring (27 µm) along the axes.
    centre = (174.3, 175.6)
    image = hertz_reflection(5, shape=(350, 350), centre=centre)
    with pytest.raises(NewtonRingError, match=r"profile at 0\.0°: 1 ring maxima"):
        newton_ring_gap(image, PIXEL, centre, A)


def test_image_without_rings_is_refused():
    flat = np.random.default_rng(6).poisson(400, size=SHAPE).astype(np.uint16)
    with pytest.raises(NewtonRingError, match="0 ring maxima"):
        newton_ring_gap(flat, PIXEL, CENTRE, A)


def test_contact_radius_swallowing_the_first_ring_is_refused():
    # An edge radius of 30 µm would put ring 0 (27 µm) inside the contact: orders ambiguous.
    with pytest.raises(NewtonRingError, match="inside the contact edge"):
        newton_ring_gap(hertz_reflection(7), PIXEL, CENTRE, 30e-6)


def test_missed_ring_is_refused_rather_than_misnumbered():
    # Blank the annulus of ring 1 (38.2 µm) to the mean level: ring 2 would otherwise be
    # numbered 1 and every gap beyond it would be 168.6 nm too small.
    image = hertz_reflection(8).astype(float)
    rows, cols = np.indices(SHAPE)
    r = np.hypot(rows - CENTRE[0], cols - CENTRE[1]) * PIXEL
    image[np.abs(r - 38.2e-6) < 3e-6] = 400.0
    with pytest.raises(NewtonRingError, match="a ring in between was probably missed"):
        newton_ring_gap(image, PIXEL, CENTRE, A)


# --- the Hertz radius: from the sheet's E*, or fitted to the rings (issue 16, item 4) ----------


def test_free_radius_fit_does_not_hang_on_the_sheet_e_star():
    """The sheet-radius fit takes the Hertz radius from E*: with E* off by ±20 % its gap is
    off by +13 / −6 nm on this sphere. The free-radius fit takes the radius from the rings
    and does not read E*: within 2 nm of the true 0 (mean of three noise seeds; single seeds
    from −0.1 to +2.0 nm over six, the +0.5 nm peak-refinement bias of the test above
    included), and its radius within 2 % of the true one."""
    free, radii = [], []
    for seed in (0, 1, 2):
        image = hertz_reflection(seed)
        result = newton_ring_gap(image, PIXEL, CENTRE, A, edge_model=FREE_RADIUS)
        free.append(result.edge_gap_mean_m)
        radii.append(result.shape_radius_m)
        for factor, sign in ((0.8, 1), (1.2, -1)):
            wrong_a = hertz.contact_radius(LOAD, RADIUS, E_STAR * factor)
            sheet = newton_ring_gap(
                image, PIXEL, CENTRE, A, edge_model=SHEET, shape_radius_m=wrong_a
            )
            assert sign * sheet.edge_gap_mean_m > 5e-9
    assert np.mean(free) == pytest.approx(0.0, abs=2e-9)
    assert max(abs(g) for g in free) < 3e-9
    np.testing.assert_allclose(radii, A, rtol=0.02)


def test_each_profile_is_extrapolated_to_its_own_edge():
    """Per-profile edges: the same rings give a larger gap on a ray whose edge lies further
    out. The edge of half the rays at A, of the other half 1.3·A: outside the Hertz radius the
    sheet-radius curve is the Hertz gap, S(1.3 A)/R = 18.6 nm here."""
    angles = half_profile_angles(20)
    edges = np.where(np.arange(angles.size) % 2 == 0, A, 1.3 * A)
    result = newton_ring_gap(
        hertz_reflection(9), PIXEL, CENTRE, edges, edge_model=SHEET, shape_radius_m=A
    )
    np.testing.assert_allclose(result.edge_radii_m, edges)
    near = result.edge_gaps_m[::2]
    far = result.edge_gaps_m[1::2]
    expected_far = exterior_gap(np.array([1.3 * A]), LOAD, RADIUS, E_STAR)[0]
    assert np.mean(near) == pytest.approx(0.0, abs=2e-9)
    assert np.mean(far) == pytest.approx(expected_far, abs=2e-9)


def test_a_ray_without_contact_is_refused_with_its_angle():
    angles = half_profile_angles(20)
    edges = np.full(angles.size, A)
    edges[3] = np.nan
    result = newton_ring_gap(
        hertz_reflection(10), PIXEL, CENTRE, edges, edge_model=SHEET, shape_radius_m=A
    )
    assert result.edge_gaps_m.size == 39
    assert any("27.0°: the ray meets no contact" in r for r in result.rejected)


def test_sheet_radius_model_without_a_radius_is_refused():
    with pytest.raises(NewtonRingError, match="needs the sheet's Hertz radius"):
        newton_ring_gap(hertz_reflection(11), PIXEL, CENTRE, A, edge_model=SHEET)
