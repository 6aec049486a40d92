"""One sphere's measurements from its raw-data folder, one function per workflow rule.

Each function reads its files through amontons.rawdata, runs the measurement from
amontons.optics / amontons.friction / amontons.hertz_check and returns plain results; the
workflow scripts only write them. A measurement that cannot be made raises RawDataError naming
the file it came from and why.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.ndimage import binary_dilation, binary_fill_holes

from amontons.friction import RheometerError, amontons_deviation, static_friction
from amontons.hertz_check import hertz_check
from amontons.images import Image, read_image, saturated_pixels
from amontons.optics.absorbance import AbsorbanceError, GraftingDensity, grafting_density
from amontons.optics.area import ContactArea, OtsuSettings, otsu_contact_area
from amontons.optics.intensity import IntensityPressure, intensity_pressure
from amontons.optics.lifetime import LifetimeStatistics, lifetime_statistics
from amontons.optics.newton_rings import NewtonRingError, NewtonRingGap, newton_ring_gap
from amontons.optics.psf import PsfError, PsfMeasurement, measure_psf
from amontons.rawdata import (
    AFM_SUFFIXES,
    RawDataError,
    fluorescence_images,
    read_absorbance,
    read_bead,
    read_flim,
    read_reflection,
    read_rheometer_traces,
)
from amontons.surface import (
    RoughnessStatistics,
    SphereFit,
    TopographyError,
    level_sphere,
    read_height_map,
    roughness_statistics,
)


def contact_geometry(mask: np.ndarray, pixel_m: float) -> tuple[tuple[float, float], float]:
    """Centre (row, col) px of a contact mask and the radius (m) of the circle of its area."""
    rows, cols = np.nonzero(mask)
    if rows.size == 0:
        raise ValueError("the contact mask is empty; expected a contact")
    radius_m = float(np.sqrt(rows.size / np.pi) * pixel_m)
    return (float(rows.mean()), float(cols.mean())), radius_m


# --- optics ------------------------------------------------------------------------------------


def measure_bead(
    path: str | Path,
    fallback_pixel_m: float | None,
    *,
    profile_radius_m: float,
    centroid_radius_m: float,
) -> PsfMeasurement:
    """PSF FWHM from the bead image ``path`` (amontons.optics.psf.measure_psf)."""
    image = read_bead(path, fallback_pixel_m)
    try:
        return measure_psf(
            image.data,
            image.pixel_m,
            profile_radius_m=profile_radius_m,
            centroid_radius_m=centroid_radius_m,
        )
    except PsfError as error:
        raise RawDataError(f"{image.path}: {error}") from error


def measure_grafting_density(
    path: str | Path, *, frac: float, n_faces: int, epsilon_m2_per_mol: float
) -> GraftingDensity:
    """Grafting density from the spectrum ``path`` (LOWESS maximum over ε·faces)."""
    wavelength_nm, absorbance = read_absorbance(path)
    try:
        return grafting_density(
            wavelength_nm,
            absorbance,
            frac=frac,
            n_faces=n_faces,
            epsilon_m2_per_mol=epsilon_m2_per_mol,
        )
    except AbsorbanceError as error:
        raise RawDataError(f"{path}: {error}") from error


@dataclass(frozen=True)
class EdgeGap:
    """Newton-ring gap at the fluorescent contact edge, with where the edge was found."""

    rings: NewtonRingGap
    centre_px: tuple[float, float]  # (row, col), from the fluorescence Otsu mask
    contact_radius_m: float
    fluorescence_path: Path
    reflection_path: Path


class NotMeasurable(RawDataError):
    """Well-formed data that hold nothing to measure: the result says so (a flagged null)
    instead of giving a number."""


class RingsUnreadable(NotMeasurable):
    """A reflection image whose Newton rings cannot be numbered (e.g. a rough sphere's)."""


class NoContact(NotMeasurable):
    """An image in which no contact stands out from the background (Otsu classes overlap)."""


def read_fluorescence_series(
    fluorescence_dir: str | Path, loads_mn: Sequence[float], fallback_pixel_m: float | None
) -> list[Image]:
    """A sphere's fluorescence images in the order of ``loads_mn``; raises RawDataError if
    their pixel sizes differ (areas and pressures of one series share one pixel)."""
    images = []
    for path in fluorescence_images(fluorescence_dir, list(loads_mn)):
        image = read_image(path, fallback_pixel_m)
        if images and abs(image.pixel_m - images[0].pixel_m) > 1e-6 * images[0].pixel_m:
            raise RawDataError(
                f"{path}: pixel {image.pixel_m * 1e9:.4g} nm differs from "
                f"{images[0].path}'s {images[0].pixel_m * 1e9:.4g} nm; expected one pixel size "
                "per sphere"
            )
        images.append(image)
    return images


def image_contact_area(image: Image, otsu: OtsuSettings) -> ContactArea:
    """Otsu contact of ``image``, flagged where no contact stands out; a constant image
    raises NoContact naming the file."""
    try:
        return otsu_contact_area(image.data, image.pixel_m, otsu)
    except ValueError as error:
        raise NoContact(f"{image.path}: {error}") from error


def separated_contact(image: Image, otsu: OtsuSettings) -> ContactArea:
    """Otsu contact of ``image``; raises NoContact, naming the file and why, when no contact
    stands out (amontons.optics.area: separation, contrast, patch size)."""
    area = image_contact_area(image, otsu)
    if not area.contact_found:
        raise NoContact(f"{image.path}: {area.flag}; expected a contact brighter than it")
    return area


def measure_edge_gap(
    reflection_path: str | Path,
    fluorescence_path: str | Path,
    fallback_pixel_m: float | None,
    *,
    otsu: OtsuSettings,
    n_profiles: int,
    edge_model: str,
    max_rings: int | None = None,
    hertz_radius_m: float | None = None,
) -> EdgeGap:
    """Gap at the contact edge from the reflection image (appendix Figs. B.6, B.7).

    The contact centre comes from the Otsu mask of ``fluorescence_path`` (the image at the
    reflection load, on the reflection's pixel grid); the edge is where that image shows it:
    the radius of the circle with the area of the mask with its holes filled (the outer
    boundary of a patchy contact). ``hertz_radius_m``, the Hertz radius of the load from
    the sheet's E* and diameter, is the radius of the exterior shape the rings are fitted
    with (amontons.optics.newton_rings.newton_ring_gap). Raises NoContact if the
    fluorescence image shows no contact, RingsUnreadable if the rings cannot be numbered.
    """
    fluorescence = read_image(fluorescence_path, fallback_pixel_m)
    area = separated_contact(fluorescence, otsu)
    try:
        centre, _ = contact_geometry(area.mask, fluorescence.pixel_m)
    except ValueError as error:
        raise RawDataError(f"{fluorescence.path}: {error}") from error
    radius = float(np.sqrt(binary_fill_holes(area.mask).sum() / np.pi) * fluorescence.pixel_m)
    reflection = read_reflection(reflection_path, fallback_pixel_m, like=fluorescence)
    try:
        rings = newton_ring_gap(
            reflection.data,
            reflection.pixel_m,
            centre,
            radius,
            n_profiles,
            edge_model=edge_model,
            max_rings=max_rings,
            shape_radius_m=hertz_radius_m,
        )
    except NewtonRingError as error:
        raise RingsUnreadable(f"{reflection.path}: {error}") from error
    return EdgeGap(rings, centre, radius, fluorescence.path, reflection.path)


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
    fluorescence_dir: str | Path,
    loads_mn: Sequence[float],
    fallback_pixel_m: float | None,
    *,
    otsu: OtsuSettings,
    background_margin_px: int,
    pressure_ref_pa: float,
    confidence: float = 0.95,
) -> tuple[IntensityPressure, list[float], dict[float, str]]:
    """Mean contact intensity versus mean contact pressure F/A (appendix Fig. B.4).

    Returns the fit, each fitted image's background (counts, from the pixels far from the
    mask) and the loads left out (mN → why): an image in which no contact stands out
    (:func:`separated_contact`) has no contact intensity, as in the load–area fit.
    Raises RawDataError if fewer than three loads are left.
    """
    images, masks, backgrounds, kept_loads, excluded = [], [], [], [], {}
    series = read_fluorescence_series(fluorescence_dir, loads_mn, fallback_pixel_m)
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
            f"{fluorescence_dir}: {len(kept_loads)} of {len(loads_mn)} images show a contact "
            f"(left out: {sorted(excluded)} mN); the intensity-pressure fit needs at least 3"
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
        raise RawDataError(f"{fluorescence_dir}: {error}") from error
    return result, backgrounds, excluded


