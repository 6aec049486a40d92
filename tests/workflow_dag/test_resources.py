"""What a solve job asks for is sized on the grid the simulation solves on: the DAG and
amontons.simulate.scene share one scene geometry (amontons.config.geometry), held equal here
on every scene of the shipped configs, and the requests grow with the grid."""

import pytest

from amontons.config import geometry
from amontons.physics.hertz import contact_radius
from amontons.simulate.scene import scene_for_sphere, synthetic_scene


@pytest.mark.parametrize("name", ["config.yaml", "test.yaml"])
def test_the_dag_sizes_each_solve_on_the_grid_the_simulation_solves_on(make_run, name):
    """Same side (px, exact), window and pixel (m, to the bit) for every running scene on
    every selected sphere, and every synthetic scene."""
    run = make_run(name)
    checked = 0
    for scene, spec in run.scenes.scenes.items():
        if spec["surface"] == "synthetic":
            pairs = [(None, synthetic_scene(scene, spec), geometry.synthetic_frame(spec))]
        else:
            pairs = [
                (s, scene_for_sphere(scene, spec, s, run.spheres.rows.row(s)), None)
                for s in run.spheres
            ]
        for sphere, simulated, frame in pairs:
            if frame is None:
                frame = geometry.sphere_frame(spec, run.spheres.rows.row(sphere))
            window = geometry.window_m(scene, spec, frame)
            assert window == simulated.window_m
            assert geometry.solver_pixel_m(spec, window) == simulated.pixel_m
            _, size = run.resources.solve_size(scene, sphere)
            assert size["side_px"] == simulated.side_px
            assert size["loads"] == len(simulated.loads_n)
            checked += 1
    assert checked >= len(run.scenes.scenes)


def test_hertz_diameter_is_the_physics_one():
    for load, radius, e_star in [(0.3, 3e-4, 3.7e9), (0.025, 2e-3, 32.8e9)]:
        assert geometry.hertz_diameter_m(load, radius, e_star) == 2 * contact_radius(
            load, radius, e_star
        )


def test_a_larger_window_asks_for_more_time_and_memory(make_run):
    run = make_run()
    scene = next(
        n
        for n, s in run.scenes.scenes.items()
        if s["surface"] == "afm_before" and s["side_px"] is None
    )
    sphere = next(iter(run.spheres))

    def wider(config):
        spec = config["scenes"][scene]
        spec["window_factor"] = 4 * run.scenes.scenes[scene]["window_factor"]
        spec["max_side_px"] = 16 * run.scenes.scenes[scene]["max_side_px"]

    bigger = make_run(edit=wider)
    small_size = run.resources.solve_size(scene, sphere)[1]
    big_size = bigger.resources.solve_size(scene, sphere)[1]
    assert big_size["side_px"] > small_size["side_px"]
    wildcards = type("W", (), {"scene": scene, "sphere": sphere})()

    def solve_of(wc):
        return [(wc.scene, wc.sphere)]

    assert bigger.resources.solve_runtime(solve_of)(wildcards) >= run.resources.solve_runtime(
        solve_of
    )(wildcards)
    assert bigger.resources.solve_mem_mb(solve_of)(wildcards) > run.resources.solve_mem_mb(
        solve_of
    )(wildcards)
