"""The study's jobs (docs/study.md): per sphere, the figures its scans and scenes allow
(Figs. B.8, B.9, B.11, B.12) and their inputs; per material, the model table; across
materials, Figs. B.10 (curvature pairs) and B.13."""

from __future__ import annotations

from collections.abc import Mapping

from amontons.models import CONTACT_HARDENING, ELASTIC, GREENWOOD_TRIPP
from amontons.workflow import paths as files
from amontons.workflow.optional_inputs import AFM_AFTER, RHEOMETER
from amontons.workflow.paths import RunPaths, figure_files
from amontons.workflow.scenes import Scenes
from amontons.workflow.spheres import Spheres

# The scanned parameter of Figs. B.9 and B.11.
K = CONTACT_HARDENING.parameter.key


class Study:
    """The study's figures and tables of a run, from its scenes, scans and curvature pairs."""

    def __init__(self, config: Mapping, spheres: Spheres, scenes: Scenes, paths: RunPaths):
        study = config["study"]
        self.curvature_pairs = {
            name: study["curvature_pairs"][name] for name in study["run_curvature_pairs"]
        }
        self.materials = list(config["materials"])
        self.spheres = spheres
        self.scenes = scenes
        self.paths = paths

    def k_scan(self, wildcards) -> dict:
        """The files of the sphere's first k scan (figures B.9 and B.11)."""
        scan = self.scenes.scans_of(K)[0]
        return self.scenes.scan_files(wildcards.material, wildcards.sphere, scan)

    def scan_maps(self, wildcards) -> dict[str, dict]:
        """Fig. B.8's inputs: every scan's files of the sphere."""
        return {
            scan: self.scenes.scan_files(wildcards.material, wildcards.sphere, scan)
            for scan in self.scenes.scans
        }

    def load_series_layout(self, wildcards) -> dict:
        """Fig. B.11's inputs: the elastic scene's rendered loads and registration, the
        Greenwood–Tripp solve and the k scan."""
        where = (wildcards.material, wildcards.sphere)
        elastic = self.scenes.first(ELASTIC.name, "microscope")
        gt = self.scenes.first(GREENWOOD_TRIPP.name)
        return {
            ELASTIC.name: {
                "rendered": self.paths.scene(files.RENDERED, *where, elastic),
                "registration": self.paths.scene(files.REGISTRATION, *where, elastic),
            },
            "gt_solve": self.paths.scene(files.SOLVE, *where, gt),
            "k_scan": self.k_scan(wildcards),
        }

    def load_series_elastic(self, wildcards) -> dict:
        """Fig. B.11's elastic scene: its rendered loads and registration."""
        return self.load_series_layout(wildcards)[ELASTIC.name]

    def _compared_files(self, material: str, sphere: str, scene: str) -> dict:
        """A scene's solve and, with optics, its comparison."""
        where = (material, sphere, scene)
        found = {"solve": self.paths.scene(files.SOLVE, *where)}
        if self.scenes.has_optics(scene):
            found["comparison"] = self.paths.scene(files.COMPARISON, *where)
        return found

    def _best_values(self, material: str, sphere: str) -> dict[str, str]:
        return {
            scan: self.paths.scan(files.BEST, material, sphere, scan) for scan in self.scenes.scans
        }

    def model_curve_layout(self, wildcards) -> dict:
        """Fig. B.12's inputs: each AFM scene's areas and each scan's best value."""
        where = (wildcards.material, wildcards.sphere)
        scenes = {
            scene: self.scenes.area_files(*where, scene)
            for scene in self.scenes.runnable(wildcards.sphere)
        }
        return {"scenes": scenes, "scans": self._best_values(*where)}

    def model_table_layout(self, material: str) -> dict:
        """The model table's inputs per sphere: its measured fit, its scenes' fits file (a
        scanned sphere runs its microscope scenes), each scene's solve and, with optics,
        comparison, and its scans' best values."""
        return {
            sphere: {
                "measured": self.paths.measured(files.LOAD_AREA_FIT, material, sphere),
                "fits": self.scenes.fits_file(material, sphere),
                "scenes": {
                    scene: self._compared_files(material, sphere, scene)
                    for scene in self.scenes.runnable(sphere)
                },
                "scans": self._best_values(material, sphere),
            }
            for sphere in self.scanned(material)
        }

    def scanned(self, material: str) -> list[str]:
        """The spheres of ``material`` whose scans run (the model table's rows)."""
        return [s for s in self.spheres.of(material) if self.scenes.runnable_scans(s)]

    def curvature_files(self, name: str) -> dict[str, str]:
        """File ``name`` of every scene of the running curvature pairs (Fig. B.10)."""
        return {
            scene: self.paths.synthetic_scene(name, scene)
            for pair in self.curvature_pairs.values()
            for scene in pair
        }

    def k_bests(self, materials) -> dict[str, str]:
        """Each sphere's best k of its first k scan (Fig. B.13); none without a k scan."""
        if not self.scenes.scans_of(K):
            return {}
        scan = self.scenes.scans_of(K)[0]
        return {
            sphere: self.paths.scan(files.BEST, material, sphere, scan)
            for material in materials
            for sphere in self.scanned(material)
        }

    def sphere_figures(self, material: str, sphere: str) -> list[str]:
        """The study's figures of one sphere that its scans and scenes allow."""
        names = []
        if self.scenes.runnable_scans(sphere):
            names += ["B8_scans", files.B12_FIGURE]
        if self.scenes.scans_of(K) and self.scenes.runnable_scans(sphere):
            if self.spheres.inputs.has(sphere, AFM_AFTER):
                names.append("B9_flattening")
            runs = self.scenes.runnable(sphere)
            elastic = self.scenes.first(ELASTIC.name, "microscope")
            gt = self.scenes.first(GREENWOOD_TRIPP.name)
            if elastic in runs and gt in runs:
                names.append("B11_load_series")
        folder = self.paths.study(material, sphere)
        return [path for name in names for path in figure_files(folder, name)]

    def outputs(self, materials) -> list[str]:
        """The study's outputs of ``materials``: per-sphere figures and each material's model
        table (with scans)."""
        out = []
        for material in materials:
            for sphere in self.spheres.of(material):
                out += self.sphere_figures(material, sphere)
            if self.scanned(material):
                out.append(f"{self.paths.material(material)}/{files.MODELS_TABLE}")
        return out

    def overview_outputs(self) -> list[str]:
        """The study's figures across materials: Fig. B.13 (with scans) and Fig. B.10 (with
        curvature pairs); built by `all` and `study`, not by a material's target."""
        out = []
        if self.scenes.scans and self.spheres.materials_with(self.materials, RHEOMETER):
            out += figure_files(self.paths.study_results, files.B13_FIGURE)
        if self.curvature_pairs:
            out += figure_files(self.paths.study_results, files.B10_FIGURE)
        return out