def measure_lifetime(
    path: str | Path,
    fallback_pixel_m: float | None,
    *,
    otsu: OtsuSettings,
    exclude_edge_px: int,
) -> LifetimeStatistics:
    """Arrival-time statistics inside and outside the contact of the FLIM map ``path``.

    The FLIM map comes from another microscope (appendix Fig. B.3), so its contact mask is
    found in the map itself: confined molecules emit later, so the contact is the Otsu class of
    long arrival times. Raises NoContact if no such class stands out.
    """
    image = read_flim(path, fallback_pixel_m)
    mask = separated_contact(image, otsu).mask
    try:
        return lifetime_statistics(image.data, mask, exclude_edge_px=exclude_edge_px)
    except ValueError as error:
        raise RawDataError(f"{image.path}: {error}") from error


# --- friction ----------------------------------------------------------------------------------


def measure_friction(
    rheometer_dir: str | Path,
    loads_mn: Sequence[float],
    *,
    median_window_s: float,
    plateau_fraction: float,
) -> pd.DataFrame:
    """Friction per load from ``<folder>/rheometer/<load>.csv``; units in the column names."""
    rows = []
    for load, trace in zip(
        loads_mn, read_rheometer_traces(rheometer_dir, list(loads_mn)), strict=True
    ):
        try:
            result = static_friction(
                trace, median_window_s=median_window_s, plateau_fraction=plateau_fraction
            )
        except RheometerError as error:
            raise RawDataError(str(error)) from error
        rows.append(
            {
                "load_mN": load,
                "normal_force_mN": result.normal_force_n * 1e3,
                "static_friction_mN": result.static_friction_n * 1e3,
                "dynamic_friction_mN": result.dynamic_friction_n * 1e3,
                "dynamic_friction_se_mN": result.dynamic_friction_se_n * 1e3,
                "static_coefficient": result.static_coefficient,
                "dynamic_coefficient": result.dynamic_coefficient,
                "sliding_speed_um_s": result.sliding_speed_m_s * 1e6,
                "sliding_distance_um": result.sliding_distance_m * 1e6,
                "peak_time_s": result.peak_time_s,
                "rotation_radius_mm": result.rotation_radius_m * 1e3,
                "file": trace.source,
            }
        )
    return pd.DataFrame(rows)


