"""What each target builds (README: `snakemake PS`, `snakemake optics`, ...): every output of
a stage per sphere and per material, collected from the per-sphere result names below and
from the scenes, scans and study of the run."""

from __future__ import annotations

from amontons.workflow import paths as files
from amontons.workflow.paths import RunPaths, figure_files
from amontons.workflow.scenes import Scenes
from amontons.workflow.spheres import Spheres
from amontons.workflow.study import Study

# Per-sphere results of each stage; lifetime only where a FLIM map exists.
OPTICS_RESULTS = (
    files.CONTACT_AREA,
    "contact_area.png",
    "contact_area.pdf",
    files.PSF,
    "psf.png",
    "psf.pdf",
    "grafting_density.json",
    "absorbance.png",
    "absorbance.pdf",
    "edge_gap.json",
    "edge_gap.png",
    "edge_gap.pdf",
    "intensity_pressure.csv",
    "intensity_pressure_fit.json",
    "intensity_pressure.png",
    "intensity_pressure.pdf",
    "hertz_check.csv",
)
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
        if self.spheres.material_of(sphere) != material:
            raise ValueError(
                f"sphere {sphere!r} is {self.spheres.material_of(sphere)}, not {material}"
            )
        return self.paths.measured(name, material, sphere)

    def per_sphere(self, material: str, name: str) -> list[str]:
        """One measurement file per sphere of ``material``."""
        return [self.measured(material, s, name) for s in self.spheres.of(material)]

    def sphere_outputs(self, materials, names) -> list[str]:
        return [
            self.measured(m, s, n) for m in materials for s in self.spheres.of(m) for n in names
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
            out += self.sphere_outputs([material], OPTICS_RESULTS)
            out += [
                self.measured(material, s, files.LIFETIME)
                for s in self.spheres.of(material)
                if self.spheres.has_flim(s)
            ]
        return out

    def friction(self, materials) -> list[str]:
        """Friction per sphere and the Amontons-deviation figure and table per material."""
        return self.sphere_outputs(materials, FRICTION_RESULTS) + self.material_figures(
            materials, ["amontons"]
        )

    def surface(self, materials) -> list[str]:
        return self.sphere_outputs(materials, SURFACE_RESULTS)

    def fits(self, materials) -> list[str]:
        return self.sphere_outputs(materials, FIT_RESULTS)

    def figures(self, materials) -> list[str]:
        """The per-material figures and tables: load-area and Amontons deviation."""
        return self.material_figures(materials, ["load_area", "amontons"])

    def material(self, materials) -> list[str]:
        """Everything a material's target builds: every measurement, fit, figure and table."""
        everything = (
            self.optics(materials)
            + self.surface(materials)
            + self.friction(materials)
            + self.fits(materials)
            + self.figures(materials)
            + self.scenes.outputs(materials)
            + self.scenes.scan_outputs(materials)
            + self.study.outputs(materials)
        )
        return list(dict.fromkeys(everything))  # once each, in order

    def virtual_experiment(self) -> list[str]:
        """The truth of every synthetic sphere: its virtual experiment is written whole."""
        return [
            f"{self.paths.synthetic_sphere(s)}/{files.TRUTH}"
            for s in self.spheres
            if self.spheres.is_synthetic(s)
        ]
