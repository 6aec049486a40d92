"""Rule simulate_scene: one scene's load series on its surface, fields to HDF5."""

import logging
import os

if "snakemake" in globals():
    # The contact solve's BLAS calls spin OpenBLAS threads beyond the rule's (benchmarks/README)
    os.environ.setdefault("OPENBLAS_NUM_THREADS", str(snakemake.threads))  # noqa: F821

from dataclasses import replace

from amontons.config.geometry import Frame, window_m
from amontons.io.fields import write_load_series
from amontons.io.files import write_json
from amontons.runlog import run_logged
from amontons.simulate.scene import synthetic_scene
from amontons.simulate.solve import solve_on_clipped_window, solve_scene
from amontons.simulate.surface import (
    afm_indenter,
    afm_scene,
    load_levelled_map,
    synthetic_indenter,
)

log = logging.getLogger(__name__)


def write_outside_scan(fields_path, solve_path, scene_name, scene_config, sphere, coverage):
    """The records of a scene whose sphere's scan holds none of its loads: no load solved,
    every load listed as outside_scan with the window it needs (never a failed job)."""
    log.warning(
        "scene %s, sphere %s: the AFM scan holds no load's window (%.1f µm about the apex); "
        "nothing simulated",
        scene_name,
        sphere,
        coverage.largest_window_m * 1e6,
    )
    settings = {
        "scene": scene_name,
        "sphere": sphere,
        "surface": scene_config["surface"],
        "model": scene_config["model"],
        "optics": scene_config["optics"],
        "loads_mn": [],
        "status": "outside_scan",
        **coverage.to_record(),
    }
    write_load_series(fields_path, [], [], settings)
    write_json(solve_path, {**settings, "wall_time_s": 0.0, "loads": []})


def own_windows_m(name: str, config: dict, scene, loads_n) -> tuple[float, ...]:
    """The window (m) each of ``loads_n`` would be solved on as the scene's largest load."""
    frame = Frame(tuple(scene.loads_n), scene.radius_m, scene.e_star_pa)
    return tuple(window_m(name, config, frame._replace(loads_n=(load,))) for load in loads_n)


def sphere_solution(levelled_path, scene_name, scene_config, sphere, sphere_record, **solver):
    """The scene on the sphere's levelled map, its indenter, its solution and what the AFM
    scan covers (amontons.simulate.surface.ScanCoverage). On a window the scan clipped, the
    loads whose contact reaches its edge are left out too. Scene, indenter and solution are
    None where no load is solved."""
    levelled = load_levelled_map(levelled_path)
    scene, scan = afm_scene(scene_name, scene_config, sphere, sphere_record, levelled)
    if scene is None:
        return None, None, None, scan
    indenter = afm_indenter(levelled, scene, levelled_path)
    if scan.clipped_from_m is None:
        return scene, indenter, solve_scene(scene, indenter, **solver), scan
    solution, dropped = solve_on_clipped_window(scene, indenter, **solver)
    scan = scan.without(dropped, own_windows_m(scene_name, scene_config, scene, dropped))
    if solution is None:
        return None, None, None, scan
    return replace(scene, loads_n=scene.loads_n[: len(solution.per_load)]), indenter, solution, scan


def main(
    levelled_path: str | None,
    fields_path: str,
    solve_path: str,
    scene_name: str,
    scene_config: dict,
    sphere: str | None,
    sphere_record: dict | None,
    threads: int,
    solver_backend: str = "cpu",
) -> None:
    solver = {"threads": threads, "backend": solver_backend}
    coverage = {}
    if sphere is None:
        scene = synthetic_scene(scene_name, scene_config)
        indenter = synthetic_indenter(scene)
        solution = solve_scene(scene, indenter, **solver)
    else:
        scene, indenter, solution, scan = sphere_solution(
            levelled_path, scene_name, scene_config, sphere, sphere_record, **solver
        )
        if solution is None:
            write_outside_scan(fields_path, solve_path, scene_name, scene_config, sphere, scan)
            return
        coverage = scan.to_record()
    log.info(
        "%s: %d² solver grid of %.1f nm (window %.1f µm); surface rms %.1f nm, slope %.3f "
        "at the solver pixel (%.1f nm, slope %.3f at the map's)",
        scene.name,
        scene.side_px,
        scene.pixel_m * 1e9,
        scene.window_m * 1e6,
        indenter.solver_statistics["roughness_rms_nm"],
        indenter.solver_statistics["slope_rms"],
        indenter.afm_statistics["roughness_rms_nm"],
        indenter.afm_statistics["slope_rms"],
    )
    settings = {
        **scene.to_record(),
        "sphere": sphere,
        "status": "outside_scan" if coverage.get("outside_scan") else "complete",
        **coverage,
        "window_centre_in_scan_um": [c * 1e6 for c in indenter.centre_in_scan_m],
        "surface_at_map_pixel": indenter.afm_statistics,
        "surface_at_solver_pixel": indenter.solver_statistics,
    }
    write_load_series(fields_path, solution.fields, solution.per_load, settings)
    write_json(
        solve_path,
        {**settings, "wall_time_s": solution.wall_time_s, "loads": solution.per_load},
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        levelled_path=sm.input.get("levelled"),
        fields_path=sm.output.fields,
        solve_path=sm.output.solve,
        scene_name=sm.wildcards.scene,
        scene_config=sm.params.scene,
        sphere=sm.params.sphere,
        sphere_record=sm.params.sphere_record,
        threads=sm.threads,
        solver_backend=sm.params.get("solver_backend", "cpu"),
    )
