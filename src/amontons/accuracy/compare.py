"""What each setting's solution is compared on (docs/accuracy.md, "Errors").

The pressure fields of all settings are brought to one common grid: the coarsest setting's
pixel over the narrowest window, centred on the apex (every window is centred there, and the
periodic surfaces share their origin). Each common pixel holds the mean pressure over its
area, so the total force on it is kept. The rendered Otsu area is taken on one common image
too (the fluorescence pixel over the narrowest window), so that a wider solver window does
not change the image's field of view.
"""

from __future__ import annotations

import numpy as np

from amontons.measure.area import OtsuSettings
from amontons.simulate.render import render_load_series
from amontons.simulate.surface import area_average


def common_side_px(window_m: float, pixel_m: float) -> int:
    """Whole common pixels (even) inside a window of ``window_m``, one spare pixel per side
    for the solver window's rounding to whole pixels."""
    n = int(np.floor(window_m / pixel_m + 1e-9)) - 2
    return n - n % 2


def on_common_grid(field: np.ndarray, spacing_m: float, side_px: int, pixel_m: float):
    """``field`` (on a centred grid of ``spacing_m``) area-averaged onto the centred common
    grid of ``side_px`` pixels of ``pixel_m``."""
    extent = field.shape[0] * spacing_m
    origin = (extent - side_px * pixel_m) / 2
    return area_average(field, spacing_m, (origin, origin), side_px, pixel_m)


def relative_l2(field: np.ndarray, reference: np.ndarray) -> float:
    """‖field − reference‖₂ / ‖reference‖₂."""
    return float(np.linalg.norm(field - reference) / np.linalg.norm(reference))


def rendered_areas_um2(
    results, spacing_m: float, window_m: float, *, pixel_m: float, psf_fwhm_m: float, otsu
) -> list[float]:
    """Otsu area (µm²) of each load rendered like the microscope sees it (the scenes'
    rendering, :func:`amontons.simulate.render.render_load_series`: emission law, bare √p)
    on the common image of the fluorescence pixel ``pixel_m`` over ``window_m``."""
    rendered = render_load_series(
        [{"pressure": r.pressure, "contact": r.contact} for r in results],
        spacing_m,
        pixel_m=pixel_m,
        psf_fwhm_m=psf_fwhm_m,
        rendering="emission",
        confinement_floor_pa=0.0,
        otsu=OtsuSettings.from_config(otsu),
        window_m=window_m,
    )
    return [r.otsu.area_m2 * 1e12 for r in rendered]
