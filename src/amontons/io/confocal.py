"""Confocal images in the microscopes' own formats: one 2-D plane chosen from a file that may
hold several channels, series (scenes) and frames, with the pixel size its metadata give.

Accepted, each tested on files its own writer made (tests/io/test_confocal.py):

- plain TIFF (``.tif``, ``.tiff``): one 2-D image, read exactly as amontons.io.tiff reads it;
- OME-TIFF (``.ome.tif``, ``.ome.tiff``), through tifffile: channel names and
  PhysicalSizeX/Y (with their unit) from the OME-XML;
- ImageJ hyperstack TIFF (``.tif``), through tifffile: the pixel from the resolution tags in
  the ImageJ ``unit``;
- Zeiss CZI (``.czi``), through pylibCZIrw (Zeiss's own libCZI): channel names and the
  Scaling of the XML metadata (m).

Which plane is used is an :class:`ImageChoice` (config ``optics.images``). A file whose
choice cannot be met raises ImageError listing what it holds (channel names, series, frames).
A file that holds a sphere's whole load series (one series or one frame per load) gives each
load's plane through the choice's :class:`LoadPlane`.
The writers (the virtual experiment's) are in amontons.io.confocal_writers.
"""

from __future__ import annotations

import logging
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass
from decimal import Decimal, InvalidOperation
from fractions import Fraction
from pathlib import Path

import numpy as np
import pylibCZIrw.czi as pyczi
import tifffile

from amontons.io.layout import (
    confocal_suffix,
    load_axis_conflict,
    load_count_mismatch,
    same_load,
)
from amontons.io.tiff import Image, ImageError, read_image, resolve_pixel

log = logging.getLogger(__name__)

# Length units of OME-XML and ImageJ metadata, per metre.
_UNITS_PER_M = {
    "m": 1.0,
    "cm": 1e2,
    "mm": 1e3,
    "µm": 1e6,
    "μm": 1e6,
    "um": 1e6,
    "micron": 1e6,
    "microns": 1e6,
    "\\u00B5m": 1e6,
    "nm": 1e9,
}
_OME_DEFAULT_UNIT = "µm"  # OME-XML: PhysicalSizeX without a unit is in µm
IMAGEJ_UNCALIBRATED = ("pixel", "pixels")  # ImageJ's unit of an image without a pixel size
_CZI_PIXEL_TYPES = {"Gray8": np.uint8, "Gray16": np.uint16, "Gray32Float": np.float32}
_FRAMES_MEAN = "mean"


@dataclass(frozen=True)
class LoadPlane:
    """Where one load's image lies in a file that holds the whole load series (config
    ``optics.images.load_series``): along ``axis`` ('series' or 'frames'), the plane of
    ``load_mn``. ``plane_loads_mn`` is the load (mN) of every plane in plane order
    (amontons.io.layout.plane_loads): the file must hold exactly that many along ``axis``."""

    axis: str
    plane_loads_mn: tuple[float, ...]
    load_mn: float

    def __post_init__(self):
        if self.axis not in ("series", "frames"):
            raise ValueError(f"load axis {self.axis!r}; expected 'series' or 'frames'")
        if not any(same_load(load, self.load_mn) for load in self.plane_loads_mn):
            raise ValueError(
                f"{self.load_mn:g} mN is none of the planes' loads {list(self.plane_loads_mn)} mN"
            )

    @property
    def index(self) -> int:
        """The plane index of ``load_mn`` along ``axis``."""
        return next(i for i, f in enumerate(self.plane_loads_mn) if same_load(f, self.load_mn))


@dataclass(frozen=True)
class ImageChoice:
    """Which 2-D plane of a confocal file is the image (config ``optics.images``).

    ``channel``: a channel name or index (None: the file must hold one channel);
    ``series``: the series (CZI scene, OME image) index; ``frames``: 'mean' (the mean of all
    frames, time points and z planes; a single frame is returned as stored) or a frame index;
    ``load``: in a file holding the whole load series, the load's plane, which takes the place
    of ``series`` or ``frames`` (that one must then keep its default: ValueError otherwise).
    """

    channel: str | int | None = None
    series: int = 0
    frames: str | int = _FRAMES_MEAN
    load: LoadPlane | None = None

    def __post_init__(self):
        if self.load is not None:
            conflict = load_axis_conflict(
                self.load.axis, {"series": self.series, "frames": self.frames}
            )
            if conflict is not None:
                raise ValueError(conflict)


