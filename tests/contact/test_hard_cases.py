"""Hard cases of the contact solver: each converges to a sound state, or fails with a typed
error that names the offending value (issue 18).

Every solved case goes through :func:`assert_sound`, which checks what any solution must
satisfy whatever its route: finite fields, force balance, complementarity (gap x pressure),
the pressure bound 0 <= p <= p_Y and convergence within its caps. The cases that only exist
in another module (tests/contact/test_errors.py, test_plasticity.py) are not repeated here;
where one is extended the docstring says so.

Problem sizes are 32²-64² so the module runs in a few seconds.
"""

import numpy as np
import pytest

from amontons.contact import (
    ContactHardening,
    ContactInputError,
    FreeBoundaryError,
    PenetrationHardness,
    solve,
    solve_load_series,
)
from amontons.contact.surfaces import self_affine, sphere

E_STAR = 3.5e9  # PMMA on glass, Pa
R = 0.75e-3  # 1.5 mm sphere, m
DX = 0.2e-6  # grid spacing of the rough-sphere cases, m
TOL = 1e-8  # the solver's default tolerance (dimensionless)
MPA_PER_NM = 1e15  # 1 MPa/nm in Pa/m
# Slack on the solver's own criteria. The CG stops when the rms gap on the contact set and
# the worst penetration off it are below tol·h_rms (docs/models.md §2.2), judged before the
# approach d is re-evaluated on the final field; the plastic routes judge it on their last
# sub-problem. 2x covers both: over the cases below the largest value of either measure was
# 0.56 tol (the largest load of the six-decade series).
SLACK = 2


def rough_sphere(shape=(64, 64), rms=30e-9, seed=1):
    """A rough 1.5 mm sphere on a non-periodic window of ``shape`` pixels (12.8 µm at 64)."""
    return sphere(shape, DX, R) + self_affine(shape, DX, 0.8, rms_height=rms, rng=seed)


def rough_plane(shape=(64, 64), rms_slope=0.1, seed=7, hurst=0.8):
    """A periodic self-affine surface, unit spacing (lengths in units of the pixel)."""
    return self_affine(shape, 1.0, hurst, rms_slope=rms_slope, rng=seed)


def assert_sound(res, load=None, p_y=None):
    """Assert the invariants every converged solution satisfies (SI units throughout).

    * finite pressure, gap and displacements;
    * force balance: A0 Σp equals the imposed load to 1e-10 relative for an elastic solve
      and the bounded route of penetration hardness (load control rescales p exactly), to
      tol for the other plastic routes (their root find on the approach stops there), or
      to one pixel at p_Y where the load is a staircase of the approach (a fully plastic
      contact; docs/models.md §2.3);
    * no penetration off the contact set: gap >= -SLACK·tol·h_rms where p = 0;
    * complementarity: Σ|g|·p <= SLACK·tol·h_rms·sqrt(n_c Σp²), which is what the rms-gap
      criterion on the contact set gives by Cauchy–Schwarz (n_c contact pixels);
    * bound 0 <= p <= p_Y (to 1e-12 relative, the bound is applied by clipping);
    * converged, within its caps (iterations <= max_iter for an elastic solve or the
      one bounded solve of penetration hardness, outer rounds <= max_outer for the other
      plastic routes).
    """
    heights = res.deformed_heights
    h_rms = float(np.std(res.heights)) or res.spacing
    for name in ("pressure", "gap", "elastic_displacement", "plastic_displacement"):
        assert np.isfinite(getattr(res, name)).all(), name
    assert np.isfinite(res.displacement)
    assert res.success and res.status == 0, res.message
    if res.info.route in ("elastic", "bounded"):
        # one CG solve; the bounded route's one solve-and-update is its only outer round
        assert res.iterations <= res.info.max_iter
        assert res.info.outer_iterations == (res.info.route == "bounded")
    else:
        assert res.info.outer_iterations <= res.info.max_outer
    p = res.pressure
    if load is not None and res.info.route in ("elastic", "bounded"):
        # load control imposes the load on the field itself (a rescale, of the free points
        # on the bounded route): exact to round-off
        assert abs(p.sum() * res.spacing**2 - load) <= 1e-10 * load
    elif load is not None:
        pixel = 0.0 if p_y is None else float(np.max(p_y)) * res.spacing**2
        assert abs(p.sum() * res.spacing**2 - load) <= max(TOL * load, pixel)
    assert p.min() >= 0
    if p_y is not None:
        assert (p <= np.asarray(p_y) * (1 + 1e-12)).all()
    gap = res.elastic_displacement - heights - res.displacement
    np.testing.assert_allclose(gap, res.gap, rtol=0, atol=1e-9 * h_rms)
    off = p == 0
    if off.any():
        assert gap[off].min() >= -SLACK * TOL * h_rms
    n_c = int(np.count_nonzero(p))
    if n_c:
        weighted = float(np.sum(np.abs(gap) * p))
        assert weighted <= SLACK * TOL * h_rms * np.sqrt(n_c * float(np.sum(p**2)))


