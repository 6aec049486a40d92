"""The run's answer (docs/study.md §6): the verdict table of every material with scans, the
headline numbers with the files they come from (results/<run>/summary.md), and the report's
first page (the verdict, then Figs. B.13 and B.12). Built from what the data allow: a sphere
without scans has no verdict row, a material without friction no Amontons table, and the
summary lists what each sphere's data did not allow, and why."""

from __future__ import annotations

from amontons.workflow import paths as files
from amontons.workflow.optional_inputs import RHEOMETER
from amontons.workflow.paths import RunPaths
from amontons.workflow.scenes import Scenes
from amontons.workflow.spheres import Spheres
from amontons.workflow.study import Study


class Summary:
    """What the summary rules read and write."""

    def __init__(self, materials, spheres: Spheres, scenes: Scenes, study: Study, paths: RunPaths):
        self.materials = list(materials)
        self.spheres = spheres
        self.scenes = scenes
        self.study = study
        self.paths = paths

    @property
    def summary(self) -> str:
        return f"{self.paths.results}/{files.RUN_SUMMARY}"

    @property
    def verdict(self) -> str:
        return f"{self.paths.results}/{files.VERDICT}"

    @property
    def report_page(self) -> str:
        return f"{self.paths.results}/{files.REPORT_PAGE}"

    def verdict_inputs(self) -> dict[str, str]:
        """Each model table (models.csv), by material: the materials with a scanned sphere."""
        return {
            m: f"{self.paths.material(m)}/{files.MODELS_TABLE}"
            for m in self.materials
            if self.study.scanned(m)
        }

    def layout(self) -> dict:
        """What summary.md reads: per sphere its load-area fit and its scans' best values,
        per material with friction its Amontons table, the verdict and the model tables it
        copies (with scans), and Fig. B.10's table (with curvature pairs)."""
        spheres = [(m, s) for m in self.materials for s in self.spheres.of(m)]
        verdict = self.verdict_inputs()
        return {
            "fits": {s: self.paths.measured(files.LOAD_AREA_FIT, m, s) for m, s in spheres},
            "bests": {
                s: {
                    scan: self.paths.scan(files.BEST, m, s, scan)
                    for scan in self.scenes.runnable_scans(s)
                }
                for m, s in spheres
            },
            "amontons": {
                m: f"{self.paths.material(m)}/{files.AMONTONS_TABLE}"
                for m in self.spheres.materials_with(self.materials, RHEOMETER)
            },
            "verdict": self.verdict if verdict else None,
            "models": verdict,
            "curvature": (
                f"{self.paths.study_results}/{files.B10_FIGURE}.csv"
                if self.study.curvature_pairs
                else None
            ),
        }

    def report_figures(self) -> dict[str, str]:
        """The figures the report's first page shows, in order, with their captions: Fig.
        B.13, then each scanned sphere's Fig. B.12."""
        figures = {}
        b13 = f"{self.paths.study_results}/{files.B13_FIGURE}.png"
        if b13 in self.study.overview_outputs():
            figures[b13] = "Fig. B.13, every material"
        for m in self.materials:
            for s in self.study.scanned(m):
                figures[f"{self.paths.study(m, s)}/{files.B12_FIGURE}.png"] = f"Fig. B.12, {s}"
        return figures

    def outputs(self) -> list[str]:
        """What `all` builds of the summary: the summary always, the verdict and the report's
        first page where a sphere was scanned."""
        return [self.summary] + ([self.verdict, self.report_page] if self.verdict_inputs() else [])
