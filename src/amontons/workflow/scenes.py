"""The expansion of scenes and scans into jobs (docs/simulate.md, docs/study.md): a scene on
a sphere's AFM map runs for every selected sphere; a synthetic scene runs once and reads
nothing of the experiment; a sphere's scan is one job, which solves its values one after
another. Only what a scene names is scheduled: its comparison files exist only with
optics."""

from __future__ import annotations

from collections.abc import Mapping

from amontons.config import geometry
from amontons.config.scenes import sheet_prior
from amontons.io.pixel_probe import tiff_scan_side_m
from amontons.models import ELASTIC, FIELD, model_named, parameter_named
from amontons.simulate.scan_grid import scan_values, value_label
from amontons.workflow import paths as files
from amontons.workflow.optional_inputs import AFM_BEFORE
from amontons.workflow.params import sorted_keys
from amontons.workflow.paths import FilesInFolder, RunPaths
from amontons.workflow.spheres import Spheres

# A scan's values run in its parameter's chain order (amontons.models), each starting from
# the one before: per parameter, the order that took fewer CG iterations on the virtual PS
# and PMMA-4mm spheres (benchmarks/bench_scan_warm_start.py; docs/study.md §1, "Warm-started
# values").

# AFM formats whose scan size the DAG reads from the header (amontons.io.pixel_probe).
HEADER_SIZED_AFM = (".tif", ".tiff")


def outside_scan_lines(scene: str, coverage: dict, side_um: float) -> list[str]:
    """What a scene leaves out of a scan of ``side_um`` (its :meth:`Scenes.scan_coverage`
    entry), one line per load, or one line where it simulates none."""
    lines = [
        f"scene {scene}: {row['load_mn']:g} mN outside_scan (its window of "
        f"{row['window_um']:.1f} µm exceeds the {side_um:.1f} µm scan)"
        for row in coverage["outside_scan"]
    ]
    if not coverage["simulated_mn"]:
        lines.append(f"scene {scene}: the AFM scan holds no load's window; nothing simulated")
    elif coverage.get("clipped_from_um") is not None:
        lines.append(
            f"scene {scene}: window clipped from {coverage['clipped_from_um']:.1f} µm to the "
            f"{side_um:.1f} µm scan for {', '.join(f'{f:g}' for f in coverage['simulated_mn'])}"
            " mN (their contacts fit with the solver's margin; one that reaches the edge is "
            "left out)"
        )
    return lines