# What a 2-D single-channel TIFF needs: nothing chosen.
NO_CHOICE = ImageChoice()


@dataclass(frozen=True)
class Planes:
    """One series of a confocal file: ``data`` (frames, channels, y, x), its channel names,
    how many series the file holds, its pixel (m, None where the metadata give none) and the
    format's name."""

    data: np.ndarray
    channels: tuple[str, ...]
    series_count: int
    pixel_m: float | None
    format: str

    def describe(self) -> str:
        """What the file holds, for error messages."""
        frames, channels = self.data.shape[:2]
        return (
            f"it holds {self.series_count} series, channels {list(self.channels)} and "
            f"{frames} frames of {self.data.shape[2]} x {self.data.shape[3]} px"
        )


def _per_metre(path: Path, unit: str) -> float:
    if unit not in _UNITS_PER_M:
        raise ImageError(
            f"{path}: pixel size unit {unit!r}; expected one of {sorted(_UNITS_PER_M)}"
        )
    return _UNITS_PER_M[unit]


def _decimal_metres(path: Path, text: str, unit: str) -> float:
    """The length ``text`` (decimal digits) in ``unit``, in metres: the double nearest the
    decimal value. float(text) / 1e6 rounds twice (0.2 µm gives 2.0000000000000002e-07 m),
    so the same 200 nm pixel would come out one ulp away from a TIFF tag's 50000 px/cm."""
    try:
        length = Decimal(text.strip())
    except InvalidOperation:
        raise ImageError(f"{path}: pixel size {text!r}; expected a number") from None
    return float(length / Decimal(_per_metre(path, unit)))


def _square_pixel(path: Path, x_m: float | None, y_m: float | None) -> float | None:
    """The pixel (m) of square pixels; ImageError naming the file for rectangular ones."""
    if x_m is not None and y_m is not None and abs(x_m - y_m) > 1e-6 * x_m:
        raise ImageError(
            f"{path}: pixels of {x_m * 1e9:.6g} x {y_m * 1e9:.6g} nm; expected square pixels"
        )
    return x_m


def _to_tcyx(path: Path, data: np.ndarray, axes: str) -> np.ndarray:
    """``data`` with tifffile's ``axes`` as (frames, channels, y, x): every axis other than
    C, Y and X (T, Z, ...) is a frame axis."""
    if "S" in axes:
        raise ImageError(
            f"{path}: axes {axes} hold colour samples (RGB); expected grey-level planes"
        )
    if not {"Y", "X"} <= set(axes):
        raise ImageError(f"{path}: axes {axes}; expected a Y and an X axis")
    if "C" not in axes:
        data, axes = data[..., np.newaxis, :, :], axes[:-2] + "CYX"
    frame_axes = [i for i, a in enumerate(axes) if a not in "CYX"]
    order = [*frame_axes, axes.index("C"), axes.index("Y"), axes.index("X")]
    data = np.transpose(data, order)
    return data.reshape(-1, *data.shape[-3:])


def _ome_pixel_and_channels(
    path: Path, xml: str, series: int
) -> tuple[float | None, tuple[str, ...]]:
    root = ElementTree.fromstring(xml)
    images = [e for e in root if e.tag.endswith("}Image")]
    pixels = next(e for e in images[series] if e.tag.endswith("}Pixels"))
    names = tuple(
        c.get("Name") or str(i)
        for i, c in enumerate(e for e in pixels if e.tag.endswith("}Channel"))
    )
    sizes = []
    for axis in ("X", "Y"):
        value = pixels.get(f"PhysicalSize{axis}")
        unit = pixels.get(f"PhysicalSize{axis}Unit", _OME_DEFAULT_UNIT)
        sizes.append(None if value is None else _decimal_metres(path, value, unit))
    return _square_pixel(path, *sizes), names


