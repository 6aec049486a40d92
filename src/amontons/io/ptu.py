"""FLIM images as the PicoQuant MicroTime 200 saves them: time-tagged photons in a PTU file.

A T3 image-mode PTU holds one record per photon: its detector channel, the sync pulse it
followed, and its TCSPC bin (the delay after that sync, in ``tcspc_resolution`` steps), with
line and frame markers that place it in a pixel. ptufile decodes the records into a histogram
per pixel; :func:`read_ptu_image` reduces it to what the lifetime measurement needs: per
pixel the photon count and the mean arrival time after the sync, and the decay histogram of
the whole image (from which the measurement finds its time origin,
:mod:`amontons.measure.lifetime`). Frames are summed; detector channels are summed or one is
chosen.

A photon in bin k arrived between k·Δt and (k+1)·Δt after the sync; it counts at the bin's
centre (k + ½)·Δt, which leaves the mean of a decay that is smooth over a bin unbiased.
"""

from __future__ import annotations

import logging
import struct
import uuid
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

import numpy as np
import ptufile

from amontons.io.files import atomic_path

log = logging.getLogger(__name__)

# Decode at most this many histogram values at a time: rows of a large image are decoded in
# chunks of 64 MB (uint32; 128 MB more while their first moment is taken in float64), so a
# 512² image of 4096 bins needs ~200 MB, not the 4 GB of its whole histogram.
_CHUNK_VALUES = 16 * 2**20
# A file and a sheet whose pixels differ by more than this are reported (as for TIFFs).
_PIXEL_AGREEMENT = 0.01
_RECORD_BYTES = 4  # every T3 record is a 32-bit word


class PtuError(ValueError):
    """A PTU file from which no FLIM image can be read."""


@dataclass(frozen=True)
class PhotonImage:
    """A T3 FLIM image reduced to what the lifetime measurement needs.

    ``photons``: photons per pixel (int64, rows × columns); ``mean_after_sync_ns``: mean
    arrival time after the sync pulse per pixel (ns, float64; NaN where a pixel has no photon);
    ``decay``: photons per TCSPC bin summed over the image; ``bin_ns``: the TCSPC bin width;
    ``period_ns``: the sync period; ``pixel_m``: the square pixel (m); ``channel``: the
    detector channel read (None: all summed).
    """

    photons: np.ndarray
    mean_after_sync_ns: np.ndarray
    decay: np.ndarray
    bin_ns: float
    period_ns: float
    pixel_m: float
    channel: int | None
    path: Path


def _open(path: Path) -> ptufile.PtuFile:
    if not path.is_file():
        raise PtuError(f"{path}: no such PTU file")
    try:
        return ptufile.PtuFile(path)
    except (ValueError, OSError, EOFError, LookupError, NameError, struct.error) as error:
        # ptufile meets a header cut short with an UnboundLocalError (a NameError)
        raise PtuError(
            f"{path}: not a readable PicoQuant PTU file ({type(error).__name__}: {error}); "
            "expected a complete .ptu file as the MicroTime 200 saves it"
        ) from error


def _check_image_mode(path: Path, ptu: ptufile.PtuFile) -> None:
    mode = ptu.tags.get("Measurement_Mode")
    if mode != ptufile.PtuMeasurementMode.T3:
        name = ptufile.PtuMeasurementMode(mode).name if mode in (2, 3) else repr(mode)
        raise PtuError(
            f"{path}: measurement mode {name} (time tags without TCSPC bins per pixel); "
            "expected a T3 image-mode FLIM measurement"
        )
    if not ptu.is_image:
        submode = ptu.tags.get("Measurement_SubMode")
        raise PtuError(
            f"{path}: T3 measurement sub-mode {submode} (a point or line measurement, not an "
            "image); expected a T3 image-mode FLIM measurement"
        )


def _check_complete(path: Path, ptu: ptufile.PtuFile) -> None:
    """The records the header promises must all be in the file (a copy cut short reads as an
    image with its last lines missing)."""
    promised = int(ptu.tags.get("TTResult_NumberOfRecords", 0))
    stored = (path.stat().st_size - ptu.record_offset) // _RECORD_BYTES
    if promised > 0 and stored < promised:
        raise PtuError(
            f"{path}: truncated: {stored} of the {promised} photon records the header "
            "announces; expected the complete file"
        )


def _header_pixel_m(ptu: ptufile.PtuFile) -> float | None:
    """The pixel (m) the header's ImgHdr_PixResol (µm) states; None where it states none."""
    file_um = ptu.tags.get("ImgHdr_PixResol")
    return float(file_um) / 1e6 if file_um and float(file_um) > 0 else None


def _pixel_m(path: Path, ptu: ptufile.PtuFile, fallback_pixel_m: float | None) -> float:
    file_m = _header_pixel_m(ptu)
    if file_m is None and fallback_pixel_m is None:
        raise PtuError(f"{path}: no pixel size in the PTU header (ImgHdr_PixResol) nor the sheet")
    if file_m is None:
        log.info(
            "%s: no pixel size in the PTU header; the sheet's %.4g nm", path, fallback_pixel_m * 1e9
        )
        return float(fallback_pixel_m)
    if fallback_pixel_m is not None and abs(file_m - fallback_pixel_m) > (
        _PIXEL_AGREEMENT * fallback_pixel_m
    ):
        log.warning(
            "%s: PTU pixel %.4g nm differs from the sheet's %.4g nm; using the PTU's (the FLIM "
            "microscope is not the confocal one)",
            path,
            file_m * 1e9,
            fallback_pixel_m * 1e9,
        )
    return file_m


