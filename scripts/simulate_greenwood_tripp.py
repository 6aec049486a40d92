"""Rule simulate_greenwood_tripp: a Greenwood-Tripp scene's real contact area per load, from the
roughness statistics of the sphere's levelled AFM map."""

import logging

from amontons.io.files import write_json
from amontons.io.heightmap import read_height_map
from amontons.measure.topography import level_sphere, square_pixels
from amontons.physics.roughness import roughness_statistics
from amontons.runlog import run_logged
from amontons.simulate.scene import scene_for_sphere
from amontons.simulate.solve import greenwood_tripp_scene

log = logging.getLogger(__name__)


def main(
    afm_before: str,
    solve_path: str,
    scene_name: str,
    scene_config: dict,
    sphere: str,
    sphere_record: dict,
    afm: dict,
) -> None:
    scene = scene_for_sphere(scene_name, scene_config, sphere, sphere_record)
    height_map = square_pixels(
        read_height_map(
            afm_before,
            fallback_pixel_m=None if afm["pixel_nm"] is None else afm["pixel_nm"] * 1e-9,
            nan_policy=afm["nan_policy"],
            channel=afm["channel"],
        )
    )
    fit = level_sphere(height_map.heights, height_map.pixel_m)
    stats = roughness_statistics(fit.roughness, height_map.pixel_m)
    rows = greenwood_tripp_scene(scene, stats.h_rms_m, stats.curvature_rms_per_m)
    for row in rows:
        log.info("%s: %.3g mN → %.1f µm²", scene.name, row["load_mn"], row["area_um2"])
    write_json(
        solve_path,
        {
            **scene.to_record(),
            "sphere": sphere,
            "surface_at_map_pixel": {
                "pixel_nm": height_map.pixel_m * 1e9,
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
        afm_before=sm.input.afm_before,
        solve_path=sm.output.solve,
        scene_name=sm.wildcards.scene,
        scene_config=sm.params.scene,
        sphere=sm.params.sphere,
        sphere_record=sm.params.sphere_record,
        afm=sm.params.afm,
    )
