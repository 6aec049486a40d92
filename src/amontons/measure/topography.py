"""AFM topography of a sphere (docs/models.md §1.8): levelling by a sphere fit and, where the
scan lines are offset, line levelling; roughness statistics, and the plastic flattening between
two scans (Fig. B.9).

Heights are in metres, positive towards the cover slip (the apex of the sphere is the maximum);
the height maps are read by amontons.io.heightmap.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from scipy import ndimage, optimize

from amontons.io.fields import read_named_records, write_named_records
from amontons.io.heightmap import HeightMap, TopographyError, read_height_map
from amontons.io.layout import RawDataError
from amontons.measure.flattening import Flattening, measure_flattening
from amontons.measure.scan_lines import LineLevelling, ScanLineError, level_lines
from amontons.physics.roughness import RoughnessStatistics, roughness_statistics


@dataclass(frozen=True)
class FitParameters:
    """What a sphere fit found: radius (m), apex (x, y) from the map centre (m), apex height
    (m), and what was done to the scan lines (their offsets, m)."""

    radius_m: float
    apex_xy_m: tuple[float, float]
    apex_height_m: float
    line_levelling: LineLevelling


@dataclass(frozen=True)
class SphereFit(FitParameters):
    """Least-squares sphere through a height map: its parameters and the ``roughness``, the
    map minus the sphere (and minus scan-line offsets, when removed), m."""

    roughness: np.ndarray

    @property
    def line_offsets(self) -> np.ndarray:
        """Offset removed from each row, m (zeros when no line was levelled)."""
        return self.line_levelling.offsets_m


def _coordinates(shape, pixel_m):
    ny, nx = shape
    x = (np.arange(nx) - (nx - 1) / 2) * pixel_m
    y = (np.arange(ny) - (ny - 1) / 2) * pixel_m
    return np.meshgrid(x, y)


def sphere_cap(shape, pixel_m, radius_m, apex_xy_m=(0.0, 0.0), apex_height_m=0.0):
    """Heights of a sphere's cap (apex up), m: z0 − R + √(R² − r²)."""
    ny, nx = shape
    x = (np.arange(nx) - (nx - 1) / 2) * pixel_m
    y = (np.arange(ny) - (ny - 1) / 2) * pixel_m
    # The squared distances per column and per row, summed by broadcasting: the same floats
    # as on the two meshgrids (the fit calls this once per residual, on 2048² maps).
    r2 = ((x - apex_xy_m[0]) ** 2)[None, :] + ((y - apex_xy_m[1]) ** 2)[:, None]
    if np.max(r2) >= radius_m**2:
        raise TopographyError(f"map wider than the sphere of radius {radius_m:.3e} m")
    return apex_height_m - radius_m + np.sqrt(radius_m**2 - r2)


def _fit_sphere_once(heights, pixel_m):
    x, y = _coordinates(heights.shape, pixel_m)
    # paraboloid z = c0 + c1 x + c2 y + c3 r² as the start: R ≈ −1/(2 c3); coordinates in
    # units of the half-width L so that the columns of the design matrix are of one scale
    half = 0.5 * max(heights.shape) * pixel_m
    xs, ys = x / half, y / half
    design = np.stack([np.ones(x.size), xs.ravel(), ys.ravel(), (xs**2 + ys**2).ravel()], axis=1)
    c, *_ = np.linalg.lstsq(design, heights.ravel(), rcond=None)
    c = c / np.array([1.0, half, half, half**2])
    if c[3] >= 0:
        raise TopographyError("height map is not convex upwards: no sphere apex to fit")
    radius = -1 / (2 * c[3])
    x0, y0 = -c[1] / (2 * c[3]), -c[2] / (2 * c[3])
    z0 = c[0] - c[3] * (x0**2 + y0**2)
    scale = np.array([radius, pixel_m, pixel_m, pixel_m])

    def residual(params):
        r_, x_, y_, z_ = params * scale
        return (sphere_cap(heights.shape, pixel_m, r_, (x_, y_), z_) - heights).ravel()

    fit = optimize.least_squares(residual, np.array([radius, x0, y0, z0]) / scale, x_scale="jac")
    r_, x_, y_, z_ = fit.x * scale
    return float(r_), (float(x_), float(y_)), float(z_)


