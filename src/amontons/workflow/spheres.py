"""The selected spheres of the sample sheet, as the DAG asks after them: their rows, where
their raw data lie and which raw files a rule reads (config/README.md, "Your own data").

Raw data are the virtual experiment's (data_source 'synthetic') or a folder the sheet names.
A measured sphere's per-load files are matched to its sheet loads here, at DAG time
(amontons.io.layout), so that a replaced file re-runs exactly the jobs that read it.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping

from amontons.io.layout import (
    AFM_SUFFIXES,
    FLUORESCENCE_DIR,
    RHEOMETER_DIR,
    afm_file,
    fluorescence_images,
    rheometer_files,
)
from amontons.workflow.paths import RunPaths

# The sheet values a scene takes from its sphere.
SCENE_COLUMNS = ("diameter_mm", "e_star_gpa", "loads", "hardness_mpa", "hardening_k_mpa_per_nm")


class Spheres:
    """The sheet records (sphere id → record, amontons.config.sheet) of the selected
    materials, in the sheet's order, with the run's paths."""

    def __init__(self, records: Mapping[str, dict], paths: RunPaths):
        self.records = dict(records)
        self.paths = paths

    def __iter__(self):
        return iter(self.records)

    def row(self, sphere: str) -> dict:
        return self.records[sphere]

    def of(self, material: str) -> list[str]:
        """The spheres of ``material``, in sheet order."""
        return [s for s, row in self.records.items() if row["material"] == material]

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

    def pixel_nm(self, sphere: str) -> float:
        """The fluorescence images' pixel, nm."""
        return float(self.records[sphere]["fluorescence_pixel_nm"])

    def per_load_inputs(self, sphere: str, kind: str) -> str | list[str]:
        """The per-load raw files of a sphere, 'fluorescence' or 'rheometer', in load order.

        Measured data: each load's file, matched to the sheet's loads (a folder that does not
        match them stops the run, naming it), so that the script reads exactly these files.
        Synthetic data: the folder, which the virtual experiment writes whole and names by
        load (amontons.io.layout.per_load_files)."""
        subfolder = FLUORESCENCE_DIR if kind == "fluorescence" else RHEOMETER_DIR
        folder = f"{self.raw_dir(sphere)}/{subfolder}"
        if self.is_synthetic(sphere):
            return folder
        files = fluorescence_images if kind == "fluorescence" else rheometer_files
        return [str(path) for path in files(folder, self.loads_mn(sphere))]

    def reflection_fluorescence(self, sphere: str) -> str:
        """The one fluorescence image the edge gap reads: the one at the reflection load (for
        synthetic data, the folder the virtual experiment writes it into)."""
        images = self.per_load_inputs(sphere, "fluorescence")
        if self.is_synthetic(sphere):
            return images
        load = self.value(sphere, "reflection_load_mn")
        return images[[abs(load - f) < 1e-9 for f in self.loads_mn(sphere)].index(True)]

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

    def has_flim(self, sphere: str) -> bool:
        """Synthetic spheres get a FLIM map where the sheet gives flim_load_mn; measured
        spheres have one where their folder holds flim.tif."""
        if self.is_synthetic(sphere):
            return self.value(sphere, "flim_load_mn") is not None
        return os.path.isfile(self.raw_file(sphere, "flim.tif"))

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


def names_pattern(names) -> str:
    """Regex matching exactly ``names``; never empty-match."""
    return "|".join(map(re.escape, names)) or "(?!)"
