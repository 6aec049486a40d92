"""AFM topography of a sphere: reading height maps, levelling, sphere fit, roughness statistics.

Heights are in metres, positive towards the cover slip (the apex of the sphere is the maximum).
Readers:

* TIFF (float heights in m; pixel size from the resolution tags or the sample sheet),
* ``.npy`` (float heights in m; pixel size from the sample sheet),
* the plain-text matrix Gwyddion exports ("Export → Text", with its informational header):
  ``# Width: 65.54 µm``, ``# Height: …``, ``# Value units: m``, then rows of numbers.
"""

from __future__ import annotations

import logging
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import ndimage, optimize

from amontons.images import ImageError, read_image

log = logging.getLogger(__name__)

_LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "µm": 1e-6, "um": 1e-6, "nm": 1e-9, "pm": 1e-12}


class TopographyError(ValueError):
    """A height map cannot be used as it is."""


@dataclass(frozen=True)
class HeightMap:
    """Heights (m) on a square grid of ``pixel_m`` metres; ``filled`` NaN pixels were filled."""

    heights: np.ndarray
    pixel_m: float
    path: Path
    filled: int = 0


def _length(value: str, unit: str, path: Path, key: str) -> float:
    unit = unit.strip()
    if unit not in _LENGTH_UNITS:
        raise TopographyError(
            f"{path}: {key} unit {unit!r} is not a length; "
            f"expected one of {', '.join(_LENGTH_UNITS)}"
        )
    return float(value) * _LENGTH_UNITS[unit]


def read_gwyddion_text(path: str | Path) -> tuple[np.ndarray, float | None]:
    """Heights (m) and pixel size (m, or None without a Width line) of a Gwyddion text export."""
    path = Path(path)
    header = {}
    with open(path, encoding="utf-8", errors="replace") as stream:
        for line in stream:
            if not line.startswith("#"):
                break
            match = re.match(r"#\s*([^:]+):\s*(.*)", line.strip())
            if match:
                header[match.group(1).strip().lower()] = match.group(2).strip()
    data = np.loadtxt(path, comments="#", ndmin=2)
    z_unit = header.get("value units", "m")
    if z_unit not in _LENGTH_UNITS:
        raise TopographyError(
            f"{path}: value units {z_unit!r} are not a length; expected a height map in "
            f"one of {', '.join(_LENGTH_UNITS)}"
        )
    heights = data * _LENGTH_UNITS[z_unit]
    pixel = None
    if "width" in header:
        value, _, unit = header["width"].partition(" ")
        pixel = _length(value, unit, path, "Width") / heights.shape[1]
    return heights, pixel


def fill_missing(heights: np.ndarray) -> tuple[np.ndarray, int]:
    """Replace NaN pixels by their nearest valid neighbour; return the map and the count."""
    missing = ~np.isfinite(heights)
    if not missing.any():
        return heights, 0
    _, (rows, cols) = ndimage.distance_transform_edt(missing, return_indices=True)
    return heights[rows, cols], int(missing.sum())


def read_height_map(
    path: str | Path, *, fallback_pixel_m: float | None = None, nan_policy: str = "fail"
) -> HeightMap:
    """Read an AFM height map (TIFF, .npy or Gwyddion text), heights in m.

    ``nan_policy`` is 'fail' (raise, naming the number and first position of NaN pixels) or
    'fill' (nearest valid neighbour, logged).
    """
    path = Path(path)
    if nan_policy not in ("fail", "fill"):
        raise ValueError(f"nan_policy must be 'fail' or 'fill', got {nan_policy!r}")
    if not path.is_file():
        raise TopographyError(f"{path}: no such height map")
    suffix = path.suffix.lower()
    if suffix in (".tif", ".tiff"):
        try:
            image = read_image(path, fallback_pixel_m, allow_nan=True)
        except ImageError as error:
            raise TopographyError(str(error)) from error
        heights, pixel = image.data.astype(float), image.pixel_m
    elif suffix == ".npy":
        heights, pixel = np.load(path).astype(float), fallback_pixel_m
    elif suffix in (".txt", ".asc", ".dat"):
        heights, pixel = read_gwyddion_text(path)
        pixel = pixel if pixel is not None else fallback_pixel_m
    else:
        raise TopographyError(
            f"{path}: unknown height-map format {suffix!r}; expected .tif, .npy or a Gwyddion "
            "text export (.txt/.asc)"
        )
    if heights.ndim != 2 or min(heights.shape) < 8:
        raise TopographyError(f"{path}: height map of shape {heights.shape}; expected 2-D")
    if pixel is None:
        raise TopographyError(f"{path}: no pixel size in the file and none in the sample sheet")
    missing = ~np.isfinite(heights)
    if missing.any():
        first = tuple(int(i) for i in np.argwhere(missing)[0])
        if nan_policy == "fail":
            raise TopographyError(
                f"{path}: {int(missing.sum())} NaN pixels (first at row, column {first}); set "
                "afm_nan_policy: fill to replace them by their nearest valid neighbour"
            )
        heights, count = fill_missing(heights)
        log.warning("%s: filled %d NaN pixels (first at %s)", path, count, first)
        return HeightMap(heights, float(pixel), path, count)
    return HeightMap(heights, float(pixel), path)


