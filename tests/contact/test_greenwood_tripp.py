"""Greenwood–Tripp rough-sphere model: exact pieces against closed forms, and the smooth limit
against Hertz."""

import numpy as np
import pytest
from scipy import integrate
from scipy.special import ndtr

from amontons.contact import ContactError, ContactInputError
from amontons.contact.greenwood_tripp import (
    AsperityModel,
    GreenwoodTrippError,
    annulus_influence,
    bearing_area_map,
    greenwood_tripp,
    gw_integral,
)

R, E_STAR, LOAD = 2e-3, 3.5e9, 0.1  # a 4 mm PMMA sphere at 100 mN


def hertz_radius(load_n, radius_m, e_star_pa):
    """Hertz contact radius a = (3FR/4E*)^(1/3), m."""
    return (3 * load_n * radius_m / (4 * e_star_pa)) ** (1 / 3)


def hertz_approach(load_n, radius_m, e_star_pa):
    """Hertz approach d = a²/R, m."""
    return hertz_radius(load_n, radius_m, e_star_pa) ** 2 / radius_m


def hertz_pressure(r_m, load_n, radius_m, e_star_pa):
    """Hertz pressure p0·√(1 − r²/a²) inside the contact, 0 outside, Pa (p0 = 3F/2πa²)."""
    a = hertz_radius(load_n, radius_m, e_star_pa)
    p0 = 3 * load_n / (2 * np.pi * a**2)
    return p0 * np.sqrt(np.clip(1 - (np.asarray(r_m) / a) ** 2, 0, None))


def test_gw_integrals_match_closed_forms():
    h = np.linspace(-15, 6, 400)
    phi = np.exp(-0.5 * h**2) / np.sqrt(2 * np.pi)
    # F_0 = 1 − Φ(h), F_1 = φ(h) − h(1 − Φ(h)). Spline and asymptotic series are good to ~1e-6
    # relative; 1e-5 (plus a tiny absolute floor in the far tail) is the stated accuracy.
    np.testing.assert_allclose(gw_integral(0.0, h), ndtr(-h), rtol=1e-5, atol=1e-12)
    np.testing.assert_allclose(gw_integral(1.0, h), phi - h * ndtr(-h), rtol=1e-5, atol=1e-12)


def test_three_halves_integral_against_quadrature():
    for h in (-14.0, -3.0, 0.0, 2.5):
        exact, _ = integrate.quad(
            lambda s, h=h: (s - h) ** 1.5 * np.exp(-0.5 * s * s) / np.sqrt(2 * np.pi), h, np.inf
        )
        assert gw_integral(1.5, np.array([h]))[0] == pytest.approx(exact, rel=1e-5)


def test_annulus_influence_reproduces_the_hertz_displacement():
    a = hertz_radius(LOAD, R, E_STAR)
    d = hertz_approach(LOAD, R, E_STAR)
    edges = np.linspace(0, 2 * a, 801)
    r = 0.5 * (edges[1:] + edges[:-1])
    w = annulus_influence(edges, E_STAR) @ hertz_pressure(r, LOAD, R, E_STAR)
    inside = r < 0.9 * a
    # Hertz: w = d − r²/2R inside the contact. Piecewise-constant pressure on 400 annuli per
    # contact radius is accurate to ~(Δr/a)^1.5 ≈ 1e-4 of d; measured 2e-5.
    np.testing.assert_allclose(w[inside], d - r[inside] ** 2 / (2 * R), atol=1e-4 * d)


def _model(sigma):
    return AsperityModel(sigma_m=sigma, beta_m=1e-6, eta_per_m2=0.05 / (sigma * 1e-6))


def test_smooth_limit_is_hertz():
    a = hertz_radius(LOAD, R, E_STAR)
    d = hertz_approach(LOAD, R, E_STAR)
    # σ = 1e-10 m is 1.6e-4 of the Hertz approach: the roughness is negligible.
    gt = greenwood_tripp(R, E_STAR, _model(1e-10), LOAD, n_radial=300)
    radius = gt.r_m[gt.pressure > 0.01 * gt.pressure.max()].max()
    # Contact radius: where p falls below 1 % of the peak (Hertz: 0.99995 a). The grid step is
    # 1 % of a, so 2 % (two grid steps) is the resolvable tolerance.
    assert radius == pytest.approx(a, rel=0.02)
    assert gt.approach_m == pytest.approx(d, rel=0.01)
    assert gt.load_n == pytest.approx(LOAD, rel=1e-10)


def test_roughness_spreads_the_contact_and_lowers_the_peak():
    smooth = greenwood_tripp(R, E_STAR, _model(1e-9), LOAD, n_radial=200)
    rough = greenwood_tripp(R, E_STAR, _model(1e-7), LOAD, n_radial=200)
    assert rough.pressure.max() < 0.9 * smooth.pressure.max()
    assert rough.pressure[rough.r_m > 1.2 * hertz_radius(LOAD, R, E_STAR)].max() > 0


def test_too_small_domain_is_an_error():
    with pytest.raises(GreenwoodTrippError, match="increase r_max_m"):
        greenwood_tripp(R, E_STAR, _model(1e-7), LOAD, r_max_m=1e-5, n_radial=100)


def test_greenwood_tripp_error_is_a_contact_error():
    """GreenwoodTrippError joins the solver's error tree and stays a RuntimeError."""
    assert issubclass(GreenwoodTrippError, ContactError)
    assert issubclass(GreenwoodTrippError, RuntimeError)
    with pytest.raises(ContactError, match="increase r_max_m"):
        greenwood_tripp(R, E_STAR, _model(1e-7), LOAD, r_max_m=1e-5, n_radial=100)


def test_non_positive_load_is_an_input_error():
    with pytest.raises(ContactInputError, match="positive load"):
        greenwood_tripp(R, E_STAR, _model(1e-7), -1.0)


def test_bearing_area_map_marks_peaks_above_the_separation():
    gt = greenwood_tripp(R, E_STAR, _model(1e-8), LOAD, n_radial=200)
    roughness = np.zeros((65, 65))
    roughness[32, 32] = 1e-6  # a tall spike in the centre
    roughness[0, 0] = 1e-6  # and one far outside the contact
    contact = bearing_area_map(roughness, 2e-6, gt)
    assert contact[32, 32] and not contact[0, 0]
