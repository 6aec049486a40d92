"""The selected spheres of the sample sheet, as the DAG asks after them: their rows, where
their raw data lie and which raw files a rule reads (config/README.md, "Your own data").

Raw data are the virtual experiment's (data_source 'synthetic') or a folder the sheet names.
A measured sphere's per-load files are matched to its sheet loads here, at DAG time
(amontons.io.layout), so that a replaced file re-runs exactly the jobs that read it. A sphere
may instead give one file holding every load (config/README.md, "A load series in one file"):
then that file is every fluorescence job's input, and the jobs' ``images`` param says which
plane is which load.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from collections.abc import Mapping

from amontons.io.export_map import MAP_KEYS, SINGLE_MAP_NAME
from amontons.io.layout import (
    ABSORBANCE_NAME,
    AFM_SUFFIXES,
    BEAD_STEM,
    CONFOCAL_SUFFIXES,
    FLUORESCENCE_DIR,
    LOAD_SERIES_STEM,
    REFLECTION_STEM,
    RHEOMETER_DIR,
    RawDataError,
    afm_file,
    confocal_file,
    flim_file,
    fluorescence_images,
    folder_files,
    load_count_mismatch,
    plane_loads,
    rheometer_files,
)
from amontons.io.pixel_probe import load_plane_count, states_pixel_size
from amontons.models import CONTACT_HARDENING, with_parameter
from amontons.workflow.failures import FailedJob
from amontons.workflow.params import sorted_keys
from amontons.workflow.paths import CONTACT_AREA, RunPaths

# The sheet values a scene takes from its sphere.
SCENE_COLUMNS = (
    "diameter_mm",
    "e_star_gpa",
    "loads",
    *(m.parameter.sheet_column for m in with_parameter()),
)
# The sheet column of a virtual sphere's true contact-hardening coefficient, MPa/nm (the
# virtual experiment's truth is contact hardening: docs/workflow.md).
TRUE_HARDENING_COLUMN = CONTACT_HARDENING.parameter.sheet_column
# A sphere's optional raw inputs (config/README.md, "Required and optional files"): without one,
# exactly the outputs that read it, and what follows from them, are not made.
REFLECTION, BEAD, ABSORBANCE, AFM_BEFORE, AFM_AFTER, RHEOMETER = (
    "reflection",
    "bead",
    "absorbance",
    "afm_before",
    "afm_after",
    "rheometer",
)
# What each optional input adds, and so what a sphere without it does not get.
OPTIONAL_INPUTS = {
    REFLECTION: "the gap at the contact edge (edge_gap.json, .png, .pdf)",
    BEAD: "the measured PSF (psf.json, .png, .pdf) that renders its scenes and scans like "
    "the microscope",
    ABSORBANCE: "the grafting density (grafting_density.json, absorbance.png, .pdf)",
    AFM_BEFORE: "the topography, every scene and scan, the study's figures and the model table",
    AFM_AFTER: "the topography (topography.json, .png, .pdf) and the flattening (Fig. B.9)",
    RHEOMETER: "the friction (friction.csv) and its place in the Amontons figures",
}
NO_PSF = (
    "no PSF either (optics.psf.stand_in is null): no microscope scene, no scan, no study "
    "figure and no model-table row"
)
STAND_IN_PSF = "the PSF is optics.psf.stand_in's (psf.json says so); no bead profile figure"
# The sheet column that names the export map (config rheometer_export) of a sphere's
# rheometer files.
SHEET_EXPORT_COLUMN = "rheometer_export"
# Sheet columns that name a file shared by many spheres, in place of the sphere's own.
SHARED_FILE_COLUMNS = {BEAD: "bead_file", ABSORBANCE: "absorbance_file"}


class Spheres:
    """The sheet records (sphere id → record, amontons.config.sheet) of the selected
    materials, in the sheet's order, with the run's paths."""

    def __init__(
        self,
        records: Mapping[str, dict],
        paths: RunPaths,
        psf_stand_in: bool = False,
        synthetic_flim: str = "tif",
        synthetic_images: str = ".tif",
        load_series: Mapping | None = None,
    ):
        """``psf_stand_in``: whether the config gives a PSF (optics.psf.stand_in) for the
        spheres with no bead image; ``synthetic_flim``: the format of the virtual experiment's
        FLIM file ('tif' or 'ptu', config virtual_experiment.formats.flim);
        ``synthetic_images``: the suffix of its confocal images ('.tif', '.ome.tif', '.czi';
        amontons.io.layout.IMAGE_FORMATS of virtual_experiment.formats.images);
        ``load_series``: how a file holding a sphere's whole load series maps its planes to
        the loads (config optics.images.load_series: {axis, planes}; None: no such file is
        accepted)."""
        self.records = dict(records)
        self.paths = paths
        self.psf_stand_in = psf_stand_in
        self.synthetic_flim = synthetic_flim
        self.synthetic_images = synthetic_images
        self.load_series = None if load_series is None else dict(load_series)
        self._missing: dict[str, dict[str, str]] = {}
        self._series_files: dict[str, str | None] = {}
        self.held_out: dict[str, list[FailedJob]] = {}

    def __iter__(self):
        return iter(self.records)

    def row(self, sphere: str) -> dict:
        return self.records[sphere]

    def of(self, material: str, having: str | None = None) -> list[str]:
        """The spheres of ``material`` whose results the run makes and its tables read, in
        sheet order: not those held out by an earlier run's failure (:meth:`hold_out`), and
        only those with the optional input ``having`` where it is given."""
        return [
            s
            for s, row in self.records.items()
            if row["material"] == material
            and s not in self.held_out
            and (having is None or self.has(s, having))
        ]

    def materials_with(self, materials, kind: str) -> list[str]:
        """Those of ``materials`` with at least one sphere that has the optional input
        ``kind``."""
        return [m for m in materials if self.of(m, having=kind)]

    def material_of(self, sphere: str) -> str:
        return self.records[sphere]["material"]

    def is_synthetic(self, sphere: str) -> bool:
        return self.records[sphere]["data_source"] == "synthetic"

    def raw_dir(self, sphere: str) -> str:
        """Folder of a sphere's raw data: the virtual experiment's, or the one the sheet
        names."""
        if self.is_synthetic(sphere):
            return self.paths.synthetic_sphere(sphere)
        return self.records[sphere]["data_source"]

    def raw_file(self, sphere: str, name: str) -> str:
        """Path of one raw file of a sphere (e.g. 'bead.tif')."""
        return f"{self.raw_dir(sphere)}/{name}"

    def loads_mn(self, sphere: str) -> list[float]:
        return list(self.records[sphere]["loads"])

    def value(self, sphere: str, column: str) -> float | None:
        """A numeric sheet value, or None where the cell is empty."""
        value = self.records[sphere].get(column)
        return None if value is None else float(value)

    def rheometer_export(self, sphere: str, maps):
        """The export maps a sphere's rheometer files are read with: the config's
        rheometer_export ``maps`` as they are, or only the map its sheet row names (column
        rheometer_export; a single map is named 'export'). Our own CSV reads as such either
        way (amontons.io.rheometer_files)."""
        named = self.records[sphere].get(SHEET_EXPORT_COLUMN)
        if named is None or maps is None:
            return maps
        if named == SINGLE_MAP_NAME:  # the map given by rheometer_export's own keys
            return {key: value for key, value in maps.items() if key in MAP_KEYS}
        return {named: maps[named]}

    def pixel_nm(self, sphere: str) -> float | None:
        """The fluorescence images' pixel from the sheet, nm; None where the sheet leaves it
        to the files' metadata."""
        return self.value(sphere, "fluorescence_pixel_nm")

    def image_pixel_inputs(self, sphere: str) -> list[str]:
        """What a rule that renders a contact at the fluorescence pixel reads that pixel from:
        nothing where the sheet gives it (fluorescence_pixel_nm), else the sphere's measured
        contact-area table, which records the pixel each image's file gave
        (amontons.measure.area.image_pixel_m)."""
        if self.pixel_nm(sphere) is not None:
            return []
        return [self.paths.measured(CONTACT_AREA, self.material_of(sphere), sphere)]

    def images_without_pixel(self, sphere: str) -> list[str]:
        """The images of a measured sphere whose sheet row gives no fluorescence_pixel_nm
        that state no pixel size in their metadata either (amontons.io.pixel_probe): the
        confocal images (fluorescence, reflection, bead) and the FLIM file (map or photons);
        none where the sheet gives one. Images that do not match the loads, or whose header
        cannot be read, are left to the errors that name them."""
        if self.is_synthetic(sphere) or self.pixel_nm(sphere) is not None:
            return []
        try:
            images = self.per_load_inputs(sphere, "fluorescence")
        except RawDataError:
            images = []
        singles = (self.reflection_image(sphere), self.bead_image(sphere), self.flim_path(sphere))
        images += [path for path in singles if path is not None and os.path.isfile(path)]
        return [path for path in images if not _states_pixel(path)]

    def check_pixel_sizes(self) -> None:
        """Stop the run before any job where an image has no pixel size: RawDataError naming
        each sphere and its images that state none while the sheet gives none."""
        lacking = {sphere: self.images_without_pixel(sphere) for sphere in self.records}
        lines = [f"sphere {s}: {', '.join(paths)}" for s, paths in lacking.items() if paths]
        if lines:
            raise RawDataError(
                "images without a pixel size in their metadata, and no fluorescence_pixel_nm "
                f"in the sheet: {'; '.join(lines)}; expected the sheet's fluorescence_pixel_nm "
                "for these spheres, or images that state their pixel (OME-TIFF PhysicalSizeX, "
                "CZI Scaling, TIFF resolution tags, PTU ImgHdr_PixResol)"
            )

    def load_series_file(self, sphere: str) -> str | None:
        """A measured sphere's one file holding every load's fluorescence image
        (``<folder>/fluorescence.<suffix>``, amontons.io.layout.LOAD_SERIES_STEM); None where
        it has none (the virtual experiment writes one image per load).

        Raises RawDataError naming both where the folder also has the per-load
        ``fluorescence/``, and naming the file where the config does not say how its planes
        map to the loads (optics.images.load_series): neither is guessed. The folder is
        looked at once, when the DAG asks first."""
        if sphere not in self._series_files:
            self._series_files[sphere] = self._find_load_series_file(sphere)
        return self._series_files[sphere]

    def _find_load_series_file(self, sphere: str) -> str | None:
        if self.is_synthetic(sphere):
            return None
        folder = self.raw_dir(sphere)
        found = confocal_file(folder, LOAD_SERIES_STEM)
        if found is None:
            return None
        if os.path.isdir(f"{folder}/{FLUORESCENCE_DIR}"):
            raise RawDataError(
                f"sphere {sphere}: both {folder}/{FLUORESCENCE_DIR}/ (one image per load) and "
                f"{found} (every load in one file); expected one of the two"
            )
        if self.load_series is None:
            raise RawDataError(
                f"sphere {sphere}: {found} holds every load, but optics.images.load_series is "
                "null; expected it to say which axis (series or frames) carries the loads and "
                "which plane is which load (config/README.md, 'A load series in one file')"
            )
        return str(found)

    def plane_loads(self, sphere: str) -> list[float] | None:
        """The load (mN) of each plane of a sphere's load-series file, in plane order; None
        where it has per-load images. A planes list that does not fit the sheet's loads stops
        the run, naming the sphere (amontons.io.layout.plane_loads)."""
        if self.load_series_file(sphere) is None:
            return None
        return plane_loads(self.loads_mn(sphere), self.load_series["planes"], f"sphere {sphere}")

    def fluorescence_choice(self, sphere: str, images: Mapping) -> dict:
        """The ``images`` param of a rule that reads a sphere's fluorescence images: the
        config's choice (amontons.workflow.params.image_choice), plus for a load-series file
        ``load_series`` {axis, plane_loads_mn} (amontons.io.rawdata.fluorescence_planes).
        Spheres with per-load images get ``images`` as it is, so their jobs' params, and
        what they make, stay those of a run without load-series files."""
        planes = self.plane_loads(sphere)
        if planes is None:
            return dict(images)
        series = {"axis": self.load_series["axis"], "plane_loads_mn": planes}
        return sorted_keys({**images, "load_series": series})

    def check_load_series_files(self, series: int = 0) -> None:
        """Stop the run before any job where a sphere's load-series file does not hold one
        plane per load along the load axis, as its header says (amontons.io.pixel_probe;
        ``series``: optics.images.series, the series whose frames carry the loads):
        RawDataError naming the sphere, the file, what it holds and the loads. A header that
        does not say is left to the jobs' reader, which counts the planes again; a folder that
        cannot be mapped at all, to the rules' input functions, which name it."""
        for sphere in self.records:
            try:
                path, planes = self.load_series_file(sphere), self.plane_loads(sphere)
            except RawDataError:
                continue
            if path is None:
                continue
            axis = self.load_series["axis"]
            count = load_plane_count(path, axis, series)
            if count is not None and count != len(planes):
                described = f"it holds {count} {axis} (its header says)"
                raise RawDataError(
                    f"sphere {sphere}: {load_count_mismatch(path, described, axis, planes)}"
                )

    def per_load_inputs(self, sphere: str, kind: str) -> str | list[str]:
        """The per-load raw files of a sphere, 'fluorescence' or 'rheometer', in load order.

        Measured data: each load's file, matched to the sheet's loads (a folder that does not
        match them stops the run, naming it), so that the script reads exactly these files;
        for fluorescence held in one load-series file, that file alone (every load's job
        reads it). Synthetic data: the folder, which the virtual experiment writes whole and
        names by load (amontons.io.layout.per_load_files)."""
        subfolder = FLUORESCENCE_DIR if kind == "fluorescence" else RHEOMETER_DIR
        folder = f"{self.raw_dir(sphere)}/{subfolder}"
        if self.is_synthetic(sphere):
            return folder
        series_file = self.load_series_file(sphere) if kind == "fluorescence" else None
        if series_file is not None:
            return [series_file]
        files = fluorescence_images if kind == "fluorescence" else rheometer_files
        return [str(path) for path in files(folder, self.loads_mn(sphere))]

    def reflection_fluorescence(self, sphere: str) -> str:
        """The one fluorescence image the edge gap reads: the one at the reflection load (for
        synthetic data, the folder the virtual experiment writes it into; for a load-series
        file, that file)."""
        images = self.per_load_inputs(sphere, "fluorescence")
        if self.is_synthetic(sphere):
            return images
        if self.load_series_file(sphere) is not None:
            return images[0]
        load = self.value(sphere, "reflection_load_mn")
        return images[[abs(load - f) < 1e-9 for f in self.loads_mn(sphere)].index(True)]

    def confocal_image(self, sphere: str, stem: str) -> str:
        """A sphere's one confocal image ``stem`` (reflection, bead): the virtual experiment's
        in its format; a measured sphere's in whichever of amontons.io.layout.CONFOCAL_SUFFIXES
        it is (two stop the run, naming them). With none present the TIFF is named, so the
        missing input is reported by that name."""
        if self.is_synthetic(sphere):
            return self.raw_file(sphere, f"{stem}{self.synthetic_images}")
        found = confocal_file(self.raw_dir(sphere), stem)
        return str(found) if found else self.raw_file(sphere, f"{stem}{CONFOCAL_SUFFIXES[2]}")

    def reflection_image(self, sphere: str) -> str:
        """The reflection image (Newton rings) of a sphere."""
        return self.confocal_image(sphere, REFLECTION_STEM)

    def afm_path(self, sphere: str, stem: str) -> str:
        """A sphere's AFM height map ``stem`` (afm_before / afm_after): the virtual experiment
        writes TIFF; measured data may be any format amontons.io.layout.AFM_SUFFIXES lists (two
        formats of one map stop the run, naming both). With none present the TIFF is named,
        so the missing input is reported by that name."""
        folder = self.raw_dir(sphere)
        present = [ext for ext in AFM_SUFFIXES if os.path.isfile(f"{folder}/{stem}{ext}")]
        if self.is_synthetic(sphere) or not present:
            return self.raw_file(sphere, f"{stem}.tif")
        return str(afm_file(folder, stem))

    def bead_image(self, sphere: str) -> str:
        """The bead image a sphere's PSF is measured from: the sheet's bead_file (shared by
        many spheres) or the sphere's own bead image (bead.tif, .ome.tif, .czi)."""
        return self.records[sphere].get("bead_file") or self.confocal_image(sphere, BEAD_STEM)

    def absorbance_spectrum(self, sphere: str) -> str:
        """The absorbance spectrum of a sphere's cover slip: the sheet's absorbance_file
        (shared by the slips of one batch) or the sphere's own absorbance.csv."""
        shared = self.records[sphere].get("absorbance_file")
        return shared or self.raw_file(sphere, ABSORBANCE_NAME)

    def missing(self, sphere: str) -> dict[str, str]:
        """The optional inputs a sphere lacks (:data:`OPTIONAL_INPUTS`), each with what was
        looked for. The virtual experiment writes every one; a measured sphere's folder is
        looked at once, when the DAG is built."""
        if sphere not in self._missing:
            self._missing[sphere] = {} if self.is_synthetic(sphere) else self._look(sphere)
        return self._missing[sphere]

    def _look(self, sphere: str) -> dict[str, str]:
        folder = self.raw_dir(sphere)
        missing = {}
        if not os.path.isfile(self.reflection_image(sphere)):
            names = ", ".join(REFLECTION_STEM + suffix for suffix in CONFOCAL_SUFFIXES)
            missing[REFLECTION] = f"no reflection image ({names}) in {folder}"
        elif self.value(sphere, "reflection_load_mn") is None:
            missing[REFLECTION] = "no reflection_load_mn in the sheet"
        for kind, path in (
            (BEAD, self.bead_image(sphere)),
            (ABSORBANCE, self.absorbance_spectrum(sphere)),
        ):
            if not os.path.isfile(path):
                missing[kind] = f"no {path}"
        for stem in (AFM_BEFORE, AFM_AFTER):
            if not any(os.path.isfile(f"{folder}/{stem}{ext}") for ext in AFM_SUFFIXES):
                missing[stem] = f"no {stem}.* in {folder}"
        if not os.path.isdir(f"{folder}/{RHEOMETER_DIR}"):
            missing[RHEOMETER] = f"no {RHEOMETER_DIR}/ folder in {folder}"
        return missing

    def left_out(self, sphere: str) -> list[str]:
        """What a sphere's data do not allow, one line per optional input it lacks: what was
        looked for and what will not be made (a dry run prints these)."""
        lines = []
        for kind, why in self.missing(sphere).items():
            line = f"{why}: {OPTIONAL_INPUTS[kind]} will not be made"
            if kind == BEAD:
                line += f"; {NO_PSF if self.psf_source(sphere) is None else STAND_IN_PSF}"
            lines.append(line)
        return lines

    def hold_out(self, failed: Mapping[str, list[FailedJob]]) -> None:
        """Hold spheres out of the run's results and tables, each with the failed jobs of an
        earlier run that hold it out (amontons.workflow.ledger)."""
        unknown = set(failed) - set(self.records)
        if unknown:
            raise ValueError(f"cannot hold out spheres not in the run: {sorted(unknown)}")
        self.held_out = {sphere: list(jobs) for sphere, jobs in failed.items()}

    def failed_lines(self, sphere: str) -> list[str]:
        """Why a held-out sphere is out of its material's tables: one line per failed job,
        with its error and log (none for a sphere not held out)."""
        material = self.material_of(sphere)
        return [
            f"failed in an earlier run: {job.rule}: {job.error or 'see its log'} [{job.log}]; "
            f"held out of {material}'s tables, figures, summary and report until its files, "
            "its sheet row or the config change, or the job succeeds"
            for job in self.held_out.get(sphere, [])
        ]

    def data_stamp(self, sphere: str, salt: str = "") -> str:
        """A digest of what a sphere's jobs read from outside the run: its sheet row and, for
        each file of its raw folder and each shared file its row names, the path, size and
        modification time; ``salt`` is mixed in (the run's config digest)."""
        digest = hashlib.sha256(salt.encode())
        digest.update(json.dumps(self.records[sphere], sort_keys=True, default=str).encode())
        shared = [self.records[sphere].get(column) for column in SHARED_FILE_COLUMNS.values()]
        for path in folder_files(self.raw_dir(sphere)) + [p for p in shared if p]:
            if os.path.isfile(path):
                stat = os.stat(path)
                digest.update(f"{path}\0{stat.st_size}\0{stat.st_mtime_ns}\n".encode())
        return digest.hexdigest()

    def has(self, sphere: str, kind: str) -> bool:
        """Whether a sphere has the optional input ``kind``."""
        return kind not in self.missing(sphere)

    def psf_source(self, sphere: str) -> str | None:
        """Where a sphere's PSF comes from: 'bead' (its image), 'stand_in' (the config's FWHM)
        or None (neither: nothing of it is rendered like the microscope)."""
        if self.has(sphere, BEAD):
            return "bead"
        return "stand_in" if self.psf_stand_in else None

    def can_simulate(self, sphere: str) -> bool:
        """A sphere's scenes need its AFM map before the loads."""
        return self.has(sphere, AFM_BEFORE)

    def can_render(self, sphere: str) -> bool:
        """A sphere's microscope scenes and scans need its AFM map and a PSF."""
        return self.can_simulate(sphere) and self.psf_source(sphere) is not None

    def with_input(self, kind: str) -> list[str]:
        """The spheres that have the optional input ``kind``."""
        return [s for s in self.records if self.has(s, kind)]

    def psf_pattern(self, source: str) -> str:
        """Regex matching the spheres whose PSF comes from ``source`` ('bead', 'stand_in')."""
        return names_pattern([s for s in self.records if self.psf_source(s) == source])

    def flim_path(self, sphere: str) -> str | None:
        """A sphere's FLIM file: the virtual experiment's flim.<format> where the sheet gives
        flim_load_mn; a measured sphere's flim.tif or flim.ptu (amontons.io.layout.flim_file;
        both stop the run, naming them); None where it has none."""
        if self.is_synthetic(sphere):
            if self.value(sphere, "flim_load_mn") is None:
                return None
            return self.raw_file(sphere, f"flim.{self.synthetic_flim}")
        found = flim_file(self.raw_dir(sphere))
        return None if found is None else str(found)

    def has_flim(self, sphere: str) -> bool:
        return self.flim_path(sphere) is not None

    def synthetic_pattern(self, with_flim: bool) -> str:
        """Regex matching the synthetic spheres with (or without) a FLIM map; never
        empty-match."""
        names = [s for s in self.records if self.is_synthetic(s) and self.has_flim(s) == with_flim]
        return names_pattern(names)

    def data_label(self, spheres) -> str:
        """'synthetic data' if any of ``spheres`` comes from the virtual experiment."""
        synthetic = any(self.is_synthetic(s) for s in spheres)
        return "synthetic data" if synthetic else "measured data"

    def scene_record(self, sphere: str) -> dict:
        """The sheet values a scene takes from its sphere (None where a cell is empty)."""
        row = self.records[sphere]
        return {key: row.get(key) for key in SCENE_COLUMNS}


def _states_pixel(path: str) -> bool:
    """Whether the image ``path`` states its pixel size; an unreadable header counts as yes
    here, since the job that reads it stops naming the file."""
    try:
        return states_pixel_size(path)
    except RawDataError:
        return True


def names_pattern(names) -> str:
    """Regex matching exactly ``names``; never empty-match."""
    return "|".join(map(re.escape, names)) or "(?!)"
