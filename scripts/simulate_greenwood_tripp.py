"""Rule simulate_greenwood_tripp: a Greenwood–Tripp scene's real contact area per load, from the
roughness statistics of the sphere's levelled AFM map."""

import logging

from amontons.io.files import write_json
from amontons.physics.roughness import roughness_statistics
from amontons.runlog import run_logged
from amontons.simulate.scene import scene_for_sphere
from amontons.simulate.solve import greenwood_tripp_scene
from amontons.simulate.surface import load_levelled_map

log = logging.getLogger(__name__)


def main(
    levelled_path: str,
    solve_path: str,
    scene_name: str,
    scene_config: dict,
    sphere: str,
    sphere_record: dict,
) -> None:
    scene = scene_for_sphere(scene_name, scene_config, sphere, sphere_record)
    levelled = load_levelled_map(levelled_path)
    pixel_m = levelled.pixel_m
    stats = roughness_statistics(levelled.roughness_m, pixel_m)
    rows = greenwood_tripp_scene(scene, stats.h_rms_m, stats.curvature_rms_per_m)
    for row in rows:
        log.info("%s: %.3g mN → %.1f µm²", scene.name, row["load_mn"], row["area_um2"])
    write_json(
        solve_path,
        {
            **scene.to_record(),
            "sphere": sphere,
            "surface_at_map_pixel": {
                "pixel_nm": pixel_m * 1e9,
                "roughness_rms_nm": stats.h_rms_m * 1e9,
                "curvature_rms_per_um": stats.curvature_rms_per_m * 1e-6,
            },
            "asperity_closure": "sigma = h_rms, beta = 1/h''_rms, eta sigma beta = 0.05",
            "loads": rows,
        },
    )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821 (injected by Snakemake)
    run_logged(
        main,
        sm.log[0],
        levelled_path=sm.input.levelled,
        solve_path=sm.output.solve,
        scene_name=sm.wildcards.scene,
        scene_config=sm.params.scene,
        sphere=sm.params.sphere,
        sphere_record=sm.params.sphere_record,
    )
