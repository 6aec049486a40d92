"""What each target builds (README: `snakemake PS`, `snakemake optics`, ...): every output of
a stage per sphere and per material, collected from the per-sphere result names below and
from the scenes, scans and study of the run."""

from __future__ import annotations

from amontons.workflow import paths as files
from amontons.workflow.optional_inputs import (
    ABSORBANCE,
    AFM_AFTER,
    AFM_BEFORE,
    BEAD,
    REFLECTION,
    RHEOMETER,
)
from amontons.workflow.paths import RunPaths, figure_files
from amontons.workflow.scenes import Scenes
from amontons.workflow.spheres import Spheres
from amontons.workflow.study import Study

# Per-sphere results of each stage, by the optional input each needs (None: only the
# fluorescence images, which every sphere has; PSF: a PSF, measured or the config's stand-in);
# lifetime only where a FLIM map exists.
PSF_NEEDED = "psf"
OPTICS_RESULTS = {
    None: (
        files.CONTACT_AREA,
        "contact_area.png",
        "contact_area.pdf",
        "intensity_pressure.csv",
        "intensity_pressure_fit.json",
        "intensity_pressure.png",
        "intensity_pressure.pdf",
        "hertz_check.csv",
    ),
    PSF_NEEDED: (files.PSF,),
    BEAD: ("psf.png", "psf.pdf"),
    ABSORBANCE: ("grafting_density.json", "absorbance.png", "absorbance.pdf"),
    REFLECTION: ("edge_gap.json", "edge_gap.png", "edge_gap.pdf"),
}
FRICTION_RESULTS = (files.FRICTION,)
SURFACE_RESULTS = ("topography.json", "topography.png", "topography.pdf")
FIT_RESULTS = (files.LOAD_AREA_FIT,)


class Targets:
    """The target rules' inputs of a run."""

    def __init__(self, spheres: Spheres, scenes: Scenes, study: Study, paths: RunPaths):
        self.spheres = spheres
        self.scenes = scenes
        self.study = study
        self.paths = paths

    def measured(self, material: str, sphere: str, name: str) -> str:
        """A measurement of one sphere, checking that the sphere is of ``material``."""
        if self.spheres.rows.material_of(sphere) != material:
            raise ValueError(
                f"sphere {sphere!r} is {self.spheres.rows.material_of(sphere)}, not {material}"
            )
        return self.paths.measured(name, material, sphere)

    def per_sphere(self, material: str, name: str, having: str | None = None) -> list[str]:
        """One measurement file per sphere of ``material`` (with the optional input
        ``having``, where it is given)."""
        return [self.measured(material, s, name) for s in self.spheres.of(material, having)]

    def sphere_outputs(self, materials, names, having: str | None = None) -> list[str]:
        """Results ``names`` of every sphere of ``materials`` (with the optional input
        ``having``, where it is given)."""
        return [
            self.measured(m, s, n)
            for m in materials
            for s in self.spheres.of(m, having)
            for n in names
        ]

    def material_figures(self, materials, names) -> list[str]:
        """Per-material figures and tables ``names`` (PNG, PDF and CSV each)."""
        return [
            path
            for m in materials
            for name in names
            for path in figure_files(self.paths.material(m), name)
        ]

    def optics(self, materials) -> list[str]:
        """Every optical measurement of every sphere of ``materials``."""
        out = []
        for material in materials:
            for sphere in self.spheres.of(material):
                for needs, names in OPTICS_RESULTS.items():
                    if self._has(sphere, needs):
                        out += [self.measured(material, sphere, name) for name in names]
                if self.spheres.files.has_flim(sphere):
                    out.append(self.measured(material, sphere, files.LIFETIME))
        return out

    def _has(self, sphere: str, needs: str | None) -> bool:
        if needs is None:
            return True
        if needs == PSF_NEEDED:
            return self.spheres.inputs.psf_source(sphere) is not None
        return self.spheres.inputs.has(sphere, needs)

    def friction_spheres(self, material: str) -> list[str]:
        """The spheres of ``material`` whose friction was measured."""
        return self.spheres.of(material, having=RHEOMETER)

    def friction(self, materials) -> list[str]:
        """Friction per sphere and the Amontons-deviation figure and table per material."""
        return self.sphere_outputs(
            materials, FRICTION_RESULTS, having=RHEOMETER
        ) + self.material_figures(
            self.spheres.materials_with(materials, RHEOMETER), [files.AMONTONS_FIGURE]
        )

    def surface(self, materials) -> list[str]:
        """The topography of every sphere with both AFM maps."""
        return [
            self.measured(m, s, name)
            for m in materials
            for s in self.spheres.of(m, having=AFM_BEFORE)
            if self.spheres.inputs.has(s, AFM_AFTER)
            for name in SURFACE_RESULTS
        ]

    def fits(self, materials) -> list[str]:
        return self.sphere_outputs(materials, FIT_RESULTS)

    def figures(self, materials) -> list[str]:
        """The per-material figures and tables: load-area (of a material with a sphere not
        held out) and Amontons deviation."""
        return self.material_figures(
            [m for m in materials if self.spheres.of(m)], ["load_area"]
        ) + self.material_figures(
            self.spheres.materials_with(materials, RHEOMETER), [files.AMONTONS_FIGURE]
        )

    def retries(self, materials) -> list[str]:
        """The outputs of the failed jobs that hold spheres of ``materials`` out of the run
        (amontons.workflow.ledger): those jobs run again, so the run fails while they do."""
        return [
            path
            for sphere, jobs in self.spheres.held_out.items()
            if self.spheres.rows.material_of(sphere) in materials
            for job in jobs
            for path in job.output_files
        ]

    def material(self, materials) -> list[str]:
        """Everything a material's target builds: every measurement, fit, figure and table,
        and the failed jobs of its held-out spheres, again."""
        everything = (
            self.optics(materials)
            + self.surface(materials)
            + self.friction(materials)
            + self.fits(materials)
            + self.figures(materials)
            + self.scenes.outputs(materials)
            + self.scenes.scan_outputs(materials)
            + self.study.outputs(materials)
            + self.retries(materials)
        )
        return list(dict.fromkeys(everything))  # once each, in order

    def virtual_experiment(self) -> list[str]:
        """The truth of every synthetic sphere: its virtual experiment is written whole."""
        return [
            f"{self.paths.synthetic_sphere(s)}/{files.TRUTH}"
            for s in self.spheres
            if self.spheres.rows.is_synthetic(s)
        ]
