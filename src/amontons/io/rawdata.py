"""The raw-data layout a sphere's folder follows, whether real or virtual, and its readers.

<folder>/fluorescence/<load in mN>.tif   one confocal image per load (e.g. 25.tif or 25mN.tif)
<folder>/rheometer/<load in mN>.csv      one friction test per load (amontons.friction layout)
<folder>/reflection.tif                  Newton rings, same field and pixel grid as the
                                         fluorescence image at the sheet's reflection_load_mn
<folder>/bead.tif                        a 100 nm fluorescent bead, imaged like the contacts
<folder>/absorbance.csv                  wavelength_nm, absorbance of the probe cover slip
<folder>/flim.tif                        optional: mean photon arrival time map, ns (float)
<folder>/afm_before.<tif|npy|txt>        AFM height map of the sphere before contact (m)
<folder>/afm_after.<tif|npy|txt>         the same after the load series (m)
<folder>/truth.json                      virtual experiment only; the analysis never reads it

Every reader raises RawDataError naming the file and what was expected.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from amontons.friction import RheometerError, RheometerTrace, read_rheometer_csv
from amontons.images import Image, ImageError, read_image
from amontons.optics.absorbance import AbsorbanceError, read_absorbance_csv

REFLECTION_NAME = "reflection.tif"
BEAD_NAME = "bead.tif"
ABSORBANCE_NAME = "absorbance.csv"
FLIM_NAME = "flim.tif"
AFM_BEFORE_NAME = "afm_before.tif"
AFM_AFTER_NAME = "afm_after.tif"
# Height-map formats amontons.surface reads (TIFF, numpy, Gwyddion text export).
AFM_SUFFIXES = (".tif", ".tiff", ".npy", ".txt", ".asc")
# A rheometer's set-point and its measured normal force differ by its force noise and drift;
# more than this relative difference means the file belongs to another load.
NORMAL_FORCE_TOLERANCE = 0.1


class RawDataError(ValueError):
    """A raw-data folder or file does not match what the sample sheet promises."""


def fluorescence_name(load_mn: float) -> str:
    """File name of the fluorescence image at ``load_mn`` (e.g. 25 → '25.tif')."""
    return f"{load_mn:g}.tif"


def rheometer_name(load_mn: float) -> str:
    """File name of the rheometer record at ``load_mn`` (e.g. 25 → '25.csv')."""
    return f"{load_mn:g}.csv"


def _load_of(path: Path) -> float | None:
    stem = path.stem.removesuffix("mN").removesuffix("mn")
    try:
        return float(stem)
    except ValueError:
        return None


def files_by_load(
    folder: str | Path, loads_mn: list[float], pattern: str, kind: str, example: str
) -> list[Path]:
    """Paths of the files matching ``pattern`` in ``folder``, one per load, in the order of
    ``loads_mn``.

    Files are named by their load in mN (``25.<ext>`` or ``25mN.<ext>``). Raises RawDataError
    naming the folder when a load has no file, a file's load is not in the list, or a file
    name is not a load.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise RawDataError(f"{folder}: no {kind} folder (expected one {example} per load)")
    found = {}
    for path in sorted(folder.glob(pattern)):
        load = _load_of(path)
        if load is None:
            raise RawDataError(f"{path}: file name is not a load in mN (expected e.g. {example})")
        found[load] = path
    missing = [load for load in loads_mn if not any(abs(load - f) < 1e-9 for f in found)]
    extra = [f for f in found if not any(abs(load - f) < 1e-9 for load in loads_mn)]
    if missing or extra:
        noun = "images" if kind == "fluorescence" else f"{kind} files"
        raise RawDataError(
            f"{folder}: the load list {loads_mn} mN does not match the {noun} "
            f"(no {'image' if kind == 'fluorescence' else 'file'} for {missing or 'none'}; "
            f"{noun} not in the list: {extra or 'none'})"
        )
    return [next(found[f] for f in found if abs(load - f) < 1e-9) for load in loads_mn]


def fluorescence_images(folder: str | Path, loads_mn: list[float]) -> list[Path]:
    """Paths of the fluorescence images (``<load>.tif``), in the order of ``loads_mn``."""
    return files_by_load(folder, loads_mn, "*.tif*", "fluorescence", "25.tif")


def fluorescence_image(folder: str | Path, load_mn: float) -> Path:
    """Path of the one fluorescence image at ``load_mn`` (``25.tif`` or ``25mN.tif``)."""
    folder = Path(folder)
    matches = [p for p in sorted(folder.glob("*.tif*")) if _load_of(p) == load_mn]
    if len(matches) != 1:
        raise RawDataError(
            f"{folder}: {len(matches)} images for {load_mn:g} mN; expected exactly one "
            f"(e.g. {fluorescence_name(load_mn)})"
        )
    return matches[0]


def rheometer_files(folder: str | Path, loads_mn: list[float]) -> list[Path]:
    """Paths of the rheometer records (``<load>.csv``), in the order of ``loads_mn``."""
    return files_by_load(folder, loads_mn, "*.csv", "rheometer", "25.csv")


def read_rheometer_traces(folder: str | Path, loads_mn: list[float]) -> list[RheometerTrace]:
    """Every load's rheometer record, in the order of ``loads_mn``.

    Besides the file checks of amontons.friction.read_rheometer_csv (columns, rotation radius,
    numbers), the mean normal force must be within NORMAL_FORCE_TOLERANCE of the file's load:
    a file named 50.csv that recorded 100 mN is refused rather than mismatched.
    """
    traces = []
    for load, path in zip(loads_mn, rheometer_files(folder, loads_mn), strict=True):
        try:
            trace = read_rheometer_csv(path)
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


def _read(path: Path, what: str, fallback_pixel_m: float | None) -> Image:
    if not path.is_file():
        raise RawDataError(f"{path}: no {what} (expected {path.name} in the sphere's folder)")
    try:
        return read_image(path, fallback_pixel_m)
    except ImageError as error:
        raise RawDataError(f"{what}: {error}") from error


def read_bead(path: str | Path, fallback_pixel_m: float | None = None) -> Image:
    """The bead image (``bead.tif``, counts)."""
    return _read(Path(path), "bead image", fallback_pixel_m)


def read_reflection(
    path: str | Path,
    fallback_pixel_m: float | None = None,
    *,
    like: Image | None = None,
) -> Image:
    """The reflection image (``reflection.tif``, counts).

    With ``like`` (the fluorescence image at the reflection load), the reflection must share
    its shape and pixel size: the contact centre and edge found in the fluorescence image are
    used on the reflection image's grid (appendix Fig. B.6 swaps filters, not the field).
    """
    image = _read(Path(path), "reflection image", fallback_pixel_m)
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


def read_absorbance(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Wavelengths (nm) and absorbance from ``absorbance.csv`` (columns wavelength_nm,
    absorbance)."""
    try:
        return read_absorbance_csv(path)
    except AbsorbanceError as error:
        raise RawDataError(str(error)) from error
