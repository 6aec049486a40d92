"""Hertz contact of a smooth elastic sphere on a rigid flat (Johnson 1985, §4.2).

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
