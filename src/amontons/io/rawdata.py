"""A sphere's raw files read with the checks the raw-data layout promises
(:mod:`amontons.io.layout`): every reader takes the exact path it is given and raises
RawDataError naming the file and what was expected.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from amontons.io.absorbance import AbsorbanceError, read_absorbance_csv
from amontons.io.confocal import NO_CHOICE, ImageChoice, LoadPlane, read_confocal
from amontons.io.export_map import ExportMap
from amontons.io.layout import RawDataError, fluorescence_names, per_load_files, same_load
from amontons.io.ptu import PhotonImage, PtuError, read_ptu_image
from amontons.io.rheometer import RheometerError, RheometerTrace
from amontons.io.rheometer_files import read_rheometer_file
from amontons.io.tiff import Image, ImageError, read_image

# A rheometer's set-point and its measured normal force differ by its force noise and drift;
# more than this relative difference means the file belongs to another load.
NORMAL_FORCE_TOLERANCE = 0.1


def read_rheometer_traces(
    paths: Sequence[str | Path],
    loads_mn: Sequence[float],
    maps: Mapping[str, ExportMap] | None = None,
) -> list[RheometerTrace]:
    """Every load's rheometer record (``paths``, one per load, in the order of ``loads_mn``),
    each read by what it is: our own CSV, or a program's export through the first of ``maps``
    (name → column map) whose columns it names (amontons.io.rheometer_files).

    Besides the file checks of amontons.io.rheometer.read_rheometer_csv (columns, rotation radius,
    numbers) or amontons.io.rheometer_export.read_rheometer_export (mapped columns, units), the
    mean normal force must be within NORMAL_FORCE_TOLERANCE of the file's load: a file named
    50.csv that recorded 100 mN is refused rather than mismatched.
    """
    traces = []
    for load, path in zip(loads_mn, paths, strict=True):
        try:
            _, trace = read_rheometer_file(path, maps or {})
        except RheometerError as error:
            raise RawDataError(str(error)) from error
        measured_mn = float(np.mean(trace.normal_force_n)) * 1e3
        if abs(measured_mn - load) > NORMAL_FORCE_TOLERANCE * load:
            raise RawDataError(
                f"{path}: mean normal force {measured_mn:.4g} mN, but the file name and the "
                f"sheet say {load:g} mN (expected within {NORMAL_FORCE_TOLERANCE:.0%})"
            )
        traces.append(trace)
    return traces


def _read(
    path: Path, what: str, fallback_pixel_m: float | None, choice: ImageChoice | None = None
) -> Image:
    """``path`` read as a 2-D TIFF (``choice`` None) or as a confocal file's chosen plane."""
    if not path.is_file():
        raise RawDataError(f"{path}: no {what} (expected {path.name} in the sphere's folder)")
    try:
        if choice is None:
            return read_image(path, fallback_pixel_m)
        return read_confocal(path, fallback_pixel_m, choice)
    except ImageError as error:
        raise RawDataError(f"{what}: {error}") from error


def read_fluorescence(
    path: str | Path, fallback_pixel_m: float | None = None, choice: ImageChoice = NO_CHOICE
) -> Image:
    """One fluorescence image (``<load>.tif``, ``.ome.tif`` or ``.czi``; counts): the plane
    ``choice`` picks (amontons.io.confocal)."""
    return _read(Path(path), "fluorescence image", fallback_pixel_m, choice)


def read_bead(
    path: str | Path, fallback_pixel_m: float | None = None, choice: ImageChoice = NO_CHOICE
) -> Image:
    """The bead image (``bead.tif``, ``.ome.tif`` or ``.czi``; counts): the plane ``choice``
    picks."""
    return _read(Path(path), "bead image", fallback_pixel_m, choice)


def read_reflection(
    path: str | Path,
    fallback_pixel_m: float | None = None,
    *,
    like: Image | None = None,
    choice: ImageChoice = NO_CHOICE,
) -> Image:
    """The reflection image (``reflection.tif``, ``.ome.tif`` or ``.czi``; counts): the plane
    ``choice`` picks (its channel may differ from the fluorescence's in the same file).

    With ``like`` (the fluorescence image at the reflection load), the reflection must share
    its shape and pixel size: the contact centre and edge found in the fluorescence image are
    used on the reflection image's grid (appendix Fig. B.6 swaps filters, not the field).
    """
    image = _read(Path(path), "reflection image", fallback_pixel_m, choice)
    if like is not None:
        same_pixel = abs(image.pixel_m - like.pixel_m) <= 1e-6 * like.pixel_m
        if image.data.shape != like.data.shape or not same_pixel:
            raise RawDataError(
                f"{image.path}: {image.data.shape} px of {image.pixel_m * 1e9:.4g} nm; expected "
                f"the field of {like.path} ({like.data.shape} px of {like.pixel_m * 1e9:.4g} nm),"
                " because the contact edge is taken from that fluorescence image"
            )
    return image


