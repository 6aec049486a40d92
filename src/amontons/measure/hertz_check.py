"""Measured contact radius against Hertz (appendix B.1.2: smooth spheres agree with Hertz).

The measured radius is that of the circle with the measured area, √(A/π); the Hertz radius
is (3FR/4E*)^{1/3} (amontons.physics.hertz). A ratio near 1 says the contact is Hertzian; a rough
sphere at low load has a smaller, patchy area and a ratio below 1.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from amontons.physics import hertz


def hertz_check(
    loads_n: np.ndarray, areas_m2: np.ndarray, radius_m: float, e_star_pa: float
) -> pd.DataFrame:
    """Table of load_n, area_m2, measured_radius_m, hertz_radius_m and radius_ratio.

    Raises ValueError for mismatched lengths or non-positive loads, areas, radius or E*.
    """
    loads = np.asarray(loads_n, dtype=float)
    areas = np.asarray(areas_m2, dtype=float)
    if loads.shape != areas.shape or loads.ndim != 1:
        raise ValueError(f"loads {loads.shape} and areas {areas.shape} must be 1-D, equal length")
    for name, values in (("loads (N)", loads), ("areas (m²)", areas)):
        if not np.all(np.isfinite(values)) or np.any(values <= 0):
            raise ValueError(f"{name} {values} must be finite and > 0")
    if not (radius_m > 0 and e_star_pa > 0):
        raise ValueError(f"sphere radius {radius_m} m and E* {e_star_pa} Pa must be > 0")
    measured = np.sqrt(areas / np.pi)
    predicted = np.array([hertz.contact_radius(f, radius_m, e_star_pa) for f in loads])
    return pd.DataFrame(
        {
            "load_n": loads,
            "area_m2": areas,
            "measured_radius_m": measured,
            "hertz_radius_m": predicted,
            "radius_ratio": measured / predicted,
        }
    )


def hertz_check_table(area_table: pd.DataFrame, radius_m: float, e_star_pa: float) -> pd.DataFrame:
    """Measured (Otsu) contact radius against Hertz per load, units in the column names.

    Loads where no contact was found are kept but flagged (column contact_found).
    """
    table = hertz_check(
        area_table["load_mn"].to_numpy() * 1e-3,
        area_table["area_um2"].to_numpy() * 1e-12,
        radius_m,
        e_star_pa,
    )
    return pd.DataFrame(
        {
            "load_mn": table["load_n"] * 1e3,
            "area_um2": table["area_m2"] * 1e12,
            "measured_radius_um": table["measured_radius_m"] * 1e6,
            "hertz_radius_um": table["hertz_radius_m"] * 1e6,
            "radius_ratio": table["radius_ratio"],
            "contact_found": area_table["contact_found"].to_numpy(),
        }
    )
