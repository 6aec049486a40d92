"""Real contact area from a fluorescence image by Otsu thresholding (appendix B.1.1).

Area = number of pixels above Otsu's threshold × pixel area. Otsu's threshold always splits
an image in two, so whether the upper class is a contact is decided separately, by three
tests, each of which catches an image that another lets through:

- the Otsu effectiveness η = σ²_between / σ²_total (Otsu 1979): → 1 for two narrow, distinct
  populations, 2/π ≈ 0.64 when the image is one Gaussian population (noise, no contact),
  0.75 for a smooth illumination gradient - but also only ~0.7 for a lone diffraction-limited
  contact on a noisy background, so η reports how well the threshold is determined rather
  than deciding alone;
- the contrast: the gap between the class means in units of the background class's noise
  (its standard deviation, and for integer photon counts at least the shot noise
  √(mean + 1)). Noise split at its mean gives 2√(2/π)/√(1 − 2/π) ≈ 2.6 (less with the shot
  noise floor); a photon-counting dark frame (mostly 0 and 1 counts, η ≈ 0.95) ≈ 1;
- the largest connected (8-neighbour) patch of the upper class, in pixels: isolated hot
  pixels on a background have η ≈ 0.9 and a huge contrast, but no patch as large as the
  image of a point source (~4 px for a 450 nm PSF on 200 nm pixels).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import ndimage
from skimage.filters import threshold_otsu

from amontons.io.tiff import Image, saturated_pixels
from amontons.measure.errors import NoContact


@dataclass(frozen=True)
class OtsuSettings:
    """Otsu histogram bins and the three tests that a contact must pass (module docstring)."""

    bins: int = 256
    min_separation: float = 0.5
    min_contrast: float = 5.0
    min_patch_px: int = 4

    @classmethod
    def from_config(cls, optics: Mapping) -> OtsuSettings:
        """From the ``optics`` config slice (keys otsu_bins, min_separation, min_contrast,
        min_patch_px)."""
        return cls(
            bins=optics["otsu_bins"],
            min_separation=optics["min_separation"],
            min_contrast=optics["min_contrast"],
            min_patch_px=optics["min_patch_px"],
        )


@dataclass(frozen=True)
class ContactArea:
    """Otsu contact area of one image; ``flag`` says why no contact was found (else None)."""

    area_m2: float
    n_contact_pixels: int
    threshold: float
    separation: float
    contrast: float
    largest_patch_px: int
    flag: str | None
    mask: np.ndarray

    @property
    def contact_found(self) -> bool:
        return self.flag is None


def otsu_separation(values: np.ndarray, threshold: float) -> float:
    """Otsu effectiveness η in [0, 1] of splitting ``values`` at ``threshold``."""
    values = np.asarray(values, dtype=float).ravel()
    total_variance = values.var()
    if total_variance == 0:
        return 0.0
    above = values > threshold
    weight_above = above.mean()
    if weight_above in (0.0, 1.0):
        return 0.0
    between = (
        weight_above * (1 - weight_above) * (values[above].mean() - values[~above].mean()) ** 2
    )
    return float(between / total_variance)


def class_contrast(values: np.ndarray, threshold: float, *, photon_counts: bool) -> float:
    """(mean above − mean below ``threshold``) / noise of the class below, where the noise is
    its standard deviation, at least √(mean + 1) for ``photon_counts`` (shot noise)."""
    values = np.asarray(values, dtype=float).ravel()
    above = values > threshold
    if above.all() or not above.any():
        return 0.0
    below = values[~above]
    noise = below.std()
    if photon_counts:
        noise = max(noise, float(np.sqrt(max(below.mean(), 0.0) + 1.0)))
    if noise == 0:
        return float("inf")
    return float((values[above].mean() - below.mean()) / noise)


def largest_patch_px(mask: np.ndarray) -> int:
    """Pixels in the largest 8-connected patch of ``mask`` (0 for an empty mask)."""
    labels, n = ndimage.label(mask, structure=np.ones((3, 3), dtype=bool))
    if n == 0:
        return 0
    return int(np.bincount(labels.ravel())[1:].max())


def _no_contact_reason(
    separation: float, contrast: float, patch_px: int, settings: OtsuSettings
) -> str | None:
    if separation < settings.min_separation:
        return (
            f"Otsu separation {separation:.3f} < {settings.min_separation:g}: contact and "
            "background intensities overlap (an image without contact gives ~0.64)"
        )
    if contrast < settings.min_contrast:
        return (
            f"the upper class is only {contrast:.2g} noise sd above the background "
            f"(< {settings.min_contrast:g}): no contact stands out"
        )
    if patch_px < settings.min_patch_px:
        return (
            f"largest bright patch {patch_px} px < {settings.min_patch_px} px: isolated bright "
            "pixels, not a contact"
        )
    return None


def otsu_contact_area(
    image: np.ndarray, pixel_m: float, settings: OtsuSettings | None = None
) -> ContactArea:
    """Contact area (m²) of a fluorescence image with square pixels of ``pixel_m`` metres.

    Integer images are taken as photon counts (shot-noise floor of the contrast). Raises
    ValueError for a constant image, where no threshold exists.
    """
    settings = settings or OtsuSettings()
    photon_counts = np.asarray(image).dtype.kind in "ui"
    image = np.asarray(image, dtype=float)
    if image.min() == image.max():
        raise ValueError(
            f"image is constant ({image.min():g} everywhere); no contact can be separated"
        )
    threshold = float(threshold_otsu(image, nbins=settings.bins))
    mask = image > threshold
    separation = otsu_separation(image, threshold)
    contrast = class_contrast(image, threshold, photon_counts=photon_counts)
    patch = largest_patch_px(mask)
    n_pixels = int(np.count_nonzero(mask))
    return ContactArea(
        area_m2=n_pixels * pixel_m**2,
        n_contact_pixels=n_pixels,
        threshold=threshold,
        separation=separation,
        contrast=contrast,
        largest_patch_px=patch,
        flag=_no_contact_reason(separation, contrast, patch, settings),
        mask=mask,
    )


def contact_geometry(mask: np.ndarray, pixel_m: float) -> tuple[tuple[float, float], float]:
    """Centre (row, col) px of a contact mask and the radius (m) of the circle of its area."""
    rows, cols = np.nonzero(mask)
    if rows.size == 0:
        raise ValueError("the contact mask is empty; expected a contact")
    radius_m = float(np.sqrt(rows.size / np.pi) * pixel_m)
    return (float(rows.mean()), float(cols.mean())), radius_m


def image_contact_area(image: Image, otsu: OtsuSettings) -> ContactArea:
    """Otsu contact of ``image``, flagged where no contact stands out; a constant image
    raises NoContact naming the file."""
    try:
        return otsu_contact_area(image.data, image.pixel_m, otsu)
    except ValueError as error:
        raise NoContact(f"{image.path}: {error}") from error


def separated_contact(image: Image, otsu: OtsuSettings) -> ContactArea:
    """Otsu contact of ``image``; raises NoContact, naming the file and why, when no contact
    stands out (:func:`otsu_contact_area`: separation, contrast, patch size)."""
    area = image_contact_area(image, otsu)
    if not area.contact_found:
        raise NoContact(f"{image.path}: {area.flag}; expected a contact brighter than it")
    return area


def image_pixel_m(sheet_pixel_nm: float | None, area_tables: Sequence[str | Path]) -> float:
    """The fluorescence images' pixel (m) a simulated contact is rendered at: the sheet's
    (``sheet_pixel_nm``), else the one the images' files gave, as the contact-area table
    (:func:`contact_area_table`, the one path of ``area_tables``) recorded it. Raises
    ValueError naming the table when it holds no single pixel size."""
    if sheet_pixel_nm is not None:
        return sheet_pixel_nm * 1e-9
    (path,) = area_tables
    pixels = [float(p) for p in pd.read_csv(path)["pixel_nm"].unique()]
    if len(pixels) != 1:
        raise ValueError(f"{path}: pixel_nm {pixels}; expected one pixel for the series")
    return float(pixels[0]) * 1e-9


def contact_area_table(
    loads_mn: Sequence[float], images: Sequence[Image], areas: Sequence[ContactArea]
) -> pd.DataFrame:
    """One row per load: the Otsu area and how well the image shows a contact (units in the
    column names). A flagged image keeps its row (``contact_found`` False, ``flag`` why);
    saturated pixels are counted (the area stands, intensities are clipped)."""
    rows = []
    for load, image, area in zip(loads_mn, images, areas, strict=True):
        rows.append(
            {
                "load_mn": load,
                "area_um2": area.area_m2 * 1e12,
                "contact_pixels": area.n_contact_pixels,
                "pixel_nm": image.pixel_m * 1e9,
                "otsu_threshold_counts": area.threshold,
                "otsu_separation": area.separation,
                "contrast_noise_sd": area.contrast,
                "largest_patch_px": area.largest_patch_px,
                "contact_found": area.contact_found,
                "flag": area.flag or "",
                "saturated_pixels": saturated_pixels(image.data),
                "pixel_source": image.pixel_source,
                "image": str(image.path),
            }
        )
    return pd.DataFrame(rows)