# --- per-sphere and per-material tables from measured tables -----------------------------------


def hertz_check_table(area_table: pd.DataFrame, radius_m: float, e_star_pa: float) -> pd.DataFrame:
    """Measured (Otsu) contact radius against Hertz per load, units in the column names.

    Loads where no contact was found are kept but flagged (column contact_found).
    """
    table = hertz_check(
        area_table["load_mN"].to_numpy() * 1e-3,
        area_table["area_um2"].to_numpy() * 1e-12,
        radius_m,
        e_star_pa,
    )
    return pd.DataFrame(
        {
            "load_mN": table["load_N"] * 1e3,
            "area_um2": table["area_m2"] * 1e12,
            "measured_radius_um": table["measured_radius_m"] * 1e6,
            "hertz_radius_um": table["hertz_radius_m"] * 1e6,
            "radius_ratio": table["radius_ratio"],
            "contact_found": area_table["contact_found"].to_numpy(),
        }
    )


def amontons_table(
    spheres: Sequence[str],
    area_tables: Sequence[pd.DataFrame],
    friction_tables: Sequence[pd.DataFrame],
    reference_load_mn: float,
) -> pd.DataFrame:
    """Area and static friction per load and sphere, normalised at ``reference_load_mn``
    (appendix Fig. B.13), from each sphere's contact_area.csv and friction.csv tables.

    Loads whose area is ill-determined (Otsu) are left out. The normal force is the
    rheometer's measured one.
    """
    frames = []
    for sphere, areas, friction in zip(spheres, area_tables, friction_tables, strict=True):
        merged = areas[areas["contact_found"]].merge(friction, on="load_mN", how="inner")
        deviation = amontons_deviation(
            merged["normal_force_mN"].to_numpy() * 1e-3,
            merged["area_um2"].to_numpy() * 1e-12,
            merged["static_friction_mN"].to_numpy() * 1e-3,
            reference_load_n=reference_load_mn * 1e-3,
        )
        # The same reference row as amontons_deviation: the load nearest the reference.
        reference = int(np.argmin(np.abs(deviation["normal_force_N"] - reference_load_mn * 1e-3)))
        frames.append(
            pd.DataFrame(
                {
                    "sphere": sphere,
                    "load_mN": merged.sort_values("normal_force_mN")["load_mN"].to_numpy(),
                    "normal_force_mN": deviation["normal_force_N"] * 1e3,
                    "area_um2": deviation["area_m2"] * 1e12,
                    "static_friction_mN": deviation["static_friction_N"] * 1e3,
                    "friction_coefficient": deviation["friction_coefficient"],
                    "shear_strength_MPa": deviation["shear_strength_Pa"] * 1e-6,
                    "area_over_area_ref": deviation["area_over_area_ref"],
                    "friction_over_friction_ref": deviation["static_friction_N"]
                    / deviation["static_friction_N"].iloc[reference],
                    "mu_over_mu_ref": deviation["mu_over_mu_ref"],
                }
            )
        )
    return pd.concat(frames, ignore_index=True)