def _channel_selector(path: Path, ptu: ptufile.PtuFile, channel: int | None) -> int:
    """ptufile's channel argument: -1 sums the channels; an index must be a recording one."""
    active = list(ptu.active_channels)
    if channel is None:
        return -1
    if channel not in active:
        raise PtuError(
            f"{path}: detector channel {channel} recorded no photon; the file's channels with "
            f"photons are {active}"
        )
    return active.index(channel)


def _decode(
    path: Path, ptu: ptufile.PtuFile, channel: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Photons and first moment (bin-centre units) per pixel, and the image's decay."""
    rows, cols, bins = ptu.sizes["Y"], ptu.sizes["X"], ptu.sizes["H"]
    centres = np.arange(bins) + 0.5
    photons = np.zeros((rows, cols), np.int64)
    moment = np.zeros((rows, cols))
    decay = np.zeros(bins, np.int64)
    step = max(1, _CHUNK_VALUES // max(1, cols * bins))
    for start in range(0, rows, step):
        selection = (slice(None), slice(start, min(start + step, rows)), Ellipsis)
        try:
            histogram = ptu.decode_image(
                selection, dtype=np.uint32, frame=-1, channel=channel, keepdims=False
            )
        except (ValueError, NotImplementedError, IndexError) as error:
            raise PtuError(
                f"{path}: the T3 records do not decode into an image ({type(error).__name__}: "
                f"{error}); expected a unidirectional line scan"
            ) from error
        histogram = histogram.reshape(-1, cols, bins)
        photons[start : start + step] = histogram.sum(axis=-1, dtype=np.int64)
        moment[start : start + step] = histogram @ centres
        decay += histogram.sum(axis=(0, 1), dtype=np.int64)
    return photons, moment, decay


@dataclass(frozen=True)
class PtuHeader:
    """What a T3 image-mode PTU's header says of its image: ``shape`` (rows, columns) and
    ``pixel_m`` (m; None where ``ImgHdr_PixResol`` gives none)."""

    shape: tuple[int, int]
    pixel_m: float | None


def read_ptu_header(path: str | Path) -> PtuHeader:
    """The image size and pixel of the T3 image-mode PTU ``path``, from its header alone (no
    photon is decoded: the data check reads this). Raises PtuError naming the file for a
    file that is missing, not a PTU, cut short or not a T3 image."""
    path = Path(path)
    with _open(path) as ptu:
        _check_image_mode(path, ptu)
        _check_complete(path, ptu)
        shape = tuple(int(n) for n in ptu.shape[1:3])
        return PtuHeader(shape=shape, pixel_m=_header_pixel_m(ptu))


def read_ptu_image(
    path: str | Path, fallback_pixel_m: float | None = None, *, channel: int | None = None
) -> PhotonImage:
    """The FLIM image of the T3 image-mode PTU ``path``: per pixel the photon count and the
    mean arrival time after the sync (ns), and the image's decay histogram.

    ``channel``: the detector channel to read (None: all channels summed). The pixel comes from
    the header (``ImgHdr_PixResol``), else ``fallback_pixel_m``. Raises PtuError naming the
    file for a file that is missing, not a PTU, cut short, in T2 mode or a T3 point or line
    measurement, a channel that recorded no photon (listing the ones that did), a scan
    ptufile cannot decode (bidirectional, sinusoidal), an image without any photon, or no
    pixel size.
    """
    path = Path(path)
    with _open(path) as ptu:
        _check_image_mode(path, ptu)
        _check_complete(path, ptu)
        pixel_m = _pixel_m(path, ptu, fallback_pixel_m)
        selector = _channel_selector(path, ptu, channel)
        bin_ns = float(ptu.tcspc_resolution) * 1e9
        period_ns = float(ptu.global_resolution) * 1e9
        photons, moment, decay = _decode(path, ptu, selector)
    if photons.sum() == 0:
        raise PtuError(f"{path}: the image holds no photon; expected a FLIM image")
    with np.errstate(invalid="ignore", divide="ignore"):
        mean_ns = np.where(photons > 0, moment / photons, np.nan) * bin_ns
    return PhotonImage(
        photons=photons,
        mean_after_sync_ns=mean_ns,
        decay=decay,
        bin_ns=bin_ns,
        period_ns=period_ns,
        pixel_m=pixel_m,
        channel=channel,
        path=path,
    )


def write_ptu_image(
    path: str | Path,
    histograms: np.ndarray,
    *,
    bin_s: float,
    sync_period_s: float,
    pixel_m: float,
    comment: str = "",
    guid: uuid.UUID | None = None,
    created: datetime | None = None,
) -> None:
    """Write TCSPC histograms (rows × columns × bins, unsigned integers) as a T3 image-mode
    PTU with ptufile's writer, atomically: ``bin_s`` the TCSPC bin, ``sync_period_s`` the laser
    period, ``pixel_m`` the pixel (written in µm, ``ImgHdr_PixResol``). ``guid`` and
    ``created`` (naive local time) go into the header; ptufile's defaults, a random GUID and
    the time of writing, make every file's bytes differ, so a writer that must be
    reproducible gives both."""
    data = np.asarray(histograms)
    if data.ndim != 3 or data.dtype.kind != "u":
        raise ValueError(
            f"histograms of shape {data.shape} and dtype {data.dtype}; expected rows × columns "
            "× bins of unsigned integers"
        )
    with atomic_path(path) as tmp:
        ptufile.imwrite(
            tmp,
            data,
            global_resolution=sync_period_s,
            tcspc_resolution=bin_s,
            pixel_resolution=pixel_m * 1e6,
            comment=comment,
            guid=guid,
            datetime=created,
        )
