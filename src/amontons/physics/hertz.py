"""Hertz contact of a smooth elastic sphere on a rigid flat (Johnson 1985, §4.2; docs/models.md
§2.7), and the gap outside it that the Newton rings see (docs/models.md §1.5).

SI units: radius R (m), load F (N), contact modulus E* (Pa).
"""

from __future__ import annotations

import numpy as np


def contact_radius(load_n: float, radius_m: float, e_star_pa: float) -> float:
    """Hertz contact radius a = (3FR / 4E*)^(1/3), m."""
    return float((3 * load_n * radius_m / (4 * e_star_pa)) ** (1 / 3))


def approach(load_n: float, radius_m: float, e_star_pa: float) -> float:
    """Rigid-body approach d = a²/R, m."""
    return contact_radius(load_n, radius_m, e_star_pa) ** 2 / radius_m


def peak_pressure(load_n: float, radius_m: float, e_star_pa: float) -> float:
    """Peak pressure p0 = 3F / (2πa²), Pa."""
    return 3 * load_n / (2 * np.pi * contact_radius(load_n, radius_m, e_star_pa) ** 2)


def pressure_profile(r_m: np.ndarray, load_n: float, radius_m: float, e_star_pa: float):
    """Pressure p0·√(1 − r²/a²) inside the contact, 0 outside, Pa."""
    a = contact_radius(load_n, radius_m, e_star_pa)
    p0 = peak_pressure(load_n, radius_m, e_star_pa)
    inside = np.clip(1 - (np.asarray(r_m) / a) ** 2, 0, None)
    return p0 * np.sqrt(inside)


def exterior_shape(r_m, edge_radius_m: float):
    """S(r) = [a·√(r² − a²) − (2a² − r²)·acos(a/r)]/π, m²: the Hertz gap times R outside the
    contact radius a = ``edge_radius_m``, 0 inside.

    The surface displacement outside a Hertz pressure distribution (Johnson 1985 §3.9) with
    d = a²/R and p0 = 2aE*/πR (§4.2) gives g(r) = r²/2R − d + u(r),
    u(r) = [(2a² − r²)·asin(a/r) + a·√(r² − a²)]/πR; with asin = π/2 − acos this is S(r)/R,
    which is 0 at r = a, rises as (r − a)^{3/2} next to the edge and tends to r²/2R − d far
    away (u → 4a³/3πRr).
    """
    a = edge_radius_m
    r = np.maximum(np.asarray(r_m, dtype=float), a)
    return (a * np.sqrt(r**2 - a**2) - (2 * a**2 - r**2) * np.arccos(a / r)) / np.pi


def exterior_gap(r_m, load_n: float, radius_m: float, e_star_pa: float):
    """Gap (m) between a Hertz sphere and the flat at distance ``r_m`` from the centre: 0 in
    the contact, :func:`exterior_shape` / R outside it."""
    return exterior_shape(r_m, contact_radius(load_n, radius_m, e_star_pa)) / radius_m