# --- AFM topography -----------------------------------------------------------------------------


@dataclass(frozen=True)
class Topography:
    """The sphere's AFM scans before and after the load series, levelled (lengths in m)."""

    before: SphereFit
    after: SphereFit
    before_statistics: RoughnessStatistics
    after_statistics: RoughnessStatistics
    change_m: np.ndarray  # after − before, the unchanged points at 0, m
    pixel_m: float
    filled_pixels: int


def afm_file(folder: str | Path, stem: str) -> Path:
    """The AFM height map ``stem`` (afm_before / afm_after) in ``folder``, in whichever of the
    readable formats it is; RawDataError naming the folder if none or several."""
    folder = Path(folder)
    found = [folder / f"{stem}{ext}" for ext in AFM_SUFFIXES if (folder / f"{stem}{ext}").is_file()]
    if len(found) != 1:
        raise RawDataError(
            f"{folder}: expected exactly one {stem} height map "
            f"({', '.join(stem + s for s in AFM_SUFFIXES)}), found {len(found)}"
        )
    return found[0]


def unchanged_level(change_m: np.ndarray, bin_m: float = 0.25e-9) -> float:
    """The height change (m) of the points that did not flow: the mode of after − before.

    Two AFM scans share no absolute height, and flattened points are not a minority near a
    large contact, so neither 0 nor the median is the reference; the points that never
    touched (most of a rough sphere, even inside the contact) form a peak as narrow as the
    scan noise.
    """
    low, high = np.percentile(change_m, [0.5, 99.5])
    if high - low < bin_m:
        return float(np.median(change_m))  # nothing flowed: one narrow population
    bins = int(np.ceil((high - low) / bin_m))
    counts, edges = np.histogram(change_m, bins=bins, range=(low, high))
    peak = int(np.argmax(counts))
    # the peak bin locates the population; its median places it to better than a bin
    inside = change_m[(change_m >= edges[peak] - bin_m) & (change_m <= edges[peak + 1] + bin_m)]
    return float(np.median(inside))


def measure_topography(
    before_path: str | Path,
    after_path: str | Path,
    fallback_pixel_m: float | None,
    *,
    nan_policy: str,
) -> Topography:
    """Level both scans (sphere fit, scan-line offsets) and take their roughness statistics and
    their difference, the plastic flattening (appendix Fig. B.9). Both scans must cover the
    same field on the same grid (a repeated scan of the same area)."""
    maps = []
    for path in (before_path, after_path):
        try:
            maps.append(
                read_height_map(path, fallback_pixel_m=fallback_pixel_m, nan_policy=nan_policy)
            )
        except TopographyError as error:
            raise RawDataError(str(error)) from error
    before, after = maps
    if before.heights.shape != after.heights.shape or not np.isclose(
        before.pixel_m, after.pixel_m, rtol=1e-6
    ):
        raise RawDataError(
            f"{after.path}: {after.heights.shape} px of {after.pixel_m * 1e9:.4g} nm; expected "
            f"the field of {before.path} ({before.heights.shape} px of "
            f"{before.pixel_m * 1e9:.4g} nm)"
        )
    fits = [level_sphere(m.heights, m.pixel_m) for m in maps]
    # No row alignment of the difference: near a large contact most of a row may have flowed,
    # so row statistics would eat the flattening; the scan-line offsets (a few nm on a few
    # rows) stay in it, which the report's tolerance allows for.
    change = after.heights - before.heights
    return Topography(
        before=fits[0],
        after=fits[1],
        before_statistics=roughness_statistics(fits[0].roughness, before.pixel_m),
        after_statistics=roughness_statistics(fits[1].roughness, after.pixel_m),
        change_m=change - unchanged_level(change),
        pixel_m=before.pixel_m,
        filled_pixels=before.filled + after.filled,
    )
