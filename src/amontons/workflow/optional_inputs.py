"""A sphere's optional raw inputs (config/README.md, "Required and optional files"): which
of them a sphere lacks, and so what its data allow. Without one, exactly the outputs that
read it, and what follows from them, are not made; a dry run prints what is left out."""

from __future__ import annotations

import os

from amontons.io.layout import AFM_SUFFIXES, CONFOCAL_SUFFIXES, REFLECTION_STEM, RHEOMETER_DIR
from amontons.workflow.raw_files import RawFiles
from amontons.workflow.sheet_rows import SheetRows
from amontons.workflow.wildcards import names_pattern

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


class OptionalInputs:
    """The optional inputs each selected sphere lacks (:data:`OPTIONAL_INPUTS`), and what
    that allows: where its PSF comes from, whether its scenes can be simulated and rendered.
    ``psf_stand_in``: whether the config gives a PSF (optics.psf.stand_in) for the spheres
    with no bead image."""

    def __init__(self, rows: SheetRows, files: RawFiles, psf_stand_in: bool = False):
        self.rows = rows
        self.files = files
        self.psf_stand_in = psf_stand_in
        self._missing: dict[str, dict[str, str]] = {}

    def missing(self, sphere: str) -> dict[str, str]:
        """The optional inputs a sphere lacks (:data:`OPTIONAL_INPUTS`), each with what was
        looked for. The virtual experiment writes every one; a measured sphere's folder is
        looked at once, when the DAG is built."""
        if sphere not in self._missing:
            self._missing[sphere] = {} if self.rows.is_synthetic(sphere) else self._look(sphere)
        return self._missing[sphere]

    def _look(self, sphere: str) -> dict[str, str]:
        folder = self.rows.raw_dir(sphere)
        missing = {}
        if not os.path.isfile(self.files.reflection_image(sphere)):
            names = ", ".join(REFLECTION_STEM + suffix for suffix in CONFOCAL_SUFFIXES)
            missing[REFLECTION] = f"no reflection image ({names}) in {folder}"
        elif self.rows.value(sphere, "reflection_load_mn") is None:
            missing[REFLECTION] = "no reflection_load_mn in the sheet"
        for kind, path in (
            (BEAD, self.files.bead_image(sphere)),
            (ABSORBANCE, self.files.absorbance_spectrum(sphere)),
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

    def has(self, sphere: str, kind: str) -> bool:
        """Whether a sphere has the optional input ``kind``."""
        return kind not in self.missing(sphere)

    def with_input(self, kind: str) -> list[str]:
        """The spheres that have the optional input ``kind``."""
        return [s for s in self.rows if self.has(s, kind)]

    def psf_source(self, sphere: str) -> str | None:
        """Where a sphere's PSF comes from: 'bead' (its image), 'stand_in' (the config's FWHM)
        or None (neither: nothing of it is rendered like the microscope)."""
        if self.has(sphere, BEAD):
            return "bead"
        return "stand_in" if self.psf_stand_in else None

    def psf_pattern(self, source: str) -> str:
        """Regex matching the spheres whose PSF comes from ``source`` ('bead', 'stand_in')."""
        return names_pattern([s for s in self.rows if self.psf_source(s) == source])

    def can_simulate(self, sphere: str) -> bool:
        """A sphere's scenes need its AFM map before the loads."""
        return self.has(sphere, AFM_BEFORE)

    def can_render(self, sphere: str) -> bool:
        """A sphere's microscope scenes and scans need its AFM map and a PSF."""
        return self.can_simulate(sphere) and self.psf_source(sphere) is not None
