"""Which raw files of a sphere a rule reads (config/README.md, "Your own data"): the
virtual experiment's, named by its formats, or those of the folder the sheet names.

A measured sphere's per-load files are matched to its sheet loads here, at DAG time
(amontons.io.layout), so that a replaced file re-runs exactly the jobs that read it; a sphere
whose loads lie in one file (amontons.workflow.load_series) gives that file instead.
"""

from __future__ import annotations

import os

from amontons.io.export_map import MAP_KEYS, SINGLE_MAP_NAME
from amontons.io.layout import (
    ABSORBANCE_NAME,
    AFM_SUFFIXES,
    BEAD_STEM,
    CONFOCAL_SUFFIXES,
    FLUORESCENCE_DIR,
    REFLECTION_STEM,
    RHEOMETER_DIR,
    afm_file,
    confocal_file,
    flim_file,
    fluorescence_images,
    rheometer_files,
)
from amontons.workflow.load_series import LoadSeries
from amontons.workflow.sheet_rows import SheetRows
from amontons.workflow.wildcards import names_pattern

# The sheet column that names the export map (config rheometer_export) of a sphere's
# rheometer files.
SHEET_EXPORT_COLUMN = "rheometer_export"


class RawFiles:
    """The raw files of the selected spheres, by role (per-load fluorescence and rheometer
    files, the reflection, bead and FLIM images, the AFM maps, the absorbance spectrum), and
    the export maps their rheometer files are read with. ``synthetic_images``: the suffix of
    the virtual experiment's confocal images ('.tif', '.ome.tif', '.czi';
    amontons.io.layout.IMAGE_FORMATS of virtual_experiment.formats.images);
    ``synthetic_flim``: the format of its FLIM file ('tif' or 'ptu', config
    virtual_experiment.formats.flim)."""

    def __init__(
        self,
        rows: SheetRows,
        series: LoadSeries,
        synthetic_images: str = ".tif",
        synthetic_flim: str = "tif",
    ):
        self.rows = rows
        self.series = series
        self.synthetic_images = synthetic_images
        self.synthetic_flim = synthetic_flim

    def per_load_inputs(self, sphere: str, kind: str) -> str | list[str]:
        """The per-load raw files of a sphere, 'fluorescence' or 'rheometer', in load order.

        Measured data: each load's file, matched to the sheet's loads (a folder that does not
        match them stops the run, naming it), so that the script reads exactly these files;
        for fluorescence held in one load-series file, that file alone (every load's job
        reads it). Synthetic data: the folder, which the virtual experiment writes whole and
        names by load (amontons.io.layout.per_load_files)."""
        subfolder = FLUORESCENCE_DIR if kind == "fluorescence" else RHEOMETER_DIR
        folder = f"{self.rows.raw_dir(sphere)}/{subfolder}"
        if self.rows.is_synthetic(sphere):
            return folder
        series_file = self.series.file(sphere) if kind == "fluorescence" else None
        if series_file is not None:
            return [series_file]
        files = fluorescence_images if kind == "fluorescence" else rheometer_files
        return [str(path) for path in files(folder, self.rows.loads_mn(sphere))]

    def reflection_fluorescence(self, sphere: str) -> str:
        """The one fluorescence image the edge gap reads: the one at the reflection load (for
        synthetic data, the folder the virtual experiment writes it into; for a load-series
        file, that file)."""
        images = self.per_load_inputs(sphere, "fluorescence")
        if self.rows.is_synthetic(sphere):
            return images
        if self.series.file(sphere) is not None:
            return images[0]
        load = self.rows.value(sphere, "reflection_load_mn")
        return images[[abs(load - f) < 1e-9 for f in self.rows.loads_mn(sphere)].index(True)]

    def confocal_image(self, sphere: str, stem: str) -> str:
        """A sphere's one confocal image ``stem`` (reflection, bead): the virtual experiment's
        in its format; a measured sphere's in whichever of amontons.io.layout.CONFOCAL_SUFFIXES
        it is (two stop the run, naming them). With none present the TIFF is named, so the
        missing input is reported by that name."""
        if self.rows.is_synthetic(sphere):
            return self.rows.raw_file(sphere, f"{stem}{self.synthetic_images}")
        found = confocal_file(self.rows.raw_dir(sphere), stem)
        if found:
            return str(found)
        return self.rows.raw_file(sphere, f"{stem}{CONFOCAL_SUFFIXES[2]}")

    def reflection_image(self, sphere: str) -> str:
        """The reflection image (Newton rings) of a sphere."""
        return self.confocal_image(sphere, REFLECTION_STEM)

    def afm_path(self, sphere: str, stem: str) -> str:
        """A sphere's AFM height map ``stem`` (afm_before / afm_after): the virtual experiment
        writes TIFF; measured data may be any format amontons.io.layout.AFM_SUFFIXES lists (two
        formats of one map stop the run, naming both). With none present the TIFF is named,
        so the missing input is reported by that name."""
        folder = self.rows.raw_dir(sphere)
        present = [ext for ext in AFM_SUFFIXES if os.path.isfile(f"{folder}/{stem}{ext}")]
        if self.rows.is_synthetic(sphere) or not present:
            return self.rows.raw_file(sphere, f"{stem}.tif")
        return str(afm_file(folder, stem))

    def bead_image(self, sphere: str) -> str:
        """The bead image a sphere's PSF is measured from: the sheet's bead_file (shared by
        many spheres) or the sphere's own bead image (bead.tif, .ome.tif, .czi)."""
        shared = self.rows.row(sphere).get("bead_file")
        return shared or self.confocal_image(sphere, BEAD_STEM)

    def absorbance_spectrum(self, sphere: str) -> str:
        """The absorbance spectrum of a sphere's cover slip: the sheet's absorbance_file
        (shared by the slips of one batch) or the sphere's own absorbance.csv."""
        shared = self.rows.row(sphere).get("absorbance_file")
        return shared or self.rows.raw_file(sphere, ABSORBANCE_NAME)

    def flim_path(self, sphere: str) -> str | None:
        """A sphere's FLIM file: the virtual experiment's flim.<format> where the sheet gives
        flim_load_mn; a measured sphere's flim.tif or flim.ptu (amontons.io.layout.flim_file;
        both stop the run, naming them); None where it has none."""
        if self.rows.is_synthetic(sphere):
            if self.rows.value(sphere, "flim_load_mn") is None:
                return None
            return self.rows.raw_file(sphere, f"flim.{self.synthetic_flim}")
        found = flim_file(self.rows.raw_dir(sphere))
        return None if found is None else str(found)

    def has_flim(self, sphere: str) -> bool:
        return self.flim_path(sphere) is not None

    def synthetic_pattern(self, with_flim: bool) -> str:
        """Regex matching the synthetic spheres with (or without) a FLIM map; never
        empty-match."""
        names = [
            s for s in self.rows if self.rows.is_synthetic(s) and self.has_flim(s) == with_flim
        ]
        return names_pattern(names)

    def rheometer_export(self, sphere: str, maps):
        """The export maps a sphere's rheometer files are read with: the config's
        rheometer_export ``maps`` as they are, or only the map its sheet row names (column
        rheometer_export; a single map is named 'export'). Our own CSV reads as such either
        way (amontons.io.rheometer_files)."""
        named = self.rows.row(sphere).get(SHEET_EXPORT_COLUMN)
        if named is None or maps is None:
            return maps
        if named == SINGLE_MAP_NAME:  # the map given by rheometer_export's own keys
            return {key: value for key, value in maps.items() if key in MAP_KEYS}
        return {named: maps[named]}