def level_sphere(heights: np.ndarray, pixel_m: float, *, line_levelling: str = "auto") -> SphereFit:
    """Fit a sphere; level the scan lines of the residual as ``line_levelling`` says
    (:func:`amontons.measure.scan_lines.level_lines`: ``auto``, ``on``, ``off``) and, if any
    offset was removed, refit the sphere on the corrected map."""
    radius, apex, z0 = _fit_sphere_once(heights, pixel_m)
    try:
        lines = level_lines(
            heights - sphere_cap(heights.shape, pixel_m, radius, apex, z0), line_levelling
        )
    except ScanLineError as error:
        raise TopographyError(str(error)) from error
    if lines.applied:
        radius, apex, z0 = _fit_sphere_once(heights - lines.offsets_m[:, None], pixel_m)
    return sphere_fit_with(heights, pixel_m, FitParameters(radius, apex, z0, lines))


def sphere_fit_with(heights: np.ndarray, pixel_m: float, fit: FitParameters) -> SphereFit:
    """The map levelled by a known fit: its roughness is the map minus the scan-line offsets
    and the sphere, less its mean (m), computed as :func:`level_sphere` computes it, so a
    fit read back from :func:`write_sphere_fits` gives the same roughness to the bit."""
    roughness = (
        heights
        - fit.line_levelling.offsets_m[:, None]
        - sphere_cap(heights.shape, pixel_m, fit.radius_m, fit.apex_xy_m, fit.apex_height_m)
    )
    return SphereFit(
        fit.radius_m,
        fit.apex_xy_m,
        fit.apex_height_m,
        fit.line_levelling,
        roughness - roughness.mean(),
    )


# The two scans of a sphere, as named in the fits' file.
SCANS = ("before", "after")


def write_sphere_fits(path: str | Path, topography: Topography) -> None:
    """Both scans' sphere fits and scan-line offsets (HDF5, float64 to the bit), so that a
    later step levels the maps again without fitting (:func:`read_sphere_fits`)."""
    write_fit_records(path, dict(zip(SCANS, (topography.before, topography.after), strict=True)))


def write_fit_records(path: str | Path, fits: Mapping[str, FitParameters]) -> None:
    """Sphere fits by name (``before``, ``after``) with their scan-line offsets (HDF5,
    float64 to the bit; :func:`read_fit_record`)."""
    records, arrays = {}, {}
    for name, fit in fits.items():
        lines = fit.line_levelling
        records[name] = {
            "radius_m": fit.radius_m,
            "apex_x_m": fit.apex_xy_m[0],
            "apex_y_m": fit.apex_xy_m[1],
            "apex_height_m": fit.apex_height_m,
            "line_mode": lines.mode,
            "lines_applied": bool(lines.applied),
            "stepped_rows": int(lines.stepped_rows),
            "every_row": bool(lines.every_row),
            "step_noise_m": float(lines.step_noise_m),
        }
        arrays[name] = {"line_offsets_m": lines.offsets_m}
    write_named_records(path, records, arrays)


def read_sphere_fits(path: str | Path) -> tuple[FitParameters, FitParameters]:
    """The fits :func:`write_sphere_fits` wrote, (before, after)."""
    records, arrays = read_named_records(path)
    before, after = (_fit_from(records[name], arrays[name]) for name in SCANS)
    return before, after


def read_fit_record(path: str | Path, name: str) -> FitParameters:
    """The fit :func:`write_fit_records` wrote under ``name``."""
    records, arrays = read_named_records(path)
    return _fit_from(records[name], arrays[name])