def _imagej_pixel(path: Path, tif: tifffile.TiffFile) -> float | None:
    """An ImageJ file's pixel (m): its resolution tags in its ``unit``; None without a unit
    or with ImageJ's uncalibrated one, 'pixel'."""
    unit = (tif.imagej_metadata or {}).get("unit")
    tags = tif.pages[0].tags
    if unit is None or unit in IMAGEJ_UNCALIBRATED or "XResolution" not in tags:
        return None
    sizes = []
    for name in ("XResolution", "YResolution"):
        numerator, denominator = tags[name].value if name in tags else tags["XResolution"].value
        # exact rational arithmetic, rounded once (as _decimal_metres)
        per_m = Fraction(_per_metre(path, unit))
        sizes.append(float(Fraction(denominator, numerator) / per_m) if numerator else None)
    return _square_pixel(path, *sizes)


def _tiff_planes(path: Path, series: int) -> Planes:
    """An OME-TIFF's or ImageJ hyperstack's series ``series``."""
    with tifffile.TiffFile(path) as tif:
        count = len(tif.series)
        if not 0 <= series < count:
            raise _series_error(path, series, count)
        data = tif.series[series].asarray()
        axes = tif.series[series].axes
        if tif.is_ome:
            pixel_m, names = _ome_pixel_and_channels(path, tif.ome_metadata, series)
            kind = "OME-TIFF"
        elif not tif.is_imagej:
            raise ImageError(
                f"{path}: named {confocal_suffix(path)} but holds no OME-XML; expected an "
                "OME-TIFF (or rename a plain TIFF to .tif)"
            )
        else:
            pixel_m, names = _imagej_pixel(path, tif), ()
            kind = "ImageJ hyperstack TIFF"
    planes = _to_tcyx(path, data, axes)
    names = names if len(names) == planes.shape[1] else tuple(map(str, range(planes.shape[1])))
    return Planes(planes, names, count, pixel_m, kind)


def _series_error(path: Path, series: int, count: int) -> ImageError:
    return ImageError(
        f"{path}: series {series} chosen (optics.images.series), but the file holds "
        f"{count} series (0 to {count - 1})"
    )


def _czi_channels(metadata: dict, count: int) -> tuple[str, ...]:
    image = metadata["ImageDocument"]["Metadata"]["Information"]["Image"]
    channels = (image.get("Dimensions") or {}).get("Channels", {}).get("Channel", [])
    channels = channels if isinstance(channels, list) else [channels]
    names = tuple(c.get("@Name") or str(i) for i, c in enumerate(channels))
    return names if len(names) == count else tuple(map(str, range(count)))


def _czi_pixel(path: Path, metadata: dict) -> float | None:
    scaling = metadata["ImageDocument"]["Metadata"].get("Scaling") or {}
    distances = (scaling.get("Items") or {}).get("Distance", [])
    by_axis = {d["@Id"]: float(d.get("Value") or 0.0) for d in distances}
    sizes = [by_axis.get(axis) or None for axis in ("X", "Y")]  # 0: none given
    return _square_pixel(path, *sizes)


def _czi_pixel_type(path: Path, czi: pyczi.CziReader) -> str:
    """The one grey-level pixel type of a CZI's channels ('Invalid': a channel with no plane)."""
    kinds = {kind for kind in czi.pixel_types.values() if kind != "Invalid"}
    if len(kinds) != 1 or not kinds <= set(_CZI_PIXEL_TYPES):
        raise ImageError(
            f"{path}: CZI pixel types {sorted(kinds)}; expected one grey-level type "
            f"({', '.join(_CZI_PIXEL_TYPES)})"
        )
    return kinds.pop()


