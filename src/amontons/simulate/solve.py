"""A scene's load series (docs/simulate.md, "Solve").

The loads step upward, each warm-started from the previous pressure and carrying the plastic
history (:func:`amontons.contact.solve_load_series`). Only what the scene names is computed:
an elastic scene passes no plasticity law (no plastic loop: zero outer iterations), a periodic
scene no Hockney padding. A contact that reaches the window edge raises the solver's
FreeBoundaryError; a solve that does not converge raises ConvergenceError: never a silent
result.

Greenwood–Tripp (appendix B.2.1) is the mean-field model of the same sphere: it takes the
roughness statistics of the map (σ = h_rms, β = 1/h''_rms) and returns an axisymmetric
nominal pressure and area fraction, not a map (docs/models.md §2.5).
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, replace

import numpy as np

from amontons.contact import ContactResult, FreeBoundaryError, solve_load_series
from amontons.contact.greenwood_tripp import AsperityModel, greenwood_tripp
from amontons.simulate.scene import Scene
from amontons.simulate.surface import Indenter

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class SceneSolution:
    """Per load: the solver's fields (SI) and diagnostics; the scene's total wall time (s)."""

    fields: list[dict]
    per_load: list[dict]
    wall_time_s: float


def _fields(result: ContactResult) -> dict:
    return {
        "pressure": result.pressure,
        "gap": result.gap,
        "plastic_displacement": result.plastic_displacement,
        "deformed_heights": result.deformed_heights,
        "contact": result.contact,
    }


def _diagnostics(result: ContactResult) -> dict:
    info = result.info
    return {
        "load_mn": float(result.load) * 1e3,
        "area_um2": float(result.area) * 1e12,
        "mean_pressure_mpa": float(result.mean_pressure) * 1e-6,
        "approach_nm": float(result.displacement) * 1e9,
        "max_plastic_depth_nm": float(-np.min(result.plastic_displacement)) * 1e9,
        "iterations": int(result.iterations),
        "residual": float(result.residual),
        "route": info.route,
        "outer_iterations": int(info.outer_iterations),
        "convolutions": float(info.convolutions),
        "wall_time_s": float(info.wall_time_s),
    }


# config solver_backend -> the solver's backend (None: the CPU solver's default FFT backend)
SOLVER_BACKENDS = {"cpu": None, "cupy": "cupy"}


def solve_scene(
    scene: Scene,
    indenter: Indenter,
    *,
    threads: int = 1,
    backend: str = "cpu",
    warm_starts: list[np.ndarray | None] | None = None,
) -> SceneSolution:
    """The scene's load series on its indenter (one ContactResult per load, as fields), on
    the solver engine ``backend`` (config ``solver_backend``: ``cpu`` or ``cupy``).
    ``warm_starts``: a starting pressure (Pa) or None per load, such as a neighbouring scan
    value's solution (:mod:`amontons.simulate.scan_start`); None starts each load from the
    previous one's."""
    start = time.perf_counter()
    results = solve_load_series(
        indenter.heights,
        indenter.spacing_m,
        scene.e_star_pa,
        list(scene.loads_n),
        periodic=scene.periodic,
        tol=scene.tol,
        plasticity=scene.plasticity,
        threads=threads,
        backend=SOLVER_BACKENDS[backend],
        warm_starts=warm_starts,
    )
    for result in results:
        log.info(
            "%s: %.3g mN → %.1f µm² (%d CG iterations, %d plastic rounds, route %s)",
            scene.name,
            result.load * 1e3,
            result.area * 1e12,
            result.iterations,
            result.info.outer_iterations,
            result.info.route,
        )
    return SceneSolution(
        fields=[_fields(r) for r in results],
        per_load=[_diagnostics(r) for r in results],
        wall_time_s=time.perf_counter() - start,
    )


def solve_on_clipped_window(
    scene: Scene, indenter: Indenter, *, threads: int = 1, backend: str = "cpu"
) -> tuple[SceneSolution | None, tuple[float, ...]]:
    """A scene on a window the AFM scan clipped (amontons.config.geometry.frame_in_scan): its
    load series, and where the largest load's contact reaches the window's edge (the solver's
    FreeBoundaryError), the series without it, and so on down. Returns the solution of the
    loads kept (None where none is) and the loads dropped (N, increasing).

    On a window that holds the contact, the contact is that of an unclipped window to the
    pixel (docs/simulate.md §2, "A scan smaller than the contact", measured by
    benchmarks/window_margin.py): the edge is the test of room."""
    loads = scene.loads_n
    while loads:
        try:
            solution = solve_scene(
                replace(scene, loads_n=loads), indenter, threads=threads, backend=backend
            )
        except FreeBoundaryError as error:
            log.info(
                "%s: %g mN left out: its contact reaches the clipped window's edge (%s)",
                scene.name,
                loads[-1] * 1e3,
                error,
            )
            loads = loads[:-1]
            continue
        return solution, scene.loads_n[len(loads) :]
    return None, scene.loads_n


def greenwood_tripp_scene(
    scene: Scene, h_rms_m: float, curvature_rms_per_m: float, eta_sigma_beta: float = 0.05
) -> list[dict]:
    """Greenwood–Tripp real contact area (µm²) per load of the scene's sphere, and its radial
    profile of the real-area fraction (annulus mid-radii, µm), with the
    asperity closure of docs/models.md §2.5 (σ = h_rms, β = 1/h''_rms, ησβ = 0.05)."""
    model = AsperityModel.from_roughness(h_rms_m, curvature_rms_per_m, eta_sigma_beta)
    rows = []
    for load in scene.loads_n:
        gt = greenwood_tripp(scene.radius_m, scene.e_star_pa, model, load)
        rows.append(
            {
                "load_mn": load * 1e3,
                "area_um2": gt.real_area_m2 * 1e12,
                "approach_nm": gt.approach_m * 1e9,
                "newton_iterations": int(gt.newton_iterations),
                # the radial profile: the mean-field map a figure draws (no asperity map)
                "r_um": [float(r) * 1e6 for r in gt.r_m],
                "area_fraction": [float(f) for f in gt.area_fraction],
            }
        )
    return rows