def _fit_from(r: Mapping, arrays: Mapping) -> FitParameters:
    """A fit from its record and its arrays as :func:`write_fit_records` wrote them."""
    lines = LineLevelling(
        r["line_mode"],
        bool(r["lines_applied"]),
        arrays["line_offsets_m"],
        int(r["stepped_rows"]),
        bool(r["every_row"]),
        float(r["step_noise_m"]),
    )
    return FitParameters(
        float(r["radius_m"]),
        (float(r["apex_x_m"]), float(r["apex_y_m"])),
        float(r["apex_height_m"]),
        lines,
    )


@dataclass(frozen=True)
class Topography:
    """The sphere's AFM scans before and after the load series, levelled (lengths in m)."""

    before: SphereFit
    after: SphereFit
    before_statistics: RoughnessStatistics
    after_statistics: RoughnessStatistics
    flattening: Flattening  # after − before: the change map and the depth of the flattening
    line_levelling: str  # the mode asked for: auto, on or off
    difference_levelling: LineLevelling  # scan-line offsets removed from after − before
    pixel_m: float
    filled_pixels: int
    nan_policy: str
    before_path: Path
    after_path: Path
    file_pixel_m: tuple[float, float]  # the files' pixel along x and y, before squaring
    channel: str | None  # the files' height channel read (None: a file of one channel)

    @property
    def change_m(self) -> np.ndarray:
        """after − before, the points that did not flow at 0, m."""
        return self.flattening.change_m

    def to_record(self) -> dict:
        """JSON-ready record, units in the key names."""

        def statistics(fit: SphereFit, stats: RoughnessStatistics) -> dict:
            return {
                "sphere_radius_mm": fit.radius_m * 1e3,
                "roughness_rms_nm": stats.h_rms_m * 1e9,
                "slope_rms": stats.slope_rms,
                "curvature_rms_per_um": stats.curvature_rms_per_m * 1e-6,
            }

        return {
            "quantity": "AFM topography levelled by a sphere fit (and scan-line levelling where "
            "lines are offset); statistics at the AFM pixel; flattening = median depth of the "
            "smoothed drop over the region that flowed",
            "pixel_nm": self.pixel_m * 1e9,
            "shape_px": list(self.change_m.shape),
            "file_pixel_nm": {"x": self.file_pixel_m[0] * 1e9, "y": self.file_pixel_m[1] * 1e9},
            "resampled_to_square_pixels": self.file_pixel_m[0] != self.file_pixel_m[1],
            "channel": self.channel,
            "before": statistics(self.before, self.before_statistics),
            "after": statistics(self.after, self.after_statistics),
            **self.flattening.to_record(),
            "line_levelling": {
                "mode": self.line_levelling,
                "before": self.before.line_levelling.to_record(),
                "after": self.after.line_levelling.to_record(),
                "difference": self.difference_levelling.to_record(),
            },
            "filled_nan_pixels": self.filled_pixels,
            "nan_policy": self.nan_policy,
            "before_file": str(self.before_path),
            "after_file": str(self.after_path),
        }


def square_pixels(height_map: HeightMap) -> HeightMap:
    """The map on square pixels of its finer spacing: the coarser axis is resampled by linear
    interpolation over the same extent (no new extrema, nothing lost along the finer axis).
    A map whose pixels are square already is returned as it is."""
    if height_map.square:
        return height_map
    dx, dy = height_map.pixel_m, height_map.pixel_y_m
    pixel = min(dx, dy)
    ny, nx = height_map.heights.shape
    rows = np.arange(int(np.floor((ny - 1) * dy / pixel + 1e-9)) + 1) * pixel / dy
    cols = np.arange(int(np.floor((nx - 1) * dx / pixel + 1e-9)) + 1) * pixel / dx
    grid = np.meshgrid(rows, cols, indexing="ij")
    heights = ndimage.map_coordinates(height_map.heights, grid, order=1, mode="nearest")
    return replace(height_map, heights=heights, pixel_m=pixel, pixel_y_m=pixel)


