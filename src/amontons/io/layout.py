"""The raw-data layout a sphere's folder follows, whether real or virtual, and its file names.

<folder>/fluorescence/<load in mN>.tif   one confocal image per load (e.g. 25.tif or 25mN.tif),
                                         or .ome.tif or .czi (CONFOCAL_SUFFIXES)
<folder>/fluorescence.ome.tif            or instead one file holding every load (.ome.tif,
                                         ImageJ .tif or .czi): one series or one frame per
                                         load, mapped to the sheet's loads by the config
                                         (optics.images.load_series; :func:`plane_loads`)
<folder>/rheometer/<load in mN>.csv      one friction test per load: our CSV
                                         (amontons.io.rheometer) or the program's export,
                                         .csv or .txt (amontons.io.rheometer_export)
<folder>/reflection.tif (or .ome.tif, .czi) Newton rings, same field and pixel grid as the
                                         fluorescence image at the sheet's reflection_load_mn
<folder>/bead.tif (or .ome.tif, .czi)     a 100 nm fluorescent bead, imaged like the contacts
<folder>/absorbance.csv                  wavelength_nm, absorbance of the probe cover slip
<folder>/flim.tif                        optional: mean photon arrival time map, ns (float),
<folder>/flim.ptu                          or the time-tagged photons (PicoQuant PTU, T3 image)
<folder>/afm_before.<tif|npy|txt>        AFM height map of the sphere before contact (m)
<folder>/afm_after.<tif|npy|txt>         the same after the load series (m)
<folder>/truth.json                      virtual experiment only; the analysis never reads it

Standard library only: the workflow matches a measured sphere's files to its loads here
when it builds the DAG, so the scripts are handed exact paths and never look into a folder.
Every lookup raises RawDataError naming the folder and what was expected.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

REFLECTION_STEM, BEAD_STEM = "reflection", "bead"
REFLECTION_NAME = f"{REFLECTION_STEM}.tif"
BEAD_NAME = f"{BEAD_STEM}.tif"
# The confocal image formats amontons.io.confocal reads, each tested on files its writer made:
# OME-TIFF, plain or ImageJ hyperstack TIFF, Zeiss CZI (docs/own-data.md says why no others).
CONFOCAL_SUFFIXES = (".ome.tif", ".ome.tiff", ".tif", ".tiff", ".czi")
# The formats the virtual experiment writes its images in (virtual_experiment.formats.images,
# amontons.io.confocal_writers) and the suffix of each.
IMAGE_FORMATS = {"tif": ".tif", "ome_tiff": ".ome.tif", "czi": ".czi"}
ABSORBANCE_NAME = "absorbance.csv"
FLIM_NAME = "flim.tif"
FLIM_PTU_NAME = "flim.ptu"
FLIM_NAMES = (FLIM_NAME, FLIM_PTU_NAME)
AFM_BEFORE_NAME = "afm_before.tif"
AFM_AFTER_NAME = "afm_after.tif"
FLUORESCENCE_DIR = "fluorescence"
# The one file that holds a sphere's whole load series, in place of FLUORESCENCE_DIR:
# <folder>/fluorescence.<one of CONFOCAL_SUFFIXES> (config/README.md, "A load series in one
# file").
LOAD_SERIES_STEM = "fluorescence"
# The axes of a confocal file that may carry the loads (config optics.images.load_series.axis),
# and the plane order that follows the sheet's load order (load_series.planes).
LOAD_AXES = ("series", "frames")
IN_LOAD_ORDER = "in_load_order"
# The choice of optics.images that each load axis takes over, and that choice's default
# (amontons.io.confocal.ImageChoice): it cannot also pick a plane along the same axis.
LOAD_AXIS_CHOICE = {"series": ("series", 0), "frames": ("frames", "mean")}
# One plane along each load axis, by name (messages, python -m amontons.check).
PLANE_NOUN = {"series": "series", "frames": "frame"}
RHEOMETER_DIR = "rheometer"
# Our own CSV, and the suffixes rheometer programs give their text exports.
RHEOMETER_SUFFIXES = (".csv", ".txt")
# Height-map formats amontons.io.heightmap reads: float TIFF, numpy, and the vendor formats
# SurfaceTopography reads (its readers detect the format from the content).
AFM_TIFF_SUFFIXES = (".tif", ".tiff")
AFM_VENDOR_SUFFIXES = (
    ".spm", ".001", ".002", ".003", ".004", ".005", ".di", ".ibw", ".nid", ".ezd", ".mi",
    ".top", ".stp", ".tom", ".cur", ".sur", ".mnt", ".x3p", ".sdf", ".dat", ".datx", ".gwy",
    ".mdt", ".jpk", ".opd", ".opdx", ".vk3", ".vk4", ".vk6", ".vk7", ".plu", ".plux", ".frt",
    ".lext", ".al3d", ".zon", ".nc", ".txt", ".asc",
)  # fmt: skip
AFM_SUFFIXES = (*AFM_TIFF_SUFFIXES, ".npy", *AFM_VENDOR_SUFFIXES)
# Loads in file names and in the sheet are the same number when they agree to this (mN).
LOAD_MATCH_MN = 1e-9


class RawDataError(ValueError):
    """A raw-data folder or file does not match what the sample sheet promises."""


def confocal_suffix(path: str | Path) -> str | None:
    """The suffix of CONFOCAL_SUFFIXES that ``path``'s name ends in ('.ome.tif' before '.tif'),
    or None."""
    name = Path(path).name.lower()
    return next((s for s in CONFOCAL_SUFFIXES if name.endswith(s)), None)


def fluorescence_name(load_mn: float, suffix: str = ".tif") -> str:
    """File name of the fluorescence image at ``load_mn`` (e.g. 25 → '25.tif')."""
    return f"{load_mn:g}{suffix}"


def fluorescence_names(load_mn: float) -> tuple[str, ...]:
    """The names the fluorescence image at ``load_mn`` may have, one per accepted suffix
    (25 → '25.ome.tif', ..., '25.czi'); :func:`per_load_files` takes the one present."""
    return tuple(fluorescence_name(load_mn, suffix) for suffix in CONFOCAL_SUFFIXES)


def rheometer_name(load_mn: float, suffix: str = ".csv") -> str:
    """File name of the rheometer record at ``load_mn`` (e.g. 25 → '25.csv'; an export may
    end in another of RHEOMETER_SUFFIXES)."""
    if suffix not in RHEOMETER_SUFFIXES:
        raise RawDataError(
            f"rheometer file suffix '{suffix}'; expected one of {list(RHEOMETER_SUFFIXES)}"
        )
    return f"{load_mn:g}{suffix}"


def same_load(a_mn: float, b_mn: float) -> bool:
    """Whether two loads (mN) are the same load."""
    return abs(a_mn - b_mn) < LOAD_MATCH_MN


def load_of(path: Path) -> float | None:
    """The load in mN a per-load file is named by (``25.tif``, ``25mN.csv``), or None."""
    suffix = confocal_suffix(path)
    stem = path.name[: -len(suffix)] if suffix else path.stem
    stem = stem.removesuffix("mN").removesuffix("mn")
    try:
        return float(stem)
    except ValueError:
        return None


def folder_files(folder: str | Path) -> list[str]:
    """Every file below a sphere's raw-data folder, sorted (none where it is not there): what
    the stamp of its data covers (amontons.workflow.data_stamp)."""
    return sorted(os.path.join(root, name) for root, _, names in os.walk(folder) for name in names)


def files_by_load(
    folder: str | Path,
    loads_mn: Sequence[float],
    pattern: str | Sequence[str],
    kind: str,
    example: str,
) -> list[Path]:
    """Paths of the files matching ``pattern`` (one glob, or several) in ``folder``, one per
    load, in the order of ``loads_mn``.

    Files are named by their load in mN (``25.<ext>`` or ``25mN.<ext>``). Raises RawDataError
    naming the folder when a load has no file or two, a file's load is not in the list, or a
    file name is not a load.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise RawDataError(f"{folder}: no {kind} folder (expected one {example} per load)")
    patterns = [pattern] if isinstance(pattern, str) else list(pattern)
    found = {}
    for path in sorted({p for glob in patterns for p in folder.glob(glob)}):
        load = load_of(path)
        if load is None:
            raise RawDataError(f"{path}: file name is not a load in mN (expected e.g. {example})")
        twin = next((found[f] for f in found if same_load(f, load)), None)
        if twin is not None:
            raise RawDataError(
                f"{folder}: two {kind} files for {load:g} mN ({twin.name}, {path.name}); "
                "expected one per load"
            )
        found[load] = path
    missing = [load for load in loads_mn if not any(same_load(load, f) for f in found)]
    extra = [f for f in found if not any(same_load(load, f) for load in loads_mn)]
    if missing or extra:
        noun = "images" if kind == "fluorescence" else f"{kind} files"
        raise RawDataError(
            f"{folder}: the load list {list(loads_mn)} mN does not match the {noun} "
            f"(no {'image' if kind == 'fluorescence' else 'file'} for {missing or 'none'}; "
            f"{noun} not in the list: {extra or 'none'})"
        )
    return [next(found[f] for f in found if same_load(load, f)) for load in loads_mn]


