"""Where a run writes: one path provider for every folder and every file that more than one
rule names (docs/results.md). Rules declare their outputs through it, and input functions
reach another rule's output through it, so that no path is typed twice.

Every run writes under its own name (config ``run``), so that the small data set never
overwrites the full reproduction: the virtual experiment's raw data, results and logs. Each
method returns a Snakemake pattern (``{material}``, ``{sphere}``, ... left as wildcards) when
called without those arguments, and a concrete path when given them.
"""

from __future__ import annotations

from dataclasses import dataclass

MATERIAL = "{material}"
SPHERE = "{sphere}"
SCENE = "{scene}"
SCAN = "{scan}"

# Files that one rule writes and another rule, or a target, reads: named once, here.
LEVELLED_MAP = "afm_before_levelled.h5"
BEFORE_FIT = "afm_before_fit.h5"  # the levelled map's sphere fit, the topography's before fit
SPHERE_FITS = "topography_fits.h5"  # both AFM scans' sphere fits, to level them again
CONTACT_AREA = "contact_area.csv"
PSF = "psf.json"
LOAD_AREA_FIT = "load_area_fit.json"
LIFETIME = "lifetime.json"
FRICTION = "friction.csv"
SOLVE = "solve.json"
FIELDS = "fields.h5"
RENDERED = "rendered.h5"
RENDER_TABLE = "render.csv"
COMPARISON_FIGURE = "comparison"  # its table is COMPARISON
COMPARISON = f"{COMPARISON_FIGURE}.csv"
REGISTRATION = "registration.json"
# The scenes' load-area fits (scene name → fit): one file per sphere, one per synthetic scene.
SCENE_FITS = "scene_fits.json"
SCAN_POINT = "scan_point.json"
SCAN_TABLE = "scan.csv"
BEST = "best.json"
# A scan job's judgement inputs beyond its grid: the model's error and the refined values.
REFINEMENT = "refinement.json"
TRUTH = "truth.json"
ACCURACY_SUMMARY = "summary.json"
MODELS_TABLE = "models.csv"
AMONTONS_FIGURE = "amontons"  # its table is AMONTONS_TABLE
AMONTONS_TABLE = f"{AMONTONS_FIGURE}.csv"
B12_FIGURE = "B12_models"
B13_FIGURE = "B13_amontons"
B10_FIGURE = "B10_curvature"
# The run's answer (docs/study.md §6), in results/<run>/.
RUN_SUMMARY = "summary.md"
VERDICT = "verdict.csv"
REPORT_PAGE = "report_first_page.rst"
ACCURACY_FIELDS = "pressure.h5"
# A figure of the study or of a material: its PNG, its PDF and the CSV of what it shows.
FIGURE_FORMATS = ("png", "pdf", "csv")


