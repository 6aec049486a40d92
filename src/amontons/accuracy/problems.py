"""The accuracy study's problems on the grid of one setting (docs/accuracy.md, "Problems").

Every setting of a problem sees the same surface: the rough spheres are one virtual sphere's
levelled AFM map, area-averaged onto each setting's grid about the fitted apex (as a scene
does, :func:`amontons.simulate.surface.afm_indenter`); the periodic surface is synthesised
once at the finest pixel and block-averaged to coarser ones (each coarse pixel holds the mean
of the fine pixels it covers). So a coarser setting differs from the reference only by what
its pixel, window, tolerance and start do to the solve.
"""

from __future__ import annotations

import dataclasses
import resource
import time
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from amontons.accuracy.settings import Setting, problem_kind
from amontons.accuracy.timing import parameter_at_ratio, plastic_ratio
from amontons.contact import ContactResult, solve_load_series
from amontons.contact.surfaces import self_affine
from amontons.measured_resources import fft_points
from amontons.models import with_parameter
from amontons.physics.hertz import contact_radius
from amontons.simulate.scene import Scene, scene_for_sphere
from amontons.simulate.surface import LevelledMap, afm_indenter

# the sphere's whole load series on one grid: no cap on the window's pixels
UNCAPPED_SIDE_PX = 1 << 20


@dataclass(frozen=True)
class Problem:
    """One problem at one setting: heights (m, rigid indenter, larger = closer), pixel (m),
    E* (Pa), loads (N), periodic, the plasticity law (None: elastic), the window side (m),
    the finest pixel of the study (m), and what the timing model reads of it: the contact's
    extent in pixels (a sphere's Hertz diameter at the largest load; a periodic surface's
    side) and a plastic law's dimensionless ratio (amontons.accuracy.timing; None: elastic)."""

    heights: np.ndarray
    pixel_m: float
    e_star_pa: float
    loads_n: tuple[float, ...]
    periodic: bool
    plasticity: object
    window_m: float
    finest_pixel_m: float
    contact_px: float
    ratio: float | None


def sphere_scene(problem: str, setting: Setting, levelled: LevelledMap, record: Mapping) -> Scene:
    """The scene of a rough-sphere problem at ``setting``: the sphere's measured loads, its
    sheet E* and k, the pixel ``pixel_factor`` × the AFM map's."""
    model = problem_kind(problem)[0]
    return _sphere_scene(f"accuracy:{problem}", model, setting, levelled.pixel_m, record)


def _sphere_scene(name: str, model: str, setting: Setting, map_pixel_m: float, record) -> Scene:
    config = {
        "surface": "afm_before",
        "geometry": "sphere",
        "model": model,
        "loads": "measured",
        "pixel_nm": setting.pixel_factor * map_pixel_m * 1e9,
        "window_factor": setting.window_factor,
        "side_px": None,
        "max_side_px": UNCAPPED_SIDE_PX,
        "tol": setting.tol,
        "optics": "none",
        "rendering": "emission",
        **{model.parameter.key: None for model in with_parameter()},
    }
    return scene_for_sphere(name, config, record["sphere"], record)


def sphere_problem(problem: str, setting: Setting, levelled: LevelledMap, record, source: str):
    """The rough sphere at ``setting`` (its AFM map on the setting's grid)."""
    scene = sphere_scene(problem, setting, levelled, record)
    return _sphere_problem(scene, afm_indenter(levelled, scene, source), levelled)


def timing_problem(
    model: str, ratio: float, setting: Setting, levelled: LevelledMap, record, source: str
) -> Problem:
    """A timing point: the rough sphere at ``setting`` under ``model`` with its law set by
    the dimensionless ``ratio`` (amontons.accuracy.timing): hardening k = s·πE*/(2Δx),
    penetration hardness p_Y = y·E*·h'_rms/2 with h'_rms the map's rms slope on the solver
    grid."""
    scene = _sphere_scene(f"timing:{model}", model, setting, levelled.pixel_m, record)
    indenter = afm_indenter(levelled, scene, source)
    parameter_si = parameter_at_ratio(
        model,
        ratio,
        pixel_m=scene.pixel_m,
        e_star_pa=scene.e_star_pa,
        slope_rms=indenter.solver_statistics["slope_rms"],
    )
    scene = dataclasses.replace(scene, parameter_si=parameter_si)
    return _sphere_problem(scene, indenter, levelled)


