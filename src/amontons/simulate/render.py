"""A simulated contact seen like the microscope sees it (docs/simulate.md, "Render").

``emission`` (the default): the probe layer emits with the law the measurement assumes,
√max(p, p_c) in contact and nothing outside (docs/models.md §1.2); the emission is averaged
over each fluorescence pixel (a patch's edge counts by the fraction of the pixel it covers),
blurred with the Gaussian PSF measured from that sphere's bead image, and thresholded by the
same Otsu code as the measured images (:func:`amontons.measure.area.otsu_contact_area`).

``binary``: the appendix's rendering, a binary contact map blurred with the PSF. Under the
√p law it overstates the Otsu area of the measured image (docs/simulate.md states by how much).

The rendered image is noiseless and in arbitrary units: Otsu's threshold does not depend on
the scale, and the measured image's noise is not the simulation's to add.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import gaussian_filter

from amontons.measure.area import ContactArea, OtsuSettings, otsu_contact_area
from amontons.physics.emission import confined_emission
from amontons.physics.gaussian import FWHM_PER_SIGMA
from amontons.simulate.grid import PixelAverager

RENDERINGS = ("emission", "binary")


@dataclass(frozen=True)
class Rendered:
    """One load rendered: the image (arbitrary units) on the fluorescence pixel (m) and its
    Otsu contact."""

    image: np.ndarray
    pixel_m: float
    otsu: ContactArea


def image_side_px(window_m: float, pixel_m: float) -> int:
    """Side (px) of the rendered image: the whole pixels of ``pixel_m`` the window holds."""
    return int(np.floor(window_m / pixel_m + 1e-9))


def render_contact(
    pressure_pa: np.ndarray,
    contact: np.ndarray,
    spacing_m: float,
    *,
    pixel_m: float,
    psf_fwhm_m: float,
    rendering: str = "emission",
    confinement_floor_pa: float = 0.0,
    averager: PixelAverager | None = None,
) -> np.ndarray:
    """The noiseless microscope image (arbitrary units, fluorescence pixels of ``pixel_m``)
    of a contact on the solver grid of ``spacing_m`` (both centred on the window centre)."""
    if rendering not in RENDERINGS:
        raise ValueError(f"rendering = {rendering!r}; expected one of {RENDERINGS}")
    if rendering == "emission":
        signal = confined_emission(pressure_pa, contact, confinement_floor_pa)
    else:
        signal = contact.astype(float)
    if averager is None:
        side = image_side_px(contact.shape[0] * spacing_m, pixel_m)
        averager = PixelAverager(contact.shape, spacing_m, (side, side), pixel_m)
    sigma_px = psf_fwhm_m / FWHM_PER_SIGMA / pixel_m
    return gaussian_filter(averager(signal), sigma_px, mode="constant")


def render_load_series(
    fields: list[dict],
    spacing_m: float,
    *,
    pixel_m: float,
    psf_fwhm_m: float,
    rendering: str,
    confinement_floor_pa: float,
    otsu: OtsuSettings,
    window_m: float | None = None,
) -> list[Rendered]:
    """Every load of a scene rendered and thresholded (one pixel averager for all loads), on
    an image over ``window_m`` (m, centred; None: the whole solver window)."""
    shape = fields[0]["contact"].shape
    side = image_side_px(shape[0] * spacing_m if window_m is None else window_m, pixel_m)
    averager = PixelAverager(shape, spacing_m, (side, side), pixel_m)
    out = []
    for field in fields:
        image = render_contact(
            field["pressure"],
            field["contact"],
            spacing_m,
            pixel_m=pixel_m,
            psf_fwhm_m=psf_fwhm_m,
            rendering=rendering,
            confinement_floor_pa=confinement_floor_pa,
            averager=averager,
        )
        out.append(Rendered(image, pixel_m, otsu_contact_area(image, pixel_m, otsu)))
    return out


def area_fraction_map(
    r_um: np.ndarray, area_fraction: np.ndarray, shape, centre_px, pixel_m: float
) -> np.ndarray:
    """A mean-field model's real-area fraction φ(r) (radii in µm, e.g. Greenwood–Tripp's
    annulus mid-radii) on an image grid of ``shape`` about ``centre_px`` (row, col): the map a
    model without asperity geometry gives. Zero beyond its last radius."""
    rows, cols = np.indices(shape, dtype=float)
    radius_um = np.hypot(rows - centre_px[0], cols - centre_px[1]) * pixel_m * 1e6
    return np.interp(radius_um, r_um, area_fraction, right=0.0)