def fluorescence_images(folder: str | Path, loads_mn: Sequence[float]) -> list[Path]:
    """Paths of the fluorescence images (``<load>`` and one of CONFOCAL_SUFFIXES), in the order
    of ``loads_mn``."""
    patterns = [f"*{suffix}" for suffix in CONFOCAL_SUFFIXES]
    return files_by_load(folder, loads_mn, patterns, "fluorescence", "25.tif")


def confocal_file(folder: str | Path, stem: str) -> Path | None:
    """The image ``stem`` (reflection, bead) in ``folder`` with any of CONFOCAL_SUFFIXES, None
    if there is none; RawDataError naming the folder and the files if there are several."""
    folder = Path(folder)
    found = [folder / f"{stem}{s}" for s in CONFOCAL_SUFFIXES if (folder / f"{stem}{s}").is_file()]
    if len(found) > 1:
        raise RawDataError(
            f"{folder}: {', '.join(p.name for p in found)}; expected one {stem} image"
        )
    return found[0] if found else None


def load_axis_conflict(axis: str, choice: dict) -> str | None:
    """Why the image choice ``choice`` (keys series, frames of optics.images) conflicts with
    loads carried along ``axis``, or None: the series (frames) of a load-series file are its
    loads, one each, so optics.images.series (frames) cannot pick among them too."""
    key, default = LOAD_AXIS_CHOICE[axis]
    if choice[key] == default:
        return None
    return (
        f"optics.images.{key} is {choice[key]!r}, but optics.images.load_series.axis is "
        f"'{axis}': the {axis} of the load-series file are its loads, one {PLANE_NOUN[axis]} each; "
        f"expected {key} {default!r} (it then applies to the per-load, reflection and bead "
        f"images only), or the loads along the other axis"
    )