def _sphere_problem(scene: Scene, indenter, levelled: LevelledMap) -> Problem:
    return Problem(
        heights=indenter.heights,
        pixel_m=scene.pixel_m,
        e_star_pa=scene.e_star_pa,
        loads_n=scene.loads_n,
        periodic=False,
        plasticity=scene.plasticity,
        window_m=scene.side_px * scene.pixel_m,
        finest_pixel_m=levelled.pixel_m,
        contact_px=2.0
        * contact_radius(max(scene.loads_n), scene.radius_m, scene.e_star_pa)
        / scene.pixel_m,
        ratio=plastic_ratio(
            scene.model,
            pixel_m=scene.pixel_m,
            e_star_pa=scene.e_star_pa,
            parameter_si=scene.parameter_si,
            slope_rms=indenter.solver_statistics["slope_rms"],
        ),
    )


def periodic_surface(spec: Mapping) -> tuple[np.ndarray, float]:
    """The periodic self-affine surface at the finest pixel (heights m, pixel m)."""
    pixel_m = spec["pixel_nm"] * 1e-9
    n = int(round(spec["side_um"] * 1e-6 / pixel_m))
    heights = self_affine(
        (n, n),
        pixel_m,
        spec["hurst"],
        rms_height=spec["rms_height_nm"] * 1e-9,
        short_cutoff=spec["short_cutoff_um"] * 1e-6,
        long_cutoff=spec["long_cutoff_um"] * 1e-6,
        rng=spec["seed"],
    )
    return heights, pixel_m


def block_average(heights: np.ndarray, factor: int) -> np.ndarray:
    """Mean over ``factor`` × ``factor`` blocks (the side must be a multiple of it)."""
    n0, n1 = heights.shape
    if n0 % factor or n1 % factor:
        raise ValueError(f"a {n0} × {n1} grid has no whole {factor} × {factor} blocks")
    return heights.reshape(n0 // factor, factor, n1 // factor, factor).mean(axis=(1, 3))


def periodic_problem(setting: Setting, spec: Mapping) -> Problem:
    """The periodic surface at ``setting``, elastic, at the spec's loads."""
    fine, fine_pixel = periodic_surface(spec)
    heights = block_average(fine, setting.pixel_factor)
    return Problem(
        heights=heights - heights.max(),
        pixel_m=fine_pixel * setting.pixel_factor,
        e_star_pa=spec["e_star_gpa"] * 1e9,
        loads_n=tuple(f * 1e-3 for f in spec["loads_mn"]),
        periodic=True,
        plasticity=None,
        window_m=fine.shape[0] * fine_pixel,
        finest_pixel_m=fine_pixel,
        contact_px=float(heights.shape[0]),
        ratio=None,
    )


def cost_record(problem: Problem, results: list[ContactResult], wall_time_s: float) -> dict:
    """What a solve cost and what the timing model reads of it (amontons.accuracy.timing):
    grid, FFT points, contact extent, plastic ratio, wall time (s), the process's peak
    memory so far (MB), iterations and convolutions over all loads."""
    side = problem.heights.shape[0]
    return {
        "side_px": side,
        "periodic": problem.periodic,
        "fft_points": fft_points(side, problem.periodic),
        "contact_px": problem.contact_px,
        "ratio": problem.ratio,
        "wall_time_s": wall_time_s,
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,  # Linux: kB
        "iterations": sum(int(r.iterations) for r in results),
        "convolutions": sum(float(r.info.convolutions) for r in results),
    }


def solve_problem(problem: Problem, setting: Setting) -> tuple[list[ContactResult], float]:
    """The load series at ``setting`` and its wall time (s): one thread, as a scene job
    (solve_load_series bounds the thread pools itself)."""
    start = time.perf_counter()
    results = solve_load_series(
        problem.heights,
        problem.pixel_m,
        problem.e_star_pa,
        list(problem.loads_n),
        periodic=problem.periodic,
        tol=setting.tol,
        plasticity=problem.plasticity,
        coarse_to_fine=setting.coarse_to_fine,
    )
    return results, time.perf_counter() - start