def read_flim(path: str | Path, fallback_pixel_m: float | None = None) -> Image:
    """The mean photon arrival time map (``flim.tif``, ns, floating point, all > 0)."""
    image = _read(Path(path), "arrival-time map", fallback_pixel_m)
    if image.data.dtype.kind != "f":
        raise RawDataError(
            f"{image.path}: pixel dtype {image.data.dtype}; expected floating-point mean photon "
            "arrival times in ns"
        )
    if np.any(image.data <= 0):
        raise RawDataError(
            f"{image.path}: {int(np.count_nonzero(image.data <= 0))} pixels ≤ 0 ns; expected "
            "positive arrival times in ns"
        )
    return image


def read_flim_photons(
    path: str | Path, fallback_pixel_m: float | None = None, *, channel: int | None = None
) -> PhotonImage:
    """The time-tagged photons of ``flim.ptu`` (T3 image mode) per pixel: photon counts, mean
    arrival time after the sync and the image's decay (amontons.io.ptu.read_ptu_image);
    ``channel`` the detector channel (None: all summed)."""
    try:
        return read_ptu_image(path, fallback_pixel_m, channel=channel)
    except PtuError as error:
        raise RawDataError(f"FLIM photons: {error}") from error


def read_absorbance(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Wavelengths (nm) and absorbance from ``absorbance.csv`` (columns wavelength_nm,
    absorbance)."""
    try:
        return read_absorbance_csv(path)
    except AbsorbanceError as error:
        raise RawDataError(str(error)) from error


def fluorescence_planes(
    given: str | Path | Sequence[str | Path], loads_mn: Sequence[float], images: dict
) -> tuple[list[Path], list[ImageChoice]]:
    """Where each load's fluorescence image is, in the order of ``loads_mn`` (mN): the file
    and the plane of it.

    ``images`` is a rule's ``images`` param
    (amontons.workflow.load_series.LoadSeries.fluorescence_choice): the keyword arguments of
    ImageChoice, and for a sphere whose one file holds every load, ``load_series`` ({axis,
    plane_loads_mn}: the load axis and the load of each plane). Then ``given`` is that one
    file and each load gets its plane; else ``given`` is one file per load, or the virtual
    experiment's folder (amontons.io.layout.per_load_files). Raises RawDataError naming the
    file for a load that is none of its planes'.
    """
    images = dict(images)
    series = images.pop("load_series", None)
    if series is None:
        paths = per_load_files(given, loads_mn, fluorescence_names)
        return paths, [ImageChoice(**images)] * len(paths)
    # the one file, for every load (per_load_files checks that it is one file and there)
    (path,) = per_load_files(given, [series["plane_loads_mn"][0]], fluorescence_names)
    plane_loads = tuple(series["plane_loads_mn"])
    missing = [load for load in loads_mn if not any(same_load(load, f) for f in plane_loads)]
    if missing:
        raise RawDataError(
            f"{path}: no plane for {missing} mN; expected one of its planes' loads "
            f"{list(plane_loads)} mN"
        )
    choices = [
        ImageChoice(**images, load=LoadPlane(series["axis"], plane_loads, load))
        for load in loads_mn
    ]
    return [path] * len(loads_mn), choices


def read_fluorescence_loads(
    given: str | Path | Sequence[str | Path],
    loads_mn: Sequence[float],
    fallback_pixel_m: float | None,
    images: dict,
) -> list[Image]:
    """Each load's fluorescence image, in the order of ``loads_mn`` (mN), wherever
    :func:`fluorescence_planes` finds it (``given``, ``images``: a rule's input and param), read
    as :func:`read_fluorescence_series` reads them (``fallback_pixel_m``: the sheet's, m)."""
    paths, choices = fluorescence_planes(given, loads_mn, images)
    return read_fluorescence_series(paths, fallback_pixel_m, choices)


def read_fluorescence_series(
    paths: Sequence[str | Path],
    fallback_pixel_m: float | None,
    choice: ImageChoice | Sequence[ImageChoice] = NO_CHOICE,
) -> list[Image]:
    """A sphere's fluorescence images (``paths``, one per load; the plane ``choice`` picks of
    each, or the plane of each load's own choice, :func:`fluorescence_planes`); raises
    RawDataError if their pixel sizes differ (areas and pressures of one series share one
    pixel)."""
    choices = [choice] * len(paths) if isinstance(choice, ImageChoice) else list(choice)
    images = []
    for path, plane in zip(paths, choices, strict=True):
        image = read_fluorescence(path, fallback_pixel_m, plane)
        if images and abs(image.pixel_m - images[0].pixel_m) > 1e-6 * images[0].pixel_m:
            raise RawDataError(
                f"{path}: pixel {image.pixel_m * 1e9:.4g} nm differs from "
                f"{images[0].path}'s {images[0].pixel_m * 1e9:.4g} nm; expected one pixel size "
                "per sphere"
            )
        images.append(image)
    return images