def _czi_planes(path: Path, series: int) -> Planes:
    """A CZI's scene ``series``: every channel, every T and Z plane (a channel the metadata
    name but no plane was written for reads as 0)."""
    with pyczi.open_czi(str(path)) as czi:
        scenes = czi.scenes_bounding_rectangle
        count = max(len(scenes), 1)
        if not 0 <= series < count:
            raise _series_error(path, series, count)
        box = czi.total_bounding_box
        kind = _czi_pixel_type(path, czi)
        frames = [
            (t, z) for t in range(*box.get("T", (0, 1))) for z in range(*box.get("Z", (0, 1)))
        ]
        scene = series if scenes else None
        stack = np.stack(
            [
                [
                    czi.read(plane={"C": c, "T": t, "Z": z}, scene=scene, pixel_type=kind)[..., 0]
                    for c in range(*box.get("C", (0, 1)))
                ]
                for t, z in frames
            ]
        )
        metadata = czi.metadata
    names = _czi_channels(metadata, stack.shape[1])
    data = stack.astype(_CZI_PIXEL_TYPES[kind], copy=False)
    return Planes(data, names, count, _czi_pixel(path, metadata), "CZI")


def _series_count(path: Path) -> int:
    """How many series (OME images, CZI scenes) the file holds, without reading pixels."""
    if confocal_suffix(path) == ".czi":
        with pyczi.open_czi(str(path)) as czi:
            return max(len(czi.scenes_bounding_rectangle), 1)
    with tifffile.TiffFile(path) as tif:
        return len(tif.series)


def _readable(path: Path, read, *args):
    """``read(path, *args)``, with a file that is missing, unreadable or truncated raised as
    ImageError naming it."""
    if not path.is_file():
        raise ImageError(f"{path}: no such image")
    try:
        return read(path, *args)
    except ImageError:
        raise
    except (
        tifffile.TiffFileError,
        RuntimeError,
        ValueError,
        KeyError,
        OSError,
        EOFError,
        IndexError,
    ) as error:
        raise ImageError(
            f"{path}: not a readable {confocal_suffix(path) or 'image'} file "
            f"({type(error).__name__}: {error}); expected a complete file"
        ) from error


def read_planes(path: str | Path, series: int = 0) -> Planes:
    """Series ``series`` of the OME-TIFF, ImageJ hyperstack or CZI ``path`` as (frames,
    channels, y, x), with its channel names and pixel size (m).

    Raises ImageError naming the file when it is missing, unreadable or truncated, or has no
    such series.
    """
    path = Path(path)
    reader = _czi_planes if confocal_suffix(path) == ".czi" else _tiff_planes
    return _readable(path, reader, series)


def _channel_index(path: Path, planes: Planes, channel: str | int | None) -> int:
    names = list(planes.channels)
    if channel is None:
        if len(names) != 1:
            raise ImageError(
                f"{path}: {len(names)} channels {names} and no optics.images channel chosen; "
                f"expected one channel, or a choice among them ({planes.describe()})"
            )
        return 0
    if isinstance(channel, int) and not isinstance(channel, bool):
        if 0 <= channel < len(names):
            return channel
    elif channel in names:
        return names.index(channel)
    raise ImageError(
        f"{path}: channel {channel!r} chosen (optics.images), but the file has no such channel; "
        f"{planes.describe()}"
    )


def _frames(path: Path, planes: np.ndarray, frames: str | int, described: str) -> np.ndarray:
    """The chosen frame of ``planes`` (frames, y, x), or their mean (a lone frame as stored)."""
    if frames == _FRAMES_MEAN:
        return planes[0] if len(planes) == 1 else planes.mean(axis=0)
    if isinstance(frames, int) and 0 <= frames < len(planes):
        return planes[frames]
    raise ImageError(
        f"{path}: frame {frames!r} chosen (optics.images.frames), but {described}; expected "
        f"'{_FRAMES_MEAN}' or an index from 0 to {len(planes) - 1}"
    )