def measure_topography(
    before_path: str | Path,
    after_path: str | Path,
    fallback_pixel_m: float | None,
    *,
    nan_policy: str,
    channel: str | None = None,
    line_levelling: str = "auto",
    known_fits: tuple[FitParameters | None, FitParameters | None] | None = None,
) -> Topography:
    """Level both scans (sphere fit, scan-line offsets as ``line_levelling`` says: ``auto``,
    ``on``, ``off``) and take their roughness statistics and their difference, the plastic
    flattening (appendix Fig. B.9; :func:`amontons.measure.flattening.measure_flattening`).
    Both scans must cover the same field on the same grid (a repeated scan of the same area).
    ``channel`` names the height channel of a vendor file (None: the format's default). Scans
    with non-square pixels are resampled to square ones first (:func:`square_pixels`).
    ``known_fits``: the scans' fits, (before, after), as :func:`read_sphere_fits` gives
    them, which a step that has them passes instead of fitting again (the same result to the
    bit); a None in it is fitted here."""
    files = []
    for path in (before_path, after_path):
        try:
            files.append(
                read_height_map(
                    path, fallback_pixel_m=fallback_pixel_m, nan_policy=nan_policy, channel=channel
                )
            )
        except TopographyError as error:
            raise RawDataError(str(error)) from error
    same_grid = files[0].heights.shape == files[1].heights.shape and all(
        np.isclose(getattr(files[0], a), getattr(files[1], a), rtol=1e-6)
        for a in ("pixel_m", "pixel_y_m")
    )
    if not same_grid:
        raise RawDataError(
            f"{files[1].path}: {files[1].heights.shape} px of {files[1].pixel_m * 1e9:.4g} nm; "
            f"expected the field of {files[0].path} ({files[0].heights.shape} px of "
            f"{files[0].pixel_m * 1e9:.4g} nm)"
        )
    maps = [square_pixels(m) for m in files]
    before, after = maps
    if before.heights.shape != after.heights.shape or not np.isclose(
        before.pixel_m, after.pixel_m, rtol=1e-6
    ):
        raise RawDataError(
            f"{after.path}: {after.heights.shape} px of {after.pixel_m * 1e9:.4g} nm; expected "
            f"the field of {before.path} ({before.heights.shape} px of "
            f"{before.pixel_m * 1e9:.4g} nm)"
        )
    try:
        fits = [
            level_sphere(m.heights, m.pixel_m, line_levelling=line_levelling)
            if known is None
            else sphere_fit_with(m.heights, m.pixel_m, known)
            for m, known in zip(maps, known_fits or (None, None), strict=True)
        ]
    except TopographyError as error:
        raise RawDataError(f"{before.path}, {after.path}: {error}") from error
    difference, difference_lines = _levelled_difference(
        after.heights - before.heights, line_levelling
    )
    return Topography(
        file_pixel_m=(files[0].pixel_m, files[0].pixel_y_m),
        channel=files[0].channel,
        before=fits[0],
        after=fits[1],
        before_statistics=roughness_statistics(fits[0].roughness, before.pixel_m),
        after_statistics=roughness_statistics(fits[1].roughness, after.pixel_m),
        flattening=measure_flattening(difference, before.pixel_m),
        line_levelling=line_levelling,
        difference_levelling=difference_lines,
        pixel_m=before.pixel_m,
        filled_pixels=before.filled + after.filled,
        nan_policy=nan_policy,
        before_path=Path(before_path),
        after_path=Path(after_path),
    )


def _levelled_difference(difference: np.ndarray, mode: str) -> tuple[np.ndarray, LineLevelling]:
    """after − before without the scan-line offsets of either scan (m).

    The scans share their roughness, so offsets stand out of their difference far more
    clearly than of either scan. Only outstanding steps are removed, also when every row of
    the scans is aligned (``on``): near a large contact most of a row may have flowed, and
    aligning every row would take the flattening into the offsets.
    """
    lines = level_lines(difference, "off" if mode == "off" else "auto")
    return difference - lines.offsets_m[:, None], lines