def load_count_mismatch(path: str | Path, described: str, axis: str, plane_loads_mn) -> str:
    """The message for a load-series file ``path`` whose planes along ``axis`` are not one per
    load: ``described`` says what it holds (e.g. 'it holds 4 series')."""
    loads = len(plane_loads_mn)
    return (
        f"{path}: {described}, but optics.images.load_series puts the sheet's {loads} loads "
        f"{list(plane_loads_mn)} mN along its {axis}, one each; expected exactly {loads} {axis}"
    )


def plane_loads(loads_mn: Sequence[float], planes: str | Sequence[int], where: str) -> list[float]:
    """The load (mN) of each plane of a load-series file, in plane order, from the sheet's
    ``loads_mn`` and the config's ``planes`` (IN_LOAD_ORDER: plane i is the i-th load; or a
    list giving each load's plane index, in the sheet's load order).

    Every plane must be a load and every load a plane: a list must give as many distinct
    indices as there are loads, from 0 to one less (a plane left over may as well be a load
    the sheet left out). Raises RawDataError naming ``where`` (the sphere) otherwise.
    """
    if planes == IN_LOAD_ORDER:
        return list(loads_mn)
    planes = list(planes)
    if sorted(planes) != list(range(len(loads_mn))):
        raise RawDataError(
            f"{where}: optics.images.load_series.planes {planes} for the sheet's "
            f"{len(loads_mn)} loads {list(loads_mn)} mN; expected one plane index per load, "
            f"each of 0 to {len(loads_mn) - 1} once"
        )
    by_plane = [0.0] * len(loads_mn)
    for load, plane in zip(loads_mn, planes, strict=True):
        by_plane[plane] = load
    return by_plane