@dataclass(frozen=True)
class RunPaths:
    """The folders and shared files of the run named ``run``, relative to the working
    directory."""

    run: str

    @property
    def results(self) -> str:
        return f"results/{self.run}"

    @property
    def logs(self) -> str:
        return f"logs/{self.run}"

    @property
    def synthetic(self) -> str:
        """The virtual experiment's raw data: one folder per synthetic sphere."""
        return f"resources/synthetic/{self.run}"

    def synthetic_sphere(self, sphere: str = SPHERE) -> str:
        return f"{self.synthetic}/{sphere}"

    def material(self, material: str = MATERIAL) -> str:
        """One material's figures and tables."""
        return f"{self.results}/{material}"

    def material_logs(self, material: str = MATERIAL) -> str:
        return f"{self.logs}/{material}"

    def measured(self, name: str = "", material: str = MATERIAL, sphere: str = SPHERE) -> str:
        """One sphere's measurement ``name`` (its folder where ``name`` is empty)."""
        return _join(f"{self.results}/{material}/{sphere}/measure", name)

    def sphere_logs(self, material: str = MATERIAL, sphere: str = SPHERE) -> str:
        return f"{self.logs}/{material}/{sphere}"

    def scene(
        self, name: str = "", material: str = MATERIAL, sphere: str = SPHERE, scene: str = SCENE
    ) -> str:
        """File ``name`` of a scene on one sphere's AFM map (its folder where ``name`` is
        empty)."""
        return _join(f"{self.results}/{material}/{sphere}/scenes/{scene}", name)

    def scene_logs(self, material: str = MATERIAL, sphere: str = SPHERE, scene: str = SCENE):
        return f"{self.logs}/{material}/{sphere}/scenes/{scene}"

    def sphere_scenes(self, name: str = "", material: str = MATERIAL, sphere: str = SPHERE):
        """File ``name`` of all of one sphere's scenes together, beside their folders (the
        folder of the scenes where ``name`` is empty)."""
        return _join(f"{self.results}/{material}/{sphere}/scenes", name)

    def sphere_scenes_logs(self, material: str = MATERIAL, sphere: str = SPHERE) -> str:
        return f"{self.logs}/{material}/{sphere}/scenes"

    def synthetic_scene(self, name: str = "", scene: str = SCENE) -> str:
        """File ``name`` of a scene on a synthetic surface (run once, for no sphere)."""
        return _join(f"{self.results}/synthetic/scenes/{scene}", name)

    def synthetic_scene_logs(self, scene: str = SCENE) -> str:
        return f"{self.logs}/synthetic/scenes/{scene}"

    def scan(
        self, name: str = "", material: str = MATERIAL, sphere: str = SPHERE, scan: str = SCAN
    ) -> str:
        """File ``name`` of one sphere's scan (its folder where ``name`` is empty)."""
        return _join(f"{self.results}/{material}/{sphere}/scans/{scan}", name)

    def scan_value(self, name: str, material: str, sphere: str, scan: str, value: str) -> str:
        """File ``name`` of one value of a scan, in the scan job's folder of values
        (:meth:`scan_values`)."""
        return f"{self.scan_values(material, sphere, scan)}/{value}/{name}"

    def scan_values(self, material: str = MATERIAL, sphere: str = SPHERE, scan: str = SCAN):
        """The folder a scan job writes its values into, one folder per value: the job's
        output, apart from the scan's judgement beside it."""
        return self.scan("values", material, sphere, scan)

    def scan_logs(self, material: str = MATERIAL, sphere: str = SPHERE, scan: str = SCAN):
        return f"{self.logs}/{material}/{sphere}/scans/{scan}"

    def study(self, material: str = MATERIAL, sphere: str = SPHERE) -> str:
        """One sphere's study figures."""
        return f"{self.results}/{material}/{sphere}/study"

    def study_logs(self, material: str = MATERIAL, sphere: str = SPHERE) -> str:
        return f"{self.logs}/{material}/{sphere}/study"

    @property
    def study_results(self) -> str:
        """The study's figures across materials (Figs. B.10 and B.13)."""
        return f"{self.results}/study"

    @property
    def accuracy(self) -> str:
        return f"{self.results}/accuracy"

    @property
    def accuracy_logs(self) -> str:
        return f"{self.logs}/accuracy"

    def accuracy_setting(self, name: str, problem: str, setting: str) -> str:
        """File ``name`` of one problem of the accuracy study at one setting."""
        return f"{self.accuracy}/{problem}/{setting}/{name}"

    def timing_point(self, point: str) -> str:
        return f"{self.accuracy}/timing/{point}/{ACCURACY_SUMMARY}"

    @property
    def validation(self) -> str:
        """The validation study's tables, summary and figure (docs/study.md §7)."""
        return f"{self.results}/validation"

    @property
    def validation_logs(self) -> str:
        return f"{self.logs}/validation"

    def validation_case(self, case: str) -> str:
        """One validation case's record."""
        return f"{self.validation}/cases/{case}.json"


def figure_files(folder: str, name: str) -> list[str]:
    """A figure ``name`` in ``folder``: its PNG, PDF and CSV."""
    return [f"{folder}/{name}.{ext}" for ext in FIGURE_FORMATS]


class FilesInFolder(list):
    """Files that one job writes inside its output folder (a Snakemake ``directory()``, such
    as a scan's values): a list of their paths for the script that reads them, and as an
    input (:func:`flat_files`) the folder, since Snakemake knows no rule for a file inside
    another rule's output folder."""

    def __init__(self, folder: str, paths: list[str]):
        super().__init__(paths)
        self.folder = folder


def flat_files(layout) -> list[str]:
    """Every path in a nested dict/list layout of paths, in order, as a rule's inputs: the
    folder of a :class:`FilesInFolder` in its files' place."""
    if isinstance(layout, FilesInFolder):
        return [layout.folder]
    if isinstance(layout, dict):
        return [p for value in layout.values() for p in flat_files(value)]
    if isinstance(layout, list):
        return [p for value in layout for p in flat_files(value)]
    return [layout]


def _join(folder: str, name: str) -> str:
    return f"{folder}/{name}" if name else folder
