"""Whether an image's file (confocal, FLIM map or photons) states its pixel size, and how
large a TIFF AFM scan is, read from the header alone with the standard library: the workflow
asks these when it builds the DAG (amontons.workflow.pixel_sizes, amontons.workflow.load_series,
amontons.workflow.scenes), so that a measured sphere whose images carry no pixel size, and
whose sheet row gives none, stops the run before any job, naming the sphere and the file, and
so that the dry run says which loads a scene will leave outside a small scan.

The readers (amontons.io.confocal, amontons.io.tiff) take the pixel from the same places:

- TIFF: the resolution tags with a centimetre or inch unit, an inch resolution above the
  display defaults (amontons.io.tiff); an ImageJ hyperstack: the tags with the ImageJ ``unit``;
  an OME-TIFF: PhysicalSizeX in the OME-XML;
- CZI: the Scaling of the XML metadata segment (X distance > 0);
- PicoQuant PTU (the FLIM photons, amontons.io.ptu): the header tag ``ImgHdr_PixResol``
  (µm, > 0).

The same headers say how many series and frames a file holding a sphere's whole load series
has (:func:`load_plane_count`), so that one with a plane too many or too few stops the run
before any job too.

tests/io/test_pixel_probe.py holds the probe to the readers on files their writers made
(tests/io/test_load_series.py the plane count).
"""

from __future__ import annotations

import re
import struct
import xml.etree.ElementTree as ElementTree
from pathlib import Path

from amontons.io.layout import RawDataError, confocal_suffix

_WIDTH, _LENGTH, _IMAGE_DESCRIPTION, _X_RESOLUTION, _RESOLUTION_UNIT = 256, 257, 270, 282, 296
_Y_RESOLUTION, _SAMPLE_FORMAT = 283, 339
_IEEE_FLOAT = 3  # SampleFormat of float samples: a height map amontons.io.heightmap reads itself
_CENTIMETRE, _INCH = 3, 2
_METRES_PER_UNIT = {_INCH: 0.0254, _CENTIMETRE: 0.01}
_DISPLAY_DPI_MAX = 1200.0  # amontons.io.tiff: an inch resolution up to this is a display default
_TAGS = (
    _WIDTH,
    _LENGTH,
    _IMAGE_DESCRIPTION,
    _X_RESOLUTION,
    _Y_RESOLUTION,
    _RESOLUTION_UNIT,
    _SAMPLE_FORMAT,
)
# TIFF field types: byte size of one value
_TYPE_SIZES = {1: 1, 2: 1, 3: 2, 4: 4, 5: 8, 6: 1, 7: 1, 8: 2, 9: 4, 10: 8, 11: 4, 12: 8, 16: 8}
_CZI_MAGIC = b"ZISRAWFILE"
_CZI_METADATA = b"ZISRAWMETADATA"
_CZI_METADATA_POSITION = 92  # FileHeader: offset of the metadata segment's position (int64)
_CZI_XML_START = 32 + 256  # metadata segment: header, then sizes and spare, then the XML


def _tiff_tags(path: Path) -> dict[int, object]:
    """The ImageWidth, ImageLength, ImageDescription, X- and YResolution and ResolutionUnit of
    a TIFF's (or BigTIFF's) first page, as int, int, text, (numerator, denominator) twice and
    int."""
    with open(path, "rb") as stream:
        head = stream.read(16)
        order = {b"II": "<", b"MM": ">"}.get(head[:2])
        if order is None:
            raise RawDataError(f"{path}: not a TIFF (no II or MM byte order mark)")
        (version,) = struct.unpack(order + "H", head[2:4])
        big = version == 43
        offset = struct.unpack(order + ("Q" if big else "I"), head[8:16] if big else head[4:8])[0]
        stream.seek(offset)
        count_format, entry_size = (order + "Q", 20) if big else (order + "H", 12)
        (count,) = struct.unpack(count_format, stream.read(struct.calcsize(count_format)))
        entries = stream.read(count * entry_size)
        tags = {}
        for i in range(count):
            entry = entries[i * entry_size : (i + 1) * entry_size]
            code, kind = struct.unpack(order + "HH", entry[:4])
            if code not in _TAGS:
                continue
            n = struct.unpack(order + ("Q" if big else "I"), entry[4:12] if big else entry[4:8])[0]
            inline = entry[12:20] if big else entry[8:12]
            size = n * _TYPE_SIZES.get(kind, 1)
            if size <= len(inline):
                value = inline[:size]
            else:
                stream.seek(struct.unpack(order + ("Q" if big else "I"), inline)[0])
                value = stream.read(size)
            if code == _IMAGE_DESCRIPTION:
                tags[code] = value.rstrip(b"\0").decode("utf-8", "replace")
            elif code in (_X_RESOLUTION, _Y_RESOLUTION):
                tags[code] = struct.unpack(order + "II", value[:8])
            else:  # SHORT (3) or LONG (4); the first value of a per-sample tag
                first = order + ("I" if kind == 4 else "H")
                tags[code] = struct.unpack(first, value[: struct.calcsize(first)])[0]
    return tags


