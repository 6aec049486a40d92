"""Writing 2-D images in the confocal formats amontons.io.confocal reads, with the pixel size
in each format's metadata: the virtual experiment's microscope (config
``virtual_experiment.formats.images``). Writes are atomic: a file is complete or absent.
"""

from __future__ import annotations

import uuid
import zlib
from pathlib import Path

import numpy as np
import pylibCZIrw.czi as pyczi
import tifffile

from amontons.io.files import atomic_path
from amontons.io.tiff import write_image


def write_ome_tiff(path: str | Path, data: np.ndarray, pixel_m: float) -> None:
    """Write a 2-D image as a one-channel OME-TIFF with its pixel size (PhysicalSizeX/Y in
    µm)."""
    pixel_um = pixel_m * 1e6
    # The OME-XML's UUID follows from the pixels, so the same image gives the same bytes.
    checksum = zlib.crc32(np.ascontiguousarray(data).tobytes())
    metadata = {
        "UUID": f"urn:uuid:{uuid.uuid5(uuid.NAMESPACE_OID, f'amontons.{checksum}')}",
        "axes": "YX",
        "PhysicalSizeX": pixel_um,
        "PhysicalSizeXUnit": "µm",
        "PhysicalSizeY": pixel_um,
        "PhysicalSizeYUnit": "µm",
    }
    with atomic_path(path) as tmp:
        tifffile.imwrite(tmp, data, ome=True, photometric="minisblack", metadata=metadata)


def write_czi(
    path: str | Path, data: np.ndarray, pixel_m: float, channel: str = "fluorescence"
) -> None:
    """Write a 2-D image (uint8, uint16 or float32) as a one-channel CZI with its pixel size
    (Scaling, m) through pylibCZIrw. libCZI gives every file new GUIDs: the same image gives
    the same pixels and metadata, not the same bytes."""
    with atomic_path(path) as tmp, pyczi.create_czi(str(tmp), exist_ok=True) as czi:
        czi.write(np.ascontiguousarray(data)[..., np.newaxis], plane={"C": 0, "T": 0, "Z": 0})
        czi.write_metadata(channel_names={0: channel}, scale_x=pixel_m, scale_y=pixel_m)


def write_confocal(path: str | Path, data: np.ndarray, pixel_m: float, image_format: str) -> None:
    """Write a 2-D image in ``image_format`` (a key of IMAGE_FORMATS; the file's suffix must
    be that format's), with its pixel size (m) in the format's metadata."""
    writers = {"tif": write_image, "ome_tiff": write_ome_tiff, "czi": write_czi}
    if image_format not in writers:
        raise ValueError(f"image format {image_format!r}; expected one of {sorted(writers)}")
    writers[image_format](path, data, pixel_m)
