"""Reading and writing microscope images (TIFF) with their pixel size.

The pixel size comes from the TIFF resolution tags when they carry a physical unit, otherwise
from the value the caller supplies (the sample sheet). Writes are atomic: a file is either
complete or absent.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import tifffile

from amontons.io.files import atomic_path

log = logging.getLogger(__name__)

_METRES_PER_UNIT = {2: 0.0254, 3: 0.01}  # TIFF ResolutionUnit: 2 = inch, 3 = centimetre
_INCH = 2
# Image software writes 72, 96, 150, 300 or 600 dots per inch whatever the image shows: an
# inch resolution this coarse (a pixel of 21 µm or more) is a display default, never the pixel
# of a microscope or an AFM (their pixels are nm to a few µm), so it is not a pixel size.
_DISPLAY_DPI_MAX = 1200.0
# A file's pixel and the sheet's fluorescence_pixel_nm that differ by more than this relative
# difference belong to different objectives or zooms: the run stops rather than pick one.
PIXEL_AGREEMENT = 0.01
# Where an image's pixel size came from (Image.pixel_source, and the measurements' records).
PIXEL_FROM_FILE, PIXEL_FROM_SHEET = "file", "sheet"


class ImageError(ValueError):
    """An image file is not a usable single-channel 2-D microscope image."""


@dataclass(frozen=True)
class Image:
    """A 2-D image and its square pixel size in metres; ``pixel_source`` says whether that
    came from the file's metadata ('file') or the sample sheet ('sheet'); ``format`` names the
    file format it was read from."""

    data: np.ndarray
    pixel_m: float
    path: Path
    pixel_source: str = PIXEL_FROM_FILE
    format: str = "TIFF"


@dataclass(frozen=True)
class TiffPixels:
    """The image of a TIFF (its first series) and the pixel size its resolution tags give
    (m; None where the tags give none, or only a display default such as 72 dpi)."""

    data: np.ndarray
    pixel_x_m: float | None
    pixel_y_m: float | None


def _tag_pixel(tags, name: str, unit: int) -> float | None:
    """Pixel (m) along one axis from a resolution tag, or None."""
    if name not in tags:
        return None
    numerator, denominator = tags[name].value
    if numerator <= 0 or denominator <= 0:
        return None
    per_unit = numerator / denominator
    if unit == _INCH and per_unit <= _DISPLAY_DPI_MAX:
        log.info("%s of %g dpi is a display default, not a pixel size; ignored", name, per_unit)
        return None
    return _METRES_PER_UNIT[unit] / per_unit


def _pixels_from_tags(page: tifffile.TiffPage) -> tuple[float | None, float | None]:
    tags = page.tags
    if "ResolutionUnit" not in tags:
        return None, None
    unit = int(tags["ResolutionUnit"].value)
    if unit not in _METRES_PER_UNIT:
        return None, None
    return _tag_pixel(tags, "XResolution", unit), _tag_pixel(tags, "YResolution", unit)


def read_tiff(path: str | Path) -> TiffPixels:
    """The image of the TIFF ``path`` (its first series), squeezed, with the pixel size of its tags.

    Raises ImageError naming the file when it is missing or tifffile cannot read it (empty,
    truncated, not a TIFF).
    """
    path = Path(path)
    if not path.is_file():
        raise ImageError(f"{path}: no such image")
    try:
        with tifffile.TiffFile(path) as tif:
            data = tif.asarray()
            pixel_x, pixel_y = _pixels_from_tags(tif.pages[0])
    except (tifffile.TiffFileError, ValueError, OSError, EOFError, IndexError) as error:
        raise ImageError(
            f"{path}: not a readable TIFF ({type(error).__name__}: {error}); expected a "
            "complete single-page TIFF file"
        ) from error
    return TiffPixels(np.squeeze(data), pixel_x, pixel_y)


def read_image(
    path: str | Path, fallback_pixel_m: float | None = None, *, allow_nan: bool = False
) -> Image:
    """Read a single-channel 2-D TIFF of unsigned integer or float pixels.

    Raises ImageError naming the file when it cannot be read, the image is not 2-D, has a
    signed-integer, boolean or complex dtype, contains NaN or infinite pixels, or has no pixel
    size from either its tags or ``fallback_pixel_m``; resolution tags of a display default
    (inch resolutions of 1200 dpi and below, e.g. 72 dpi) give none; or when the tags and
    ``fallback_pixel_m`` (the sheet) differ by more than 1 % (resolve_pixel). ``allow_nan``
    leaves NaN pixels to the caller.
    """
    path = Path(path)
    tiff = read_tiff(path)
    data, tag_pixel = tiff.data, tiff.pixel_x_m
    if data.ndim != 2:
        raise ImageError(
            f"{path}: image has shape {data.shape}; expected one 2-D single-channel frame"
        )
    kind = data.dtype.kind  # 'u' unsigned integer, 'f' floating point
    if kind not in ("u", "f"):
        raise ImageError(
            f"{path}: pixel dtype {data.dtype}; expected unsigned integer (uint8/uint16/uint32) "
            "photon counts or floating point"
        )
    if not allow_nan and kind == "f" and not np.all(np.isfinite(data)):
        bad = int(np.count_nonzero(~np.isfinite(data)))
        raise ImageError(f"{path}: {bad} NaN or infinite pixels; expected finite intensities")
    pixel_m, source = resolve_pixel(path, tag_pixel, fallback_pixel_m, "TIFF resolution tags")
    return Image(data=data, pixel_m=pixel_m, path=path, pixel_source=source)


def resolve_pixel(
    path: Path, file_pixel_m: float | None, sheet_pixel_m: float | None, where: str
) -> tuple[float, str]:
    """The pixel size (m) of the image ``path`` and its source ('file' or 'sheet').

    The file's pixel (``file_pixel_m``, read from ``where`` in it) wins; without one the
    sheet's is used and the log says so. Raises ImageError naming the file and both values
    when neither gives one, or when both do and differ by more than PIXEL_AGREEMENT.
    """
    if file_pixel_m is None and sheet_pixel_m is None:
        raise ImageError(
            f"{path}: no pixel size in the {where} and no fluorescence_pixel_nm in the sheet; "
            "expected one of them"
        )
    if file_pixel_m is None:
        log.info(
            "%s: no pixel size in the %s; the sheet's %.6g nm is used",
            path,
            where,
            sheet_pixel_m * 1e9,
        )
        return float(sheet_pixel_m), PIXEL_FROM_SHEET
    if sheet_pixel_m is not None:
        difference = abs(file_pixel_m - sheet_pixel_m) / sheet_pixel_m
        if difference > PIXEL_AGREEMENT:
            raise ImageError(
                f"{path}: the {where} give a pixel of {file_pixel_m * 1e9:.6g} nm, the sheet's "
                f"fluorescence_pixel_nm is {sheet_pixel_m * 1e9:.6g} nm: they differ by "
                f"{difference:.2%}; expected them within {PIXEL_AGREEMENT:.0%} (correct the "
                "sheet, or leave its fluorescence_pixel_nm empty to take the file's)"
            )
    return float(file_pixel_m), PIXEL_FROM_FILE


def saturated_pixels(data: np.ndarray) -> int:
    """Pixels at the ceiling of an unsigned-integer image (detector saturation); 0 for floats."""
    if data.dtype.kind != "u":
        return 0
    return int(np.count_nonzero(data == np.iinfo(data.dtype).max))


def write_image(path: str | Path, data: np.ndarray, pixel_m: float) -> None:
    """Write a 2-D image as TIFF with its pixel size in the resolution tags (pixels per cm)."""
    pixels_per_cm = 0.01 / pixel_m
    with atomic_path(path) as tmp:
        tifffile.imwrite(
            tmp, data, resolution=(pixels_per_cm, pixels_per_cm), resolutionunit="CENTIMETER"
        )