def rheometer_files(folder: str | Path, loads_mn: Sequence[float]) -> list[Path]:
    """Paths of the rheometer records (``<load>.csv`` or an export's ``<load>.txt``), in the
    order of ``loads_mn``."""
    patterns = [f"*{suffix}" for suffix in RHEOMETER_SUFFIXES]
    return files_by_load(folder, loads_mn, patterns, "rheometer", "25.csv")


def flim_file(folder: str | Path) -> Path | None:
    """The sphere's FLIM file in ``folder`` (``flim.tif`` or ``flim.ptu``), None if it has
    none; RawDataError naming the folder if it has both."""
    folder = Path(folder)
    found = [folder / name for name in FLIM_NAMES if (folder / name).is_file()]
    if len(found) > 1:
        raise RawDataError(
            f"{folder}: both {' and '.join(FLIM_NAMES)}; expected one FLIM file per sphere"
        )
    return found[0] if found else None


def per_load_files(
    given: str | Path | Sequence[str | Path], loads_mn: Sequence[float], name_of
) -> list[Path]:
    """The per-load files a rule was given, in the order of ``loads_mn``.

    ``given`` is either the files themselves (measured data: the workflow matched them to
    the loads; one file may be given as a plain path) or the one folder the virtual
    experiment writes whole, whose files are named by ``name_of(load)``
    (:func:`fluorescence_name`, :func:`rheometer_name`), or by one of the names
    ``name_of(load)`` returns (:func:`fluorescence_names`: the one present; several present
    is an error naming them). No folder is searched: a missing file is an error naming it.
    """
    if isinstance(given, str | Path) and Path(given).is_dir():
        paths = [_named_file(Path(given), name_of(load)) for load in loads_mn]
    elif isinstance(given, str | Path):
        paths = [Path(given)]
    else:
        paths = [Path(p) for p in given]
    if len(paths) != len(loads_mn):
        raise RawDataError(
            f"{len(paths)} files {[str(p) for p in paths]} for {len(loads_mn)} loads "
            f"{list(loads_mn)} mN; expected one file per load"
        )
    for path in paths:
        if not path.is_file():
            raise RawDataError(f"{path}: no such file (expected one file per load)")
    return paths


def _named_file(folder: Path, names: str | tuple[str, ...]) -> Path:
    """``folder / names`` (one name), or the one of several ``names`` present in ``folder``;
    RawDataError naming the folder if none or several are."""
    if isinstance(names, str):
        return folder / names
    present = [folder / name for name in names if (folder / name).is_file()]
    if len(present) != 1:
        raise RawDataError(
            f"{folder}: {len(present)} of {', '.join(names)} present "
            f"({', '.join(p.name for p in present) or 'none'}); expected exactly one"
        )
    return present[0]


def afm_file(folder: str | Path, stem: str) -> Path:
    """The AFM height map ``stem`` (afm_before / afm_after) in ``folder``, in whichever of the
    readable formats it is; RawDataError naming the folder if none or several."""
    folder = Path(folder)
    found = [folder / f"{stem}{ext}" for ext in AFM_SUFFIXES if (folder / f"{stem}{ext}").is_file()]
    if len(found) != 1:
        raise RawDataError(
            f"{folder}: expected exactly one {stem} height map "
            f"({', '.join(stem + s for s in AFM_SUFFIXES)}), found {len(found)}"
        )
    return found[0]
