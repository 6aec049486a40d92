"""Mean contact intensity versus mean contact pressure (appendix Fig. B.4).

Per load: the mean contact pressure is F/A with A the area of the contact mask (Otsu), and
the mean contact intensity is, as the appendix defines it (Fig. B.4), the total
background-subtracted intensity divided by the same area. "Total" is summed over the mask
dilated by ``margin_px``: the PSF spreads a patchy contact's light beyond its Otsu mask (a
share that shrinks as the contact grows, which biased a mask-only mean by +0.1 in the
exponent on the rough virtual spheres), while the pixels beyond the margin are background.
The appendix finds intensity ∝ √pressure; the exponent comes from a log–log OLS fit
(amontons.powerlaw.fit_power_law).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.ndimage import binary_dilation

from amontons.powerlaw import PowerLawFit, fit_power_law


@dataclass(frozen=True)
class IntensityPressure:
    """Per-load table (units in column names) and the power-law fit intensity ∝ pressure^α."""

    table: pd.DataFrame
    fit: PowerLawFit


def mean_contact_intensity(
    image: np.ndarray, mask: np.ndarray, background: float, margin_px: int
) -> float:
    """Background-subtracted counts summed over the mask dilated by ``margin_px``, per mask
    pixel (counts)."""
    region = binary_dilation(mask, iterations=margin_px) if margin_px > 0 else mask
    return float((np.asarray(image, dtype=float)[region] - background).sum() / mask.sum())


def intensity_pressure(
    images: Sequence[np.ndarray],
    masks: Sequence[np.ndarray],
    loads_n: Sequence[float],
    background: float | Sequence[float],
    *,
    pixel_m: float,
    margin_px: int = 5,
    pressure_ref_pa: float = 1e8,
    confidence: float = 0.95,
) -> IntensityPressure:
    """Mean contact intensity (counts) vs mean contact pressure (Pa) and its exponent.

    ``background`` is one value in counts for all images, or one per image. Raises ValueError
    for mismatched lengths or shapes, an empty mask, or a mean contact intensity that is not
    above the background (named by its load).
    """
    n = len(images)
    backgrounds = np.broadcast_to(np.asarray(background, dtype=float), (n,))
    if not (len(masks) == len(loads_n) == n):
        raise ValueError(
            f"{n} images, {len(masks)} masks and {len(loads_n)} loads; expected one of each "
            "per load"
        )
    rows = []
    for image, mask, load, level in zip(images, masks, loads_n, backgrounds, strict=True):
        mask = np.asarray(mask, dtype=bool)
        if mask.shape != np.shape(image):
            raise ValueError(f"load {load:g} N: mask {mask.shape} ≠ image {np.shape(image)}")
        n_pixels = int(mask.sum())
        if n_pixels == 0:
            raise ValueError(f"load {load:g} N: the contact mask is empty; expected a contact")
        intensity = mean_contact_intensity(image, mask, level, margin_px)
        if not intensity > 0:
            raise ValueError(
                f"load {load:g} N: mean contact intensity {intensity:.3g} counts is not above "
                f"the background {level:g} counts"
            )
        area = n_pixels * pixel_m**2
        rows.append(
            {
                "load_N": float(load),
                "area_m2": area,
                "mean_pressure_Pa": float(load) / area,
                "mean_intensity_counts": intensity,
            }
        )
    table = pd.DataFrame(rows)
    fit = fit_power_law(
        table["mean_pressure_Pa"].to_numpy(),
        table["mean_intensity_counts"].to_numpy(),
        x_ref=pressure_ref_pa,
        confidence=confidence,
    )
    return IntensityPressure(table=table, fit=fit)