@dataclass(frozen=True)
class SphereFit:
    """Least-squares sphere through a height map.

    radius_m, apex (x, y) in m from the map centre, apex height in m; ``roughness`` is the map
    minus the sphere (and minus scan-line offsets, when removed), m; ``line_offsets`` per row, m.
    """

    radius_m: float
    apex_xy_m: tuple[float, float]
    apex_height_m: float
    roughness: np.ndarray
    line_offsets: np.ndarray


def _coordinates(shape, pixel_m):
    ny, nx = shape
    x = (np.arange(nx) - (nx - 1) / 2) * pixel_m
    y = (np.arange(ny) - (ny - 1) / 2) * pixel_m
    return np.meshgrid(x, y)


def sphere_cap(shape, pixel_m, radius_m, apex_xy_m=(0.0, 0.0), apex_height_m=0.0):
    """Heights of a sphere's cap (apex up), m: z0 − R + √(R² − r²)."""
    x, y = _coordinates(shape, pixel_m)
    r2 = (x - apex_xy_m[0]) ** 2 + (y - apex_xy_m[1]) ** 2
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


def scan_line_offsets(residual: np.ndarray) -> np.ndarray:
    """Per-row offsets (m) by the median of differences between consecutive rows (Gwyddion's
    'median of differences' row alignment): steps between rows are taken as offsets, smooth
    roughness contributes little because neighbouring rows are strongly correlated."""
    steps = np.median(np.diff(residual, axis=0), axis=1)
    offsets = np.concatenate([[0.0], np.cumsum(steps)])
    return offsets - np.median(offsets)


def level_sphere(heights: np.ndarray, pixel_m: float, *, align_rows: bool = True) -> SphereFit:
    """Fit a sphere, remove scan-line offsets from the residual, refit on corrected data."""
    radius, apex, z0 = _fit_sphere_once(heights, pixel_m)
    offsets = np.zeros(heights.shape[0])
    if align_rows:
        residual = heights - sphere_cap(heights.shape, pixel_m, radius, apex, z0)
        offsets = scan_line_offsets(residual)
        radius, apex, z0 = _fit_sphere_once(heights - offsets[:, None], pixel_m)
    roughness = heights - offsets[:, None] - sphere_cap(heights.shape, pixel_m, radius, apex, z0)
    return SphereFit(radius, apex, z0, roughness - roughness.mean(), offsets)


@dataclass(frozen=True)
class RoughnessStatistics:
    """h_rms (m), h'_rms = √⟨|∇h|²⟩ (dimensionless), h''_rms = rms of the mean curvature ½∇²h
    (1/m; the convention of SurfaceTopography's rms_curvature; rms(∇²h) is twice it)."""

    h_rms_m: float
    slope_rms: float
    curvature_rms_per_m: float


def roughness_statistics(roughness: np.ndarray, pixel_m: float) -> RoughnessStatistics:
    """Statistics of a roughness map by finite differences at its own pixel (the value of h'
    and h'' depends on the pixel: report it with them)."""
    gy, gx = np.gradient(roughness, pixel_m)
    laplacian = (
        roughness[2:, 1:-1]
        + roughness[:-2, 1:-1]
        + roughness[1:-1, 2:]
        + roughness[1:-1, :-2]
        - 4 * roughness[1:-1, 1:-1]
    ) / pixel_m**2
    return RoughnessStatistics(
        h_rms_m=float(np.std(roughness)),
        slope_rms=float(np.sqrt(np.mean(gx**2 + gy**2))),
        curvature_rms_per_m=float(np.sqrt(np.mean((0.5 * laplacian) ** 2))),
    )