class Scenes:
    """The running scenes (config ``run_scenes``) and scans (``run_scans``) of a run."""

    def __init__(self, config: Mapping, spheres: Spheres, paths: RunPaths):
        self.scenes = {name: config["scenes"][name] for name in config["run_scenes"]}
        self.scans = {name: config["scans"][name] for name in config["run_scans"]}
        self.spheres = spheres
        self.paths = paths

    # scenes

    def names(self, surface=None, model=None, optics=None, field=None) -> list[str]:
        """Names of the scenes with the given surface, model and optics; ``field``: True for
        the scenes whose solver gives fields (every model but Greenwood–Tripp), False for GT.
        """
        names = []
        for name, scene in self.scenes.items():
            if surface is not None and scene["surface"] != surface:
                continue
            if model is not None and scene["model"] != model:
                continue
            if optics is not None and scene["optics"] != optics:
                continue
            if field is not None and (model_named(scene["model"]).kind == FIELD) != field:
                continue
            names.append(name)
        return names

    def afm_scenes(self) -> list[str]:
        """The scenes on a sphere's AFM map."""
        return self.names(surface="afm_before")

    def has_optics(self, scene: str) -> bool:
        return self.scenes[scene]["optics"] == "microscope"

    def config(self, scene: str) -> dict:
        """A scene's config entry, as a rule's params (a changed scene re-runs only its
        jobs)."""
        return sorted_keys(self.scenes[scene])

    def models(self) -> dict[str, str]:
        """Each running scene's model."""
        return {name: scene["model"] for name, scene in self.scenes.items()}

    def first(self, model: str, optics: str | None = None) -> str | None:
        """The first running AFM scene of ``model`` (and ``optics``), or None."""
        names = self.names(surface="afm_before", model=model, optics=optics)
        return names[0] if names else None

    def missing_prior(self, sphere: str, scene: str) -> tuple[str, str] | None:
        """(key, sheet column) where ``scene`` takes its model parameter from a sheet cell that
        ``sphere`` leaves empty; None where it has what it needs."""
        needs = sheet_prior(self.scenes[scene])
        if needs is None or self.spheres.rows.row(sphere).get(needs[1]) is not None:
            return None
        return needs

    def runnable(self, sphere: str) -> list[str]:
        """The AFM scenes a sphere's data allow: its map before the loads for each, a PSF for
        those rendered like the microscope, and the sheet's value of the model parameter for
        those that take it from there (never invented)."""
        return [
            scene
            for scene in self.afm_scenes()
            if self.spheres.inputs.can_simulate(sphere)
            and (not self.has_optics(scene) or self.spheres.inputs.can_render(sphere))
            and self.missing_prior(sphere, scene) is None
        ]

    def sphere_registration_scene(self, sphere: str) -> str | None:
        """The scene a sphere's AFM frame is registered on the microscope's once (docs/simulate.md,
        "Compare"): its first running microscope scene (the elastic scene in the configs); None
        where it runs none."""
        runs = [s for s in self.runnable(sphere) if self.has_optics(s)]
        return runs[0] if runs else None

    def sphere_registration(self, wildcards) -> list[str]:
        """What a scene's comparison registers by: the sphere's registration, found on
        :meth:`sphere_registration_scene` (nothing for that scene itself, which finds it)."""
        scene = self.sphere_registration_scene(wildcards.sphere)
        if scene is None or scene == wildcards.scene:
            return []
        return [self.paths.scene(files.REGISTRATION, wildcards.material, wildcards.sphere, scene)]

    def registration_scene(self, sphere: str, scan: str) -> str | None:
        """The scene whose registration a sphere's scan is judged under: its base scene, or,
        where the sphere does not run it (no prior), its first microscope scene; None where it
        runs none."""
        runs = [s for s in self.runnable(sphere) if self.has_optics(s)]
        base = self.scans[scan]["scene"]
        return base if base in runs else (runs[0] if runs else None)

    def runnable_scans(self, sphere: str) -> list[str]:
        """The scans a sphere's data allow: each registers on a microscope scene."""
        return [scan for scan in self.scans if self.registration_scene(sphere, scan)]

    def scan_coverage(self, sphere: str, side_um: float) -> dict[str, dict]:
        """Per scene that solves on the sphere's map: the loads (mN) its window keeps inside
        an AFM scan of ``side_um`` and those left out (``outside_scan``), with the apex taken
        at the scan's centre. The run fits the apex; one off centre holds a smaller window, so
        the run may leave out more (amontons.simulate.surface.afm_scene)."""
        record = self.spheres.rows.scene_record(sphere)
        coverage = {}
        for scene in self.runnable(sphere):
            spec = self.scenes[scene]
            if model_named(spec["model"]).kind != FIELD:
                continue  # mean-field: no window on the map
            frame = geometry.sphere_frame(spec, record)
            cut = geometry.frame_in_scan(scene, spec, frame, side_um * 1e-6)
            coverage[scene] = {
                "simulated_mn": [f * 1e3 for f in cut.frame.loads_n],
                "outside_scan": [load.to_record() for load in cut.left_out],
                "clipped_from_um": None if cut.clipped_from_m is None else cut.clipped_from_m * 1e6,
            }
        return coverage

    def header_scan_side_um(self, sphere: str) -> float | None:
        """The shorter side (µm) of a measured sphere's AFM scan where its header gives it
        cheaply (a TIFF: amontons.io.pixel_probe; the sheet's afm_pixel_nm where the file
        states no pixel); None otherwise, the job then reading the scan."""
        if self.spheres.rows.is_synthetic(sphere) or not self.spheres.inputs.can_simulate(sphere):
            return None
        path = self.spheres.files.afm_path(sphere, AFM_BEFORE)
        if not path.lower().endswith(HEADER_SIZED_AFM):
            return None
        sheet_nm = self.spheres.rows.value(sphere, "afm_pixel_nm")
        side_m = tiff_scan_side_m(path, None if sheet_nm is None else sheet_nm * 1e-9)
        return None if side_m is None else side_m * 1e6

    def predicted_outside_scan(self, sphere: str) -> list[str]:
        """The loads each scene will leave outside the sphere's AFM scan, where its size is
        read at DAG time (:meth:`header_scan_side_um`), with the apex at the scan's centre."""
        side_um = self.header_scan_side_um(sphere)
        if side_um is None:
            return []
        coverage = self.scan_coverage(sphere, side_um)
        return [
            f"{line}; apex taken at the scan's centre"
            for scene, entry in coverage.items()
            for line in outside_scan_lines(scene, entry, side_um)
        ]

    def left_out(self, sphere: str) -> list[str]:
        """What a sphere without a prior does not get (the scenes at the sheet's value), and
        how its scans run instead."""
        lines = []
        for scene in self.afm_scenes():
            needs = self.missing_prior(sphere, scene)
            if needs is not None and self.spheres.inputs.can_simulate(sphere):
                lines.append(
                    f"no {needs[1]} in the sheet: scene {scene} ({needs[0]} null, at the "
                    "sheet's value) will not be made"
                )
        for scan, spec in self.scans.items():
            if self.prior(sphere, scan) is None and scan in self.runnable_scans(sphere):
                low, high = spec["prior_free_range"]
                parameter = parameter_named(spec["parameter"])
                lines.append(
                    f"no {parameter.sheet_column} in the sheet: scan {scan} runs over "
                    f"its prior-free range ({parameter.prior_free_scale} {low:g} to "
                    f"{high:g}, {spec['prior_free_steps']} values)"
                )
        return lines

    def sphere_scene_outputs(self, material: str, sphere: str, scene: str) -> list[str]:
        """What a scene of one sphere delivers beside the sphere's fits (:meth:`fits_file`):
        with optics, its comparison; without, nothing more."""
        if not self.has_optics(scene):
            return []
        folder = self.paths.scene("", material, sphere, scene)
        return [
            *files.figure_files(folder, files.COMPARISON_FIGURE),
            f"{folder}/{files.REGISTRATION}",
        ]

    def fits_file(self, material: str, sphere: str) -> str:
        """The load-area fits of every scene of one sphere, in one file (scene → fit)."""
        return self.paths.sphere_scenes(files.SCENE_FITS, material, sphere)

    def outputs(self, materials) -> list[str]:
        """Every AFM scene of every sphere of ``materials``, each sphere's fits and each
        material's scene table."""
        out = []
        for material in materials:
            for sphere in self.spheres.of(material):
                scenes = self.runnable(sphere)
                for scene in scenes:
                    out += self.sphere_scene_outputs(material, sphere, scene)
                if scenes:
                    out.append(self.fits_file(material, sphere))
            if self.table_layout(material):
                out.append(f"{self.paths.material(material)}/scenes.csv")
        return out

    def synthetic_outputs(self) -> list[str]:
        return [
            self.paths.synthetic_scene(files.SCENE_FITS, s) for s in self.names(surface="synthetic")
        ]

    def area_files(self, material: str, sphere: str, scene: str) -> dict[str, str]:
        """A scene's areas per load: its solve and, with optics, its rendered areas."""
        where = (material, sphere, scene)
        found = {"solve": self.paths.scene(files.SOLVE, *where)}
        if self.has_optics(scene):
            found["render"] = self.paths.scene(files.RENDER_TABLE, *where)
        return found

    def fit_layout(self, material: str, sphere: str) -> dict[str, dict[str, str]]:
        """What one sphere's fits read: each scene's :meth:`area_files`."""
        return {scene: self.area_files(material, sphere, scene) for scene in self.runnable(sphere)}

    def synthetic_fit_layout(self, scene: str) -> dict[str, dict[str, str]]:
        """What a synthetic scene's fit reads: its solve (a synthetic scene has no optics)."""
        return {scene: {"solve": self.paths.synthetic_scene(files.SOLVE, scene)}}

    def table_layout(self, material: str) -> dict[str, str]:
        """The scene table's inputs: the fits of each sphere of ``material`` that runs a
        scene (sphere → its fits file)."""
        return {
            sphere: self.fits_file(material, sphere)
            for sphere in self.spheres.of(material)
            if self.runnable(sphere)
        }

    # scans

    def scans_of(self, parameter: str) -> list[str]:
        """The running scans of ``parameter`` (a parameter's config key, amontons.models)."""
        return [name for name, spec in self.scans.items() if spec["parameter"] == parameter]

    def prior(self, sphere: str, scan: str) -> float | None:
        """The sheet's value a sphere's scan is centred on, or None (no prior)."""
        column = parameter_named(self.scans[scan]["parameter"]).sheet_column
        return self.spheres.rows.value(sphere, column)

    def prior_free_scale(self, sphere: str, scan: str) -> float:
        """The scale (in the parameter's config unit) that makes a scan's prior-free range
        dimensionless on a sphere: E* (MPa) for p_Y, E*/Δx (MPa/nm) for k, Δx the solver
        pixel of the scan's base scene on that sphere (amontons.config.geometry)."""
        spec = self.scans[scan]
        parameter = parameter_named(spec["parameter"])
        base = self.scenes[spec["scene"]]
        frame = geometry.sphere_frame(base, self.spheres.rows.row(sphere))
        if parameter.prior_free_pixel_power == 0:
            return frame.e_star_pa * parameter.from_si
        window = geometry.window_m(spec["scene"], base, frame)
        pixel = geometry.solver_pixel_m(base, window)
        return frame.e_star_pa / pixel**parameter.prior_free_pixel_power * parameter.from_si

    def scan_params(self, sphere: str, scan: str) -> dict:
        """A scan's config as a scan job's params: the keys of the range its sphere is scanned
        over (about the prior, or prior-free), so that a changed range of the other kind
        re-runs none of its jobs."""
        unused = ("prior_free_range", "prior_free_steps")
        if self.prior(sphere, scan) is None:
            unused = ("range_factor", "steps")
        return sorted_keys({k: v for k, v in self.scans[scan].items() if k not in unused})

    def scan_value_labels(self, sphere: str, scan: str) -> list[str]:
        """The folder names of a scan's values for one sphere: range_factor × its sheet
        value, or, without one, prior_free_range × the sphere's scale
        (:meth:`prior_free_scale`)."""
        spec = self.scans[scan]
        prior = self.prior(sphere, scan)
        if prior is not None:
            values = scan_values(prior, spec["range_factor"], spec["steps"], spec["spacing"])
        else:
            scale = self.prior_free_scale(sphere, scan)
            values = scan_values(
                scale, spec["prior_free_range"], spec["prior_free_steps"], spec["spacing"]
            )
        return [value_label(v) for v in values]

    def scan_chain(self, sphere: str, scan: str) -> list[str]:
        """A scan's values in the order its job solves them (its parameter's chain order,
        amontons.models), each starting from the one before (amontons.simulate.scan_start)."""
        labels = sorted(self.scan_value_labels(sphere, scan), key=float)
        return labels[::-1] if self.chain_order(scan) < 0 else labels

    def chain_order(self, scan: str) -> int:
        """+1 where a scan solves its values from the smallest up, -1 from the largest down."""
        return parameter_named(self.scans[scan]["parameter"]).chain_order

    def scan_seed_scene(self, sphere: str, scan: str) -> str | None:
        """The scene whose pressures start a scan's first value (amontons.simulate.scan_start):
        where the chain starts at the scan's elastic end (the largest value), the sphere's
        first running elastic scene on its map; None where it starts at the other end or the
        sphere runs no elastic scene. The elastic scene's comparison registers the sphere,
        which the scan waits for already: its fields cost the scan no wait."""
        if self.chain_order(scan) > 0:
            return None
        return self.sphere_elastic_scene(sphere)

    def sphere_elastic_scene(self, sphere: str) -> str | None:
        """The sphere's first running elastic scene on its map, or None."""
        elastic = [s for s in self.runnable(sphere) if self.scenes[s]["model"] == ELASTIC.name]
        return elastic[0] if elastic else None

    def scan_seed_fields(self, wildcards) -> list[str]:
        """The fields file of :meth:`scan_seed_scene` (a scan job's input), or nothing."""
        scene = self.scan_seed_scene(wildcards.sphere, wildcards.scan)
        if scene is None:
            return []
        return [self.paths.scene(files.FIELDS, wildcards.material, wildcards.sphere, scene)]

    def scan_values_folder(self, wildcards) -> str:
        """The folder a scan job writes every value's files into (its output)."""
        return self.paths.scan_values(wildcards.material, wildcards.sphere, wildcards.scan)

    def scan_value_files(self, wildcards) -> list[dict]:
        """A scan job's values in the order it solves them (:meth:`scan_chain`), each with
        the paths of its result (``point``) and rendered fields (``rendered``)."""
        where = (wildcards.material, wildcards.sphere, wildcards.scan)
        return [
            {
                "value": value,
                "point": self.paths.scan_value(files.SCAN_POINT, *where, value),
                "rendered": self.paths.scan_value(files.RENDERED, *where, value),
            }
            for value in self.scan_chain(wildcards.sphere, wildcards.scan)
        ]

    def scan_points(self, wildcards) -> list[str]:
        """Every value's result of one sphere's scan, in the scan job's folder
        (:meth:`scan_values_folder`)."""
        where = (wildcards.material, wildcards.sphere, wildcards.scan)
        return [
            self.paths.scan_value(files.SCAN_POINT, *where, value)
            for value in self.scan_value_labels(wildcards.sphere, wildcards.scan)
        ]

    def scan_base_registration(self, wildcards) -> str:
        """The registration a scan is judged under on its sphere (:meth:`registration_scene`)."""
        scene = self.registration_scene(wildcards.sphere, wildcards.scan)
        return self.paths.scene(files.REGISTRATION, wildcards.material, wildcards.sphere, scene)

    def scan_outputs(self, materials) -> list[str]:
        """Every scan of every sphere of ``materials``: its table and best value."""
        return [
            self.paths.scan(name, material, sphere, scan)
            for material in materials
            for sphere in self.spheres.of(material)
            for scan in self.runnable_scans(sphere)
            for name in (files.SCAN_TABLE, files.BEST)
        ]

    def scan_files(self, material: str, sphere: str, scan: str) -> dict:
        """What the study's figures read of one sphere's scan: its judgement, every value's
        rendered fields and its base scene's registration."""
        where = (material, sphere, scan)
        return {
            "best": self.paths.scan(files.BEST, *where),
            "table": self.paths.scan(files.SCAN_TABLE, *where),
            "rendered": FilesInFolder(
                self.paths.scan_values(*where),
                [
                    self.paths.scan_value(files.RENDERED, *where, v)
                    for v in self.scan_value_labels(sphere, scan)
                ],
            ),
            "registration": self.paths.scene(
                files.REGISTRATION, material, sphere, self.registration_scene(sphere, scan)
            ),
        }