def _tag_pixel_m(tags: dict[int, object], code: int) -> float | None:
    """The pixel (m) a resolution tag states with a physical unit, as amontons.io.tiff reads
    it; None without a unit or at a display default."""
    numerator, denominator = tags.get(code, (0, 0))
    unit = tags.get(_RESOLUTION_UNIT)
    if numerator <= 0 or denominator <= 0 or unit not in _METRES_PER_UNIT:
        return None
    per_unit = numerator / denominator
    if unit == _INCH and per_unit <= _DISPLAY_DPI_MAX:
        return None
    return _METRES_PER_UNIT[unit] / per_unit


def tiff_scan_side_m(path: str | Path, sheet_pixel_m: float | None = None) -> float | None:
    """The shorter side (m) of a TIFF height map's scan: its width and length in pixels times
    the pixel its resolution tags state (amontons.io.tiff's rules), else ``sheet_pixel_m``.
    Only a float TIFF's first page is the map itself (amontons.io.heightmap); a vendor's
    TIFF keeps its heights elsewhere (a Park Systems file's first page is a 256² preview of
    a 512² map), so its size is left to the job's reader. None then, where neither gives a
    pixel, or where the header cannot be read (the job that reads the map names the file)."""
    try:
        tags = _tiff_tags(Path(path))
    except (OSError, struct.error, ValueError, RawDataError):
        return None
    if _WIDTH not in tags or _LENGTH not in tags or tags.get(_SAMPLE_FORMAT) != _IEEE_FLOAT:
        return None
    pixel_x = _tag_pixel_m(tags, _X_RESOLUTION) or sheet_pixel_m
    pixel_y = _tag_pixel_m(tags, _Y_RESOLUTION) or pixel_x
    if pixel_x is None:
        return None
    return min(tags[_WIDTH] * pixel_x, tags[_LENGTH] * pixel_y)


def _tiff_states_pixel(path: Path) -> bool:
    tags = _tiff_tags(path)
    description = str(tags.get(_IMAGE_DESCRIPTION, ""))
    if "<OME" in description:
        return re.search(r'PhysicalSizeX="[0-9.eE+-]*[1-9]', description) is not None
    numerator, denominator = tags.get(_X_RESOLUTION, (0, 0))
    if numerator <= 0 or denominator <= 0:
        return False
    if description.startswith("ImageJ="):
        unit = re.search(r"^unit=(.*)$", description, re.MULTILINE)
        return unit is not None and unit[1].strip() not in ("pixel", "pixels")
    return _tag_pixel_m(tags, _X_RESOLUTION) is not None


def _czi_metadata(path: Path) -> ElementTree.Element:
    """The root of a CZI's XML metadata segment."""
    with open(path, "rb") as stream:
        header = stream.read(_CZI_METADATA_POSITION + 8)
        if not header.startswith(_CZI_MAGIC) or len(header) < _CZI_METADATA_POSITION + 8:
            raise RawDataError(f"{path}: not a CZI (no ZISRAWFILE header)")
        (position,) = struct.unpack("<q", header[_CZI_METADATA_POSITION:])
        stream.seek(position)
        segment = stream.read(_CZI_XML_START)
        if not segment.startswith(_CZI_METADATA) or len(segment) < _CZI_XML_START:
            raise RawDataError(f"{path}: no metadata segment where the CZI header points")
        (xml_size,) = struct.unpack("<i", segment[32:36])
        xml = stream.read(xml_size)
    try:
        return ElementTree.fromstring(xml)
    except ElementTree.ParseError as error:
        raise RawDataError(f"{path}: unreadable CZI metadata ({error})") from error


def _czi_states_pixel(path: Path) -> bool:
    root = _czi_metadata(path)
    for distance in root.iter("Distance"):
        if distance.get("Id") == "X":
            value = distance.findtext("Value") or "0"
            return float(value) > 0
    return False


_PTU_MAGIC = b"PQTTTR\x00\x00"
_PTU_TAG = struct.Struct("<32siIq")  # ident, index, type, value (or the length of what follows)
_PTU_FLOAT8 = 0x20000008
_PTU_FOLLOWED = {0x2001FFFF, 0x4001FFFF, 0x4002FFFF, 0xFFFFFFFF}  # arrays, strings, blobs
_PTU_END = "Header_End"


