"""AFM height maps: heights in m, rows along y and columns along x, positive towards the cover
slip, with the pixel size along each axis (a scan's pixels need not be square).

Readers, by file suffix:

* vendor formats through SurfaceTopography (the library contact.engineering runs on): Bruker
  and Veeco Nanoscope (``.spm``, ``.001``…, ``.di``), Asylum Research Igor (``.ibw``),
  Nanosurf (``.nid``, ``.ezd``), Molecular Imaging (``.mi``), WSxM (``.top``…), Digital Surf
  (``.sur``), ISO 25178 (``.x3p``, ``.sdf``), Zygo (``.dat``, ``.datx``), Gwyddion (``.gwy``),
  NT-MDT (``.mdt``), JPK (``.jpk``), Keyence, Sensofar, Olympus, …, the Park Systems TIFF, and
  the text matrices that Gwyddion exports ("Export → Text", English or German header);
* a float TIFF of heights in m (the virtual experiment's scans), the pixel size in its
  resolution tags;
* ``.npy``, float heights in m, the pixel size from the sample sheet.

The file's height channel is chosen by name (``channel``), by default the format's default
channel. Metadata are strict: heights must be floats in a known length unit; the pixel size
comes from the file or the sheet, never from a display default (72 dpi); a file and a sheet
that disagree are an error naming both. Every failure to read is a TopographyError naming the
file and what was expected.

Writer: float TIFF with the pixel size in its resolution tags (the virtual experiment's scans).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import ndimage

from amontons.io.layout import AFM_SUFFIXES, AFM_TIFF_SUFFIXES, AFM_VENDOR_SUFFIXES
from amontons.io.tiff import ImageError, read_tiff, write_image

log = logging.getLogger(__name__)

LENGTH_UNITS = {
    "m": 1.0,
    "mm": 1e-3,
    "µm": 1e-6,  # micro sign, U+00B5
    "μm": 1e-6,  # Greek mu, U+03BC
    "um": 1e-6,
    "nm": 1e-9,
    "Å": 1e-10,
    "pm": 1e-12,
}
VENDOR_SUFFIXES, TIFF_SUFFIXES, SUFFIXES = AFM_VENDOR_SUFFIXES, AFM_TIFF_SUFFIXES, AFM_SUFFIXES
TEXT_SUFFIXES = (".txt", ".asc")
# The smallest map a sphere fit and the roughness statistics can use.
MIN_SIDE_PX = 8
# Peak-to-valley heights an AFM map of a sphere's apex can have: below a picometre is no
# surface (a wrong unit: nm written on metres), above a millimetre no AFM scan (an image of
# counts or a preview taken for metres).
PLAUSIBLE_PEAK_TO_VALLEY_M = (1e-12, 1e-3)
# A file's pixel and the sheet's agree when they differ by less than this.
PIXEL_TOLERANCE = 0.01


class TopographyError(ValueError):
    """A height map cannot be used as it is."""


@dataclass(frozen=True)
class HeightMap:
    """Heights (m; rows along y, columns along x) with the pixel along x (``pixel_m``) and
    along y (``pixel_y_m``); ``filled`` NaN pixels were filled; ``channel`` is the file's
    channel that was read (None for a file of one channel)."""

    heights: np.ndarray
    pixel_m: float
    path: Path
    filled: int = 0
    pixel_y_m: float | None = None
    channel: str | None = None

    def __post_init__(self):
        if self.pixel_y_m is None:
            object.__setattr__(self, "pixel_y_m", self.pixel_m)

    @property
    def square(self) -> bool:
        """Whether the pixels are square (to 1e-6)."""
        return abs(self.pixel_y_m - self.pixel_m) <= 1e-6 * self.pixel_m


@dataclass(frozen=True)
class RawHeights:
    """What a file holds, before any policy: heights in m (rows along y), its pixel along x
    and y in m (None where the file has none) and the channel read."""

    heights: np.ndarray
    pixel_x_m: float | None
    pixel_y_m: float | None
    channel: str | None = None


def _length_factor(unit, path: Path, what: str) -> float:
    if unit not in LENGTH_UNITS:
        raise TopographyError(
            f"{path}: {what} in {unit!r}, which is not a length; expected one of "
            f"{', '.join(LENGTH_UNITS)}"
        )
    return LENGTH_UNITS[unit]


def _check_text_rows(path: Path) -> None:
    """A text matrix must be UTF-8 and every data row must hold as many numbers as the first:
    a file cut inside a row is refused (SurfaceTopography would drop the partial row)."""
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except UnicodeDecodeError as error:
        raise TopographyError(
            f"{path}: not UTF-8 text ({error.reason} at byte {error.start}); expected a "
            "text export saved as UTF-8"
        ) from error
    for line in lines:
        key, _, value = line.lstrip("#").partition(":")
        if line.startswith("#") and key.strip().lower() == "value units":
            _length_factor(value.strip(), path, "Value units")
    rows = [line.split() for line in lines if line.strip() and not line.startswith("#")]
    if rows and any("," in token for token in rows[0]):
        raise TopographyError(
            f"{path}: numbers with decimal commas ({rows[0][0]!r}); expected decimal points"
        )
    for number, row in enumerate(rows[1:], start=2):
        if len(row) != len(rows[0]):
            raise TopographyError(
                f"{path}: data row {number} holds {len(row)} numbers, the first {len(rows[0])}; "
                "expected a complete matrix (is the file truncated?)"
            )


def _pick_channel(reader, channel: str | None, path: Path):
    names = [c.name for c in reader.channels]
    if not names:
        raise TopographyError(f"{path}: no data channel in the file; expected a height map")
    if channel is None:
        return reader.default_channel
    matches = [c for c in reader.channels if c.name == channel]
    if not matches:
        raise TopographyError(
            f"{path}: no channel {channel!r} (surface.afm_channel); the file's channels: "
            f"{', '.join(repr(n) for n in names)}"
        )
    return matches[0]


def _read_vendor(path: Path, channel: str | None) -> RawHeights:
    """A height channel through SurfaceTopography, converted to m, rows along y."""
    from SurfaceTopography import open_topography  # 1.6 s to import: only for vendor files

    if path.suffix.lower() in TEXT_SUFFIXES:
        _check_text_rows(path)
    try:
        reader = open_topography(str(path))
    except Exception as error:  # the library raises many kinds; all mean "cannot read"
        reason = " ".join(str(error).split())[:300]
        raise TopographyError(
            f"{path}: not a readable height map ({type(error).__name__}: {reason}); "
            f"expected an AFM file of a supported format ({', '.join(SUFFIXES)})"
        ) from error
    picked = _pick_channel(reader, channel, path)
    lateral_unit, height_unit = (
        picked.unit if isinstance(picked.unit, tuple) else (picked.unit, picked.unit)
    )
    names = ", ".join(repr(c.name) for c in reader.channels)
    if height_unit is None:
        raise TopographyError(
            f"{path}: channel {picked.name!r} has no height unit (a phase, amplitude or a "
            f"file without a 'Value units' line); expected heights in a length unit - choose "
            f"a height channel with surface.afm_channel (channels: {names})"
        )
    scale = _length_factor(height_unit, path, f"channel {picked.name!r} heights")
    nx, ny = picked.nb_grid_pts
    sizes = picked.physical_sizes
    try:
        topography = picked.topography(physical_sizes=None if sizes is not None else (nx, ny))
        heights = np.ma.filled(np.ma.asarray(topography.heights(), dtype=float), np.nan)
    except Exception as error:
        raise TopographyError(
            f"{path}: channel {picked.name!r} cannot be read ({type(error).__name__}: {error})"
        ) from error
    if sizes is None:
        pixel_x = pixel_y = None
    else:
        lateral = _length_factor(lateral_unit, path, "lateral size")
        pixel_x, pixel_y = sizes[0] / nx * lateral, sizes[1] / ny * lateral
    # SurfaceTopography indexes heights [x, y]; a map here has rows along y
    return RawHeights(heights.T * scale, pixel_x, pixel_y, picked.name)


def _read_npy(path: Path) -> RawHeights:
    try:
        heights = np.load(path, allow_pickle=False)
    except (ValueError, OSError, EOFError) as error:
        raise TopographyError(
            f"{path}: not a readable .npy array ({type(error).__name__}: {error}); expected a "
            "2-D float array saved by numpy.save"
        ) from error
    if heights.dtype.kind != "f":
        raise TopographyError(
            f"{path}: heights of dtype {heights.dtype}; expected float heights in m (an "
            "integer or complex array carries no unit)"
        )
    return RawHeights(np.asarray(heights, dtype=float), None, None)


def _read_tiff_map(path: Path, channel: str | None) -> RawHeights:
    """A float TIFF of heights in m, or else a vendor TIFF (Park Systems)."""
    try:
        tiff = read_tiff(path)
    except ImageError as error:
        raise TopographyError(str(error)) from error
    if tiff.data.dtype.kind == "f":
        return RawHeights(np.asarray(tiff.data, dtype=float), tiff.pixel_x_m, tiff.pixel_y_m)
    try:
        return _read_vendor(path, channel)
    except TopographyError as error:
        raise TopographyError(
            f"{path}: {tiff.data.dtype} pixels and not a vendor TIFF that SurfaceTopography "
            f"reads ({error}); expected float heights in m, or a Park Systems TIFF"
        ) from error


def fill_missing(heights: np.ndarray) -> tuple[np.ndarray, int]:
    """Replace NaN pixels by their nearest valid neighbour; return the map and the count."""
    missing = ~np.isfinite(heights)
    if not missing.any():
        return heights, 0
    _, (rows, cols) = ndimage.distance_transform_edt(missing, return_indices=True)
    return heights[rows, cols], int(missing.sum())


def _pixels(raw: RawHeights, fallback_pixel_m: float | None, path: Path) -> tuple[float, float]:
    """The pixel along x and y: the file's, else the sheet's (square); a file and a sheet
    that disagree are an error naming both."""
    if raw.pixel_x_m is None:
        if fallback_pixel_m is None:
            raise TopographyError(
                f"{path}: no pixel size in the file and none in the sample sheet "
                "(afm_pixel_nm); expected one of them"
            )
        return fallback_pixel_m, fallback_pixel_m
    if fallback_pixel_m is not None and (
        abs(raw.pixel_x_m - fallback_pixel_m) > PIXEL_TOLERANCE * fallback_pixel_m
    ):
        raise TopographyError(
            f"{path}: the file's pixel is {raw.pixel_x_m * 1e9:.6g} nm, the sample sheet's "
            f"afm_pixel_nm {fallback_pixel_m * 1e9:.6g} nm; expected them to agree (correct "
            "the sheet, or leave afm_pixel_nm empty to use the file's)"
        )
    return raw.pixel_x_m, raw.pixel_y_m if raw.pixel_y_m is not None else raw.pixel_x_m


def _check_heights(heights: np.ndarray, path: Path, min_side_px: int) -> None:
    if heights.ndim != 2:
        raise TopographyError(f"{path}: height map of shape {heights.shape}; expected 2-D")
    if min(heights.shape) < min_side_px:
        raise TopographyError(
            f"{path}: height map of {heights.shape[0]} × {heights.shape[1]} px; a sphere fit "
            f"needs at least {min_side_px} × {min_side_px}"
        )
    finite = heights[np.isfinite(heights)]
    if finite.size == 0:
        raise TopographyError(f"{path}: every pixel is NaN; expected heights")
    low, high = PLAUSIBLE_PEAK_TO_VALLEY_M
    span = float(finite.max() - finite.min())
    if not low <= span <= high:
        raise TopographyError(
            f"{path}: heights span {span:.3g} m; expected {low:g} to {high:g} m for an AFM map "
            "(check the height unit of the file, or the channel)"
        )


def read_heights(path: str | Path, channel: str | None = None) -> RawHeights:
    """The heights (m) and pixel sizes a height-map file holds, by its suffix, without the
    policy of :func:`read_height_map` (size, plausible heights, pixel from the sheet, NaN);
    raises TopographyError naming the file when it cannot be read."""
    path = Path(path)
    if not path.is_file():
        raise TopographyError(f"{path}: no such height map")
    suffix = path.suffix.lower()
    if suffix in TIFF_SUFFIXES:
        return _read_tiff_map(path, channel)
    if suffix == ".npy":
        return _read_npy(path)
    if suffix in VENDOR_SUFFIXES:
        return _read_vendor(path, channel)
    raise TopographyError(
        f"{path}: unknown height-map format {suffix!r}; expected one of {', '.join(SUFFIXES)}"
    )


def read_height_map(
    path: str | Path,
    *,
    fallback_pixel_m: float | None = None,
    nan_policy: str = "fail",
    channel: str | None = None,
    min_side_px: int = MIN_SIDE_PX,
) -> HeightMap:
    """Read an AFM height map, heights in m (module docstring: formats and checks).

    ``fallback_pixel_m`` is the sample sheet's pixel (used where the file has none; a file
    that has one must agree with it). ``channel`` names the height channel of a vendor file
    (None: the format's default). ``nan_policy`` is 'fail' (raise, naming the number and
    first position of NaN pixels) or 'fill' (nearest valid neighbour, logged); a map of
    nothing but NaN is refused either way.
    """
    path = Path(path)
    if nan_policy not in ("fail", "fill"):
        raise ValueError(f"nan_policy must be 'fail' or 'fill', got {nan_policy!r}")
    raw = read_heights(path, channel)
    heights = raw.heights
    _check_heights(heights, path, min_side_px)
    pixel_x, pixel_y = _pixels(raw, fallback_pixel_m, path)
    filled = 0
    missing = ~np.isfinite(heights)
    if missing.any():
        first = tuple(int(i) for i in np.argwhere(missing)[0])
        if nan_policy == "fail":
            raise TopographyError(
                f"{path}: {int(missing.sum())} NaN pixels (first at row, column {first}); set "
                "afm_nan_policy: fill to replace them by their nearest valid neighbour"
            )
        heights, filled = fill_missing(heights)
        log.warning("%s: filled %d NaN pixels (first at %s)", path, filled, first)
    return HeightMap(heights, float(pixel_x), path, filled, float(pixel_y), raw.channel)


def write_height_map(path: str | Path, heights_m: np.ndarray, pixel_m: float) -> None:
    """Write a height map (m) as a float32 TIFF with its pixel size in the resolution tags,
    atomically; refuses NaN or infinite heights."""
    heights = np.asarray(heights_m)
    if not np.all(np.isfinite(heights)):
        raise ValueError(f"{path}: refusing to write a height map with NaN or inf")
    write_image(path, heights.astype(np.float32), pixel_m)