# --- elastic geometry -----------------------------------------------------------------------


def test_near_full_contact_periodic():
    """Mean pressure 2 E*·h'_rms on a rough plane (rms slope 0.1): > 99 % of the window in
    contact, the regime where the free set is almost everything."""
    h = rough_plane()
    load = 2 * 0.1 * h.size  # E* = 1, unit pixels
    res = solve(h, 1.0, 1.0, load=load, periodic=True)
    assert res.contact_fraction > 0.99
    assert_sound(res, load)


def test_single_asperity_carries_the_whole_load():
    """1 pN on the rough sphere touches one asperity only (<= 4 pixels, all adjacent to the
    highest point)."""
    h = rough_sphere()
    res = solve(h, DX, E_STAR, load=1e-12)
    assert 1 <= res.contact.sum() <= 4
    top = np.unravel_index(np.argmax(h), h.shape)
    assert res.contact[top]
    assert_sound(res, 1e-12)


def test_very_steep_topography():
    """rms slope 2 (far outside the small-slope theory, still a valid BEM problem)."""
    h = rough_plane(rms_slope=2.0, hurst=0.3, seed=4)
    res = solve(h, 1.0, 1.0, load=0.02 * h.size, periodic=True)
    assert 0 < res.contact_fraction < 0.5
    assert_sound(res, 0.02 * h.size)


def test_spiky_topography():
    """Twenty isolated one-pixel spikes on a flat plane: spikes of different heights, each a
    point load; at this load they are flattened and the plane between them touches too."""
    n = 64
    rng = np.random.default_rng(5)
    h = np.zeros((n, n))
    h.flat[rng.choice(h.size, 20, replace=False)] = rng.uniform(0.5, 1.0, 20)
    for load in (1e-3 * h.size, 0.05 * h.size):
        res = solve(h, 1.0, 1.0, load=load, periodic=True)
        assert_sound(res, load)
    assert res.contact_fraction > 0.5


def test_flat_indenter_periodic_gives_the_uniform_pressure():
    """Constant heights: full contact at exactly the mean pressure W/A (h_rms = 0, so the
    residual's length scale falls back to the spacing)."""
    h = np.full((32, 48), 3e-9)
    load = 1e-3
    res = solve(h, DX, E_STAR, load=load, periodic=True)
    np.testing.assert_allclose(res.pressure, load / (h.size * DX**2), rtol=1e-12)
    assert_sound(res, load)


# --- plasticity at its limits ---------------------------------------------------------------


def test_tiny_hardness_everything_plastic():
    """p_Y = 1e-6 E*: every contact pixel but at most one (the one being filled) sits at p_Y,
    to 1e-6 (a few pixels sit 1e-12..1e-9 below it: the bounded CG places them to its tol).
    Extends test_plasticity's tiny-hardness case with the common invariants."""
    h = rough_sphere()
    p_y = 1e-6 * E_STAR
    load = 100 * p_y * DX**2
    res = solve(h, DX, E_STAR, load=load, plasticity=PenetrationHardness(p_y))
    below = res.contact & (res.pressure < p_y * (1 - 1e-6))
    assert below.sum() <= 1
    assert_sound(res, load, p_y=p_y)


