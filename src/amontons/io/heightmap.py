"""AFM height maps, heights in m, positive towards the cover slip.

Readers:

* TIFF (float heights in m; pixel size from the resolution tags or the sample sheet),
* ``.npy`` (float heights in m; pixel size from the sample sheet),
* the plain-text matrix Gwyddion exports ("Export → Text", with its informational header):
  ``# Width: 65.54 µm``, ``# Height: …``, ``# Value units: m``, then rows of numbers.

Writer: float TIFF with the pixel size in its resolution tags (the virtual experiment's scans).
"""

from __future__ import annotations

import logging
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import ndimage

from amontons.io.tiff import ImageError, read_image, write_image

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


def write_height_map(path: str | Path, heights_m: np.ndarray, pixel_m: float) -> None:
    """Write a height map (m) as a float32 TIFF with its pixel size in the resolution tags,
    atomically; refuses NaN or infinite heights."""
    heights = np.asarray(heights_m)
    if not np.all(np.isfinite(heights)):
        raise ValueError(f"{path}: refusing to write a height map with NaN or inf")
    write_image(path, heights.astype(np.float32), pixel_m)