def select_plane(path: Path, planes: Planes, choice: ImageChoice) -> np.ndarray:
    """The 2-D image ``choice`` picks from ``planes``.

    Raises ImageError naming the file and listing what it holds when the channel or frame is
    not in it, and when the chosen channel holds no image: every pixel of it 0 in every frame,
    which is what a detector channel that recorded nothing, and a plane that was never
    written (the readers fill those with 0), look like. A real confocal image always has
    background counts.
    """
    index = _channel_index(path, planes, choice.channel)
    channel = planes.data[:, index]
    if not np.any(channel):
        raise ImageError(
            f"{path}: channel {planes.channels[index]!r} holds no image (all "
            f"{channel.size} pixels of its {len(channel)} frames are 0); expected detector "
            f"counts ({planes.describe()})"
        )
    return _frames(path, channel, choice.frames, planes.describe())


def is_plain_tiff(path: Path) -> bool:
    """Whether ``path`` is a TIFF that is neither OME-TIFF nor ImageJ hyperstack (read as one
    2-D image by amontons.io.tiff, exactly as before confocal formats were accepted)."""
    if confocal_suffix(path) not in (".tif", ".tiff") or not path.is_file():
        return False
    try:
        with tifffile.TiffFile(path) as tif:
            return not (tif.is_ome or tif.is_imagej)
    except (tifffile.TiffFileError, ValueError, OSError, EOFError, IndexError):
        return True  # amontons.io.tiff names what is wrong with it


def read_confocal(
    path: str | Path, fallback_pixel_m: float | None = None, choice: ImageChoice = NO_CHOICE
) -> Image:
    """The 2-D image ``choice`` picks from the confocal file ``path``, with its pixel size (m)
    and where that came from (the file's metadata, else ``fallback_pixel_m``, the sheet's).

    A plain TIFF is read by amontons.io.tiff.read_image. Raises ImageError naming the file (and
    what it holds) when it cannot be read, the choice cannot be met, the pixels are not
    unsigned integers or floats, or the pixel size is missing or disagrees with the sheet by
    more than 1 % (amontons.io.tiff.resolve_pixel).
    """
    path = Path(path)
    if choice.load is not None:
        planes, choice = _load_planes(path, choice)
    elif is_plain_tiff(path):
        return read_image(path, fallback_pixel_m)
    else:
        planes = read_planes(path, choice.series)
    data = select_plane(path, planes, choice)
    if data.dtype.kind not in ("u", "f") or not np.all(np.isfinite(data)):
        raise ImageError(
            f"{path}: pixel dtype {data.dtype} (or non-finite pixels); expected finite unsigned "
            "integer counts or floating point"
        )
    pixel_m, source = resolve_pixel(
        path, planes.pixel_m, fallback_pixel_m, f"{planes.format} metadata"
    )
    return Image(data=data, pixel_m=pixel_m, path=path, pixel_source=source, format=planes.format)


def _load_count_error(path: Path, load: LoadPlane, described: str) -> ImageError:
    return ImageError(load_count_mismatch(path, described, load.axis, load.plane_loads_mn))


def _load_planes(path: Path, choice: ImageChoice) -> tuple[Planes, ImageChoice]:
    """The planes of a load-series file that hold ``choice.load``'s image, and the choice
    that picks it from them (its frame, where frames carry the loads). The file must hold
    exactly one plane per load along the load axis: ImageError naming it, what it holds and
    the loads otherwise."""
    load = choice.load
    if is_plain_tiff(path):
        raise ImageError(
            f"{path}: a plain TIFF holds one image, but optics.images.load_series reads "
            f"{len(load.plane_loads_mn)} loads from it; expected an OME-TIFF, ImageJ "
            "hyperstack or CZI holding one series or frame per load"
        )
    if load.axis == "series":
        count = _readable(path, _series_count)
        if count != len(load.plane_loads_mn):
            raise _load_count_error(path, load, f"it holds {count} series")
        return read_planes(path, load.index), choice
    planes = read_planes(path, choice.series)
    if len(planes.data) != len(load.plane_loads_mn):
        raise _load_count_error(path, load, planes.describe())
    return planes, ImageChoice(choice.channel, choice.series, load.index)