def test_huge_hardness_is_elastic():
    """p_Y = 1e3 E* is never reached (elastic peak ~0.05 E*): same field as the elastic
    solve to 1e-6 of its peak (both at tol 1e-8), no plastic displacement at all."""
    h = rough_sphere()
    load = 1e-4
    elastic = solve(h, DX, E_STAR, load=load)
    res = solve(h, DX, E_STAR, load=load, plasticity=PenetrationHardness(1e3 * E_STAR))
    assert not res.plastic_displacement.any()
    np.testing.assert_allclose(
        res.pressure, elastic.pressure, rtol=0, atol=1e-6 * elastic.pressure.max()
    )
    assert_sound(res, load, p_y=1e3 * E_STAR)


@pytest.mark.parametrize(
    ("k_mpa_per_nm", "load"), [(1e-3, 1e-9), (1e4, 1e-4)], ids=["k=1e-3", "k=1e4"]
)
def test_hardening_coefficient_extremes(k_mpa_per_nm, load):
    """k = 1e-3 and 1e4 MPa/nm (PMMA: 7): the Winkler layer dominates the half-space or
    vanishes beside it. Every contact pixel sits on its yield surface p = k|h_pl|
    (monotonic loading from a virgin surface; 1e-9 relative: the Winkler solve is a linear
    solve to tol). The softer law spreads the contact, so its load is smaller."""
    k = k_mpa_per_nm * MPA_PER_NM
    res = solve(rough_sphere(), DX, E_STAR, load=load, plasticity=ContactHardening(k))
    c = res.contact
    yield_p = k * np.abs(res.plastic_displacement)
    np.testing.assert_allclose(res.pressure[c], yield_p[c], rtol=1e-6)
    assert_sound(res, load, p_y=np.maximum(yield_p, 0) * (1 + 1e-6))


# --- load range and input forms -------------------------------------------------------------


def test_loads_spanning_six_decades_on_one_surface():
    """A load series over 1e-6 ... 1 of E*·A·h'_rms on one periodic surface: every step
    sound, the area grows with the load, the smallest step is one or two asperities and the
    largest nearly full contact."""
    h = rough_plane()
    loads = 0.1 * h.size * np.logspace(-6, 0, 7)
    series = solve_load_series(h, 1.0, 1.0, loads, periodic=True)
    for res, load in zip(series, loads, strict=True):
        assert_sound(res, load)
    areas = [r.contact.sum() for r in series]
    assert areas == sorted(areas)
    assert areas[0] <= 3 and series[-1].contact_fraction > 0.9


def test_float32_heights_give_the_float64_solution():
    """Heights are promoted to float64 on entry: the solution of a float32 map is that of
    the same values in float64, bit for bit."""
    h32 = rough_sphere().astype(np.float32)
    a = solve(h32, DX, E_STAR, load=1e-4)
    b = solve(h32.astype(np.float64), DX, E_STAR, load=1e-4)
    assert a.pressure.dtype == np.float64
    assert np.array_equal(a.pressure, b.pressure)
    assert_sound(a, 1e-4)


@pytest.mark.parametrize("shape", [(48, 80), (63, 65), (33, 17)], ids=str)
def test_non_square_and_odd_grids(shape):
    """Non-square and odd-sized grids, free (rough sphere) and periodic (rough plane). The
    sphere's load scales as the cube of the shorter side (Hertz: a ∝ W^(1/3)) so its contact
    stays inside the window."""
    load = 3e-5 * (min(shape) / 64) ** 3
    res = solve(rough_sphere(shape), DX, E_STAR, load=load)
    assert_sound(res, load)
    h = rough_plane(shape)
    res = solve(h, 1.0, 1.0, load=0.005 * h.size, periodic=True)
    assert_sound(res, 0.005 * h.size)


