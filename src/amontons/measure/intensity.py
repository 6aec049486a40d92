"""Mean contact intensity versus mean contact pressure (appendix Fig. B.4).

Per load: the mean contact pressure is F/A with A the area of the contact mask (Otsu), and
the mean contact intensity is, as the appendix defines it (Fig. B.4), the total
background-subtracted intensity divided by the same area. "Total" is summed over the mask
dilated by ``margin_px``: the PSF spreads a patchy contact's light beyond its Otsu mask (a
share that shrinks as the contact grows, which biased a mask-only mean by +0.1 in the
exponent on the rough virtual spheres), while the pixels beyond the margin are background.
The appendix finds intensity ∝ √pressure; the exponent comes from a log–log OLS fit
(amontons.power_law.fit_power_law).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.ndimage import binary_dilation

from amontons.io.confocal import NO_CHOICE, ImageChoice
from amontons.io.layout import RawDataError
from amontons.io.rawdata import read_fluorescence_series
from amontons.io.tiff import saturated_pixels
from amontons.measure.area import OtsuSettings, separated_contact
from amontons.measure.errors import NoContact
from amontons.power_law import PowerLawFit, fit_power_law


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
                "load_n": float(load),
                "area_m2": area,
                "mean_pressure_pa": float(load) / area,
                "mean_intensity_counts": intensity,
            }
        )
    table = pd.DataFrame(rows)
    fit = fit_power_law(
        table["mean_pressure_pa"].to_numpy(),
        table["mean_intensity_counts"].to_numpy(),
        x_ref=pressure_ref_pa,
        confidence=confidence,
    )
    return IntensityPressure(table=table, fit=fit)


def background_level(image: np.ndarray, mask: np.ndarray, margin_px: int) -> float:
    """Median counts of the pixels more than ``margin_px`` from the contact mask.

    The margin keeps the PSF's tail around the contact out of the background estimate.
    """
    far = ~binary_dilation(mask, iterations=margin_px) if margin_px > 0 else ~mask
    if far.sum() < 10:
        raise ValueError(
            f"only {int(far.sum())} pixels lie more than {margin_px} px from the contact; "
            "expected a background region around it"
        )
    return float(np.median(np.asarray(image, dtype=float)[far]))


def measure_intensity_pressure(
    image_paths: Sequence[str | Path],
    loads_mn: Sequence[float],
    fallback_pixel_m: float | None,
    *,
    otsu: OtsuSettings,
    background_margin_px: int,
    pressure_ref_pa: float,
    confidence: float = 0.95,
    choice: ImageChoice | Sequence[ImageChoice] = NO_CHOICE,
) -> tuple[IntensityPressure, list[float], dict[float, str]]:
    """Mean contact intensity versus mean contact pressure F/A (appendix Fig. B.4), from
    the fluorescence images ``image_paths`` (one per load of ``loads_mn``; ``choice``: the plane
    of a confocal file, amontons.io.confocal, or each load's own, as a file holding the whole
    load series needs: amontons.io.rawdata.fluorescence_planes).

    Returns the fit, each fitted image's background (counts, from the pixels far from the
    mask) and the loads left out (mN → why): an image in which no contact stands out
    (:func:`separated_contact`) has no contact intensity, as in the load–area fit.
    Raises RawDataError if fewer than three loads are left.
    """
    images, masks, backgrounds, kept_loads, excluded = [], [], [], [], {}
    series = read_fluorescence_series(image_paths, fallback_pixel_m, choice)
    for load, image in zip(loads_mn, series, strict=True):
        path = image.path
        saturated = saturated_pixels(image.data)
        if saturated:
            raise RawDataError(
                f"{path}: {saturated} saturated pixels (the {image.data.dtype} maximum); the "
                "mean contact intensity of a clipped image is too low - expected none (lower "
                "the laser power or the detector gain)"
            )
        try:
            mask = separated_contact(image, otsu).mask
        except NoContact as error:
            excluded[load] = str(error)
            continue
        images.append(image.data)
        masks.append(mask)
        kept_loads.append(load)
        try:
            backgrounds.append(background_level(image.data, mask, background_margin_px))
        except ValueError as error:
            raise RawDataError(f"{path}: {error}") from error
    if len(kept_loads) < 3:
        raise RawDataError(
            f"{Path(image_paths[0]).parent}: {len(kept_loads)} of {len(loads_mn)} images show a "
            f"contact (left out: {sorted(excluded)} mN); the intensity-pressure fit needs 3 or more"
        )
    loads_n = [load * 1e-3 for load in kept_loads]
    try:
        result = intensity_pressure(
            images,
            masks,
            loads_n,
            backgrounds,
            pixel_m=series[0].pixel_m,
            margin_px=background_margin_px,
            pressure_ref_pa=pressure_ref_pa,
            confidence=confidence,
        )
    except ValueError as error:
        raise RawDataError(f"{Path(image_paths[0]).parent}: {error}") from error
    return result, backgrounds, excluded


def intensity_pressure_table(result: IntensityPressure, backgrounds: Sequence[float]):
    """Per-load table of the fitted loads, units in the column names."""
    table = result.table
    return table.assign(
        load_mn=table["load_n"] * 1e3,
        area_um2=table["area_m2"] * 1e12,
        mean_pressure_mpa=table["mean_pressure_pa"] * 1e-6,
        background_counts=list(backgrounds),
    )[["load_mn", "area_um2", "mean_pressure_mpa", "mean_intensity_counts", "background_counts"]]


def intensity_pressure_record(result: IntensityPressure, excluded: dict[float, str]) -> dict:
    """JSON-ready record of the intensity–pressure fit, with the loads left out and why."""
    return {
        "quantity": "background-subtracted mean contact intensity versus mean contact pressure "
        "F/A, I = I_ref (p / p_ref)^exponent (appendix Fig. B.4: exponent 1/2)",
        "units": {"prefactor": "counts (intensity at p_ref)", "x_ref": "Pa"},
        **result.fit.to_record(),
        # images in which no contact stands out have no contact intensity: left out, with why
        "excluded_loads_mn": list(excluded),
        "exclusion_flags": list(excluded.values()),
    }