def _ptu_states_pixel(path: Path) -> bool:
    """Whether the PTU header's ImgHdr_PixResol holds a pixel > 0 (the tags are walked
    to Header_End; no record is read)."""
    with open(path, "rb") as stream:
        if stream.read(16)[:8] != _PTU_MAGIC:
            raise RawDataError(f"{path}: not a PicoQuant PTU file (no PQTTTR header)")
        while True:
            raw = stream.read(_PTU_TAG.size)
            if len(raw) < _PTU_TAG.size:
                raise RawDataError(f"{path}: the PTU header ends before Header_End")
            ident, _, kind, value = _PTU_TAG.unpack(raw)
            name = ident.rstrip(b"\0").decode("ascii", "replace")
            if name == _PTU_END:
                return False
            if name == "ImgHdr_PixResol" and kind == _PTU_FLOAT8:
                return struct.unpack("<d", raw[-8:])[0] > 0
            if kind in _PTU_FOLLOWED:
                stream.seek(value, 1)


def _size(element: ElementTree.Element | None, name: str, get) -> int:
    """A size of ``element`` (1 where it gives none)."""
    value = None if element is None else get(element, name)
    return int(value) if value else 1


def _tiff_plane_count(path: Path, axis: str, series: int) -> int | None:
    """Series (OME images) or frames (T x Z of series ``series``) of an OME-TIFF or ImageJ
    hyperstack, from the first page's ImageDescription; None for a plain TIFF."""
    description = str(_tiff_tags(path).get(_IMAGE_DESCRIPTION, ""))
    if "<OME" in description:
        root = ElementTree.fromstring(description)
        images = [e for e in root if e.tag.endswith("}Image")]
        if axis == "series":
            return len(images)
        if not 0 <= series < len(images):
            return None  # the job names the series the file lacks
        pixels = next((e for e in images[series] if e.tag.endswith("}Pixels")), None)
        return _size(pixels, "SizeT", ElementTree.Element.get) * _size(
            pixels, "SizeZ", ElementTree.Element.get
        )
    if description.startswith("ImageJ="):
        if axis == "series":
            return 1  # a hyperstack is one series
        fields = dict(re.findall(r"^(\w+)=(.*)$", description, re.MULTILINE))
        return int(fields.get("images", 1)) // int(fields.get("channels", 1))
    return None


def _czi_plane_count(path: Path, axis: str) -> int:
    """Scenes (SizeS) or frames (SizeT x SizeZ) of a CZI, from its XML metadata."""
    image = next(_czi_metadata(path).iter("Image"), None)
    if axis == "series":
        return _size(image, "SizeS", ElementTree.Element.findtext)
    find = ElementTree.Element.findtext
    return _size(image, "SizeT", find) * _size(image, "SizeZ", find)


def _header(path: Path, read, *args):
    """``read(path, *args)``, with a header that cannot be read raised as RawDataError naming
    the file."""
    try:
        return read(path, *args)
    except (OSError, struct.error, ValueError, UnicodeDecodeError) as error:
        if isinstance(error, RawDataError):
            raise
        raise RawDataError(f"{path}: unreadable image header ({error})") from error


def states_pixel_size(path: str | Path) -> bool:
    """Whether the image ``path`` (a confocal image, a suffix of
    amontons.io.layout.CONFOCAL_SUFFIXES; a FLIM map ``.tif``; or FLIM photons ``.ptu``)
    states its pixel size in its metadata. Raises RawDataError naming the file when its header
    cannot be read."""
    path = Path(path)
    if path.suffix.lower() == ".ptu":
        read = _ptu_states_pixel
    else:
        read = _czi_states_pixel if confocal_suffix(path) == ".czi" else _tiff_states_pixel
    return _header(path, read)


def load_plane_count(path: str | Path, axis: str, series: int = 0) -> int | None:
    """How many planes a load-series file holds along ``axis`` (amontons.io.layout.LOAD_AXES):
    its series (OME images, CZI scenes), or the frames (time points x z planes) of series
    ``series``, as amontons.io.confocal counts them, read from the header alone; None where
    the header does not say (a plain TIFF: the job's reader names what is wrong). Raises
    RawDataError naming the file when its header cannot be read."""
    path = Path(path)
    if confocal_suffix(path) == ".czi":
        return _header(path, _czi_plane_count, axis)
    return _header(path, _tiff_plane_count, axis, series)