# --- refused input --------------------------------------------------------------------------


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_pixel_is_refused_by_the_load_series(bad):
    """One non-finite pixel: refused before any solve, naming the pixel (test_errors.py
    covers solve; this covers solve_load_series and inf)."""
    h = rough_plane()
    h[10, 20] = bad
    with pytest.raises(ContactInputError, match=r"non-finite.*\(10, 20\)"):
        solve_load_series(h, 1.0, 1.0, [1.0, 2.0], periodic=True)


@pytest.mark.parametrize("bad", [0.0, -1.0, np.nan, np.inf])
def test_zero_negative_and_non_finite_loads_in_a_series_are_refused(bad):
    """Every load of a series is checked up front, naming the list (test_errors.py covers
    the single solve)."""
    with pytest.raises(ContactInputError, match="finite and positive"):
        solve_load_series(rough_plane(), 1.0, 1.0, [1.0, bad, 3.0], periodic=True)


@pytest.mark.parametrize("loads", [[2.0, 1.0], [1.0, 1.0, 2.0]], ids=["decreasing", "repeated"])
def test_load_series_that_is_not_increasing_is_refused(loads):
    """A series is a loading history warm-started step by step; a decrease or a repeat is
    refused (ContactInputError naming the loads) rather than sorted: with plasticity the
    order is physics. Unload with solve(..., plastic_displacement=...) instead (next test)."""
    with pytest.raises(ContactInputError, match="strictly increasing"):
        solve_load_series(rough_plane(), 1.0, 1.0, loads, periodic=True)


def test_contact_reaching_the_window_edge_in_a_series_names_the_step():
    """A series whose last load outgrows the window raises FreeBoundaryError, and the error
    says which step (test_errors.py covers the single solve)."""
    loads = [1e-5, 1e-4, 3e-3]
    with pytest.raises(FreeBoundaryError, match="edge pixel") as info:
        solve_load_series(rough_sphere(), DX, E_STAR, loads)
    assert "load step 3 of 3" in "".join(getattr(info.value, "__notes__", []))


# --- history and starting points -----------------------------------------------------------


def test_unloading_a_hardening_surface_keeps_its_history():
    """Load to 1e-4 N with contact hardening, then unload to 3e-5 N from that plastic
    state: no point flows further (the plastic displacement is unchanged, exactly, since
    unloading is elastic), the contact shrinks, and every pressure stays below the yield
    pressure k|h_pl| reached on loading."""
    h = rough_sphere()
    law = ContactHardening(7 * MPA_PER_NM)
    loaded = solve(h, DX, E_STAR, load=1e-4, plasticity=law)
    unloaded = solve(
        h,
        DX,
        E_STAR,
        load=3e-5,
        plasticity=law,
        plastic_displacement=loaded.plastic_displacement,
    )
    assert np.array_equal(unloaded.plastic_displacement, loaded.plastic_displacement)
    assert unloaded.contact.sum() < loaded.contact.sum()
    p_y = law.k * np.abs(loaded.plastic_displacement)
    assert_sound(unloaded, 3e-5, p_y=p_y)


@pytest.mark.parametrize("start", ["random", "one-pixel"])
def test_warm_start_from_a_wildly_wrong_pressure(start):
    """A warm start that is wrong in shape and 1e6x wrong in total converges to the cold
    solution (1e-6 of its peak; both at tol 1e-8). The one-pixel start is the regression
    case of a bug: a one-pixel free set has no gap (d is its own gap), and the solver took
    that for the exact solution, returning all the load on one pixel with the rest of the
    surface penetrating 27 h_rms."""
    h = rough_plane(seed=11)
    load = 0.005 * h.size
    cold = solve(h, 1.0, 1.0, load=load, periodic=True)
    if start == "random":
        warm = np.random.default_rng(0).uniform(0, 1e6 * load / h.size, h.shape)
    else:
        warm = np.zeros_like(h)
        warm[3, 3] = 1e6
    res = solve(h, 1.0, 1.0, load=load, periodic=True, warm_start=warm)
    np.testing.assert_allclose(res.pressure, cold.pressure, rtol=0, atol=1e-6 * cold.pressure.max())
    assert_sound(res, load)
