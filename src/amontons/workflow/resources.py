"""Cluster resources of each job (docs/cluster.md): each rule's measured wall time and peak
memory (workflow/resources.json, amontons.measured_resources), and for the solves the
accuracy study's timing model (workflow/timing_model.json, docs/accuracy.md §6) in their
FFT grid, loads, tolerance and plastic ratio. The grid is the scene's own
(amontons.config.geometry), so that what a job asks for grows with what it solves."""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from pathlib import Path

from amontons.accuracy.timing import plastic_ratio, predict
from amontons.config import geometry
from amontons.measured_resources import JobResources, mem_mb_of, runtime_min
from amontons.models import model_named, with_parameter
from amontons.workflow.spheres import Spheres

# A job's solves, one after the other, from its wildcards: each (scene, sphere or None for a
# synthetic scene[, scan parameter, scan value])
SolvesOf = Callable[[object], list[tuple]]
# config solver_backend -> what the solve rules add: their resources and their params
GPU_BACKENDS = {"cupy": {"gpu": 1}}


def _parameter_si(model: str, law: Mapping) -> float | None:
    """The SI value of ``model``'s parameter among ``law``'s config values (parameter key ->
    value in the config unit); None for a model without one, or where it is missing or 0."""
    parameter = model_named(model).parameter
    value = None if parameter is None else law.get(parameter.key)
    return value * parameter.to_si if value else None


class SolverBackend:
    """The contact solver's engine of the scene and scan solves (config ``solver_backend``,
    config/README.md): ``cpu`` adds nothing to their jobs, so that they stay as they were; a
    GPU backend (``cupy``) adds the resource ``gpu=1`` (the SLURM executor asks for a GPU)
    and the param ``solver_backend`` their scripts pass to the solver. Nothing here imports
    CuPy: a dry run needs none, a missing one fails the solve job."""

    def __init__(self, config: Mapping):
        self.name = config.get("solver_backend", "cpu")
        gpu = GPU_BACKENDS.get(self.name)
        self.resources = dict(gpu) if gpu else {}
        self.params = {"solver_backend": self.name} if gpu else {}


class SolveResources:
    """What a run's jobs ask for: measured per rule, predicted per solve."""

    def __init__(
        self,
        config: Mapping,
        spheres: Spheres,
        measured: JobResources,
        timing_model: Mapping,
    ):
        self.scenes = config["scenes"]
        self.spheres = spheres
        self.measured = measured
        self.timing_model = timing_model
        self.backend = SolverBackend(config)

    @classmethod
    def from_files(
        cls, config: Mapping, spheres: Spheres, resources: str | Path, timing_model: str | Path
    ) -> SolveResources:
        """From the measured resources (workflow/resources.json) and the timing model
        (workflow/timing_model.json) at the paths given."""
        with open(timing_model, encoding="utf-8") as stream:
            model = json.load(stream)
        measured = JobResources(JobResources.from_file(resources).record, "workflow/resources.json")
        return cls(config, spheres, measured, model)

    def runtime(self, rule: str) -> int:
        """Measured runtime (min) of a job of ``rule``."""
        return self.measured.runtime_min(rule)

    def mem_mb(self, rule: str) -> int:
        """Measured memory (MB) of a job of ``rule``."""
        return self.measured.mem_mb(rule)

    def solve_size(self, scene, sphere=None, scan=None, value=None) -> tuple[str, dict]:
        """What the timing model needs of a scene's solve on ``sphere`` (None: synthetic),
        with the scan parameter ``scan`` (a parameter's config key, amontons.models) at
        ``value`` if given: model and the keyword arguments of amontons.accuracy.timing.predict."""
        spec = self.scenes[scene]
        if sphere is None:
            frame = geometry.synthetic_frame(spec)
            slope = spec["synthetic"].get("rms_slope")
            law = spec
        else:
            row = self.spheres.rows.row(sphere)
            frame = geometry.sphere_frame(spec, row)
            slope = None  # the map's slope is known only once it is levelled
            law = {
                p.key: spec.get(p.key) or row.get(p.sheet_column)
                for p in (m.parameter for m in with_parameter())
            }
        if scan is not None:
            law = {**law, scan: float(value)}
        window = geometry.window_m(scene, spec, frame)
        pixel = geometry.solver_pixel_m(spec, window)
        contact_px = None
        if frame.radius_m is not None:
            largest = max(frame.loads_n)
            contact_px = geometry.hertz_diameter_m(largest, frame.radius_m, frame.e_star_pa) / pixel
        ratio = plastic_ratio(
            spec["model"],
            pixel_m=pixel,
            e_star_pa=frame.e_star_pa,
            parameter_si=_parameter_si(spec["model"], law),
            slope_rms=slope,
        )
        return spec["model"], {
            "side_px": geometry.side_px(window, pixel),
            "periodic": spec["geometry"] == "flat_periodic",
            "loads": len(frame.loads_n),
            "tol": spec["tol"],
            "contact_px": contact_px,
            "ratio": ratio,
        }

    def predicted(self, solves_of: SolvesOf, wildcards) -> tuple[float, float]:
        """(wall time s, peak memory MB) the timing model predicts for a job's solves, one
        after the other: their times summed, the largest memory."""
        each = [
            predict(self.timing_model, model, **size)
            for model, size in (self.solve_size(*solve) for solve in solves_of(wildcards))
        ]
        return sum(time for time, _ in each), max(memory for _, memory in each)

    def solve_runtime(self, solves_of: SolvesOf):
        """Runtime (min) of a solve job, as a function of its wildcards: the timing model's
        prediction with the resources' safety factor."""
        return lambda wildcards: runtime_min(self.predicted(solves_of, wildcards)[0])

    def solve_mem_mb(self, solves_of: SolvesOf):
        """Memory (MB) of a solve job, as :meth:`solve_runtime`."""
        return lambda wildcards: mem_mb_of(self.predicted(solves_of, wildcards)[1])


def scan_solves(
    scans: Mapping,
    chain: Callable[[str, str], list[str]],
    refined: int = 0,
    check_pixel_factor: float = 1.0,
) -> SolvesOf:
    """A scan job's solves for the timing model: its scene on its sphere at each value of
    ``chain(sphere, scan)``; and, at most, ``refined`` values more, the elastic limit, and the
    two model-error checks at ``check_pixel_factor`` times the pixel (the best value's and
    the elastic limit's: docs/study.md §1, §6), each check costed as the cells it solves,
    1/factor² times a solve's; each costed as the grid's middle value: an upper bound of the
    time, so that a cluster's time limit holds the refined scan too (the memory is a solve's
    at the scan's pixel: a check's is larger by its cells)."""

    def solves_of(wildcards):
        scan = scans[wildcards.scan]
        values = chain(wildcards.sphere, wildcards.scan)
        middle = sorted(values, key=float)[len(values) // 2]
        checks = 2 * max(1, round(check_pixel_factor**-2))
        return [
            (scan["scene"], wildcards.sphere, scan["parameter"], value)
            for value in [*values, *[middle] * (refined + 1 + checks)]
        ]

    return solves_of
