"""A window clipped to a small AFM scan (docs/simulate.md §2, "A scan smaller than the
contact"): a load whose own window (window_factor × its Hertz diameter) the scan does not
hold, but whose contact it holds with CONTACT_MARGIN of room, is solved on the largest window
the scan holds, and the record says by how much the window was clipped. On a smooth sphere
the contact is Hertz's, so the clipped solve must give the unclipped one's contact, pixel for
pixel; a contact that reaches the clipped window's edge is refused by the solver and its
load left out."""

from dataclasses import replace

import numpy as np
import pytest

from amontons.config import geometry
from amontons.physics.hertz import contact_radius
from amontons.simulate.scene import scene_for_sphere
from amontons.simulate.solve import solve_on_clipped_window, solve_scene
from amontons.simulate.surface import afm_indenter, afm_scene, level_afm_map

# test_surface's elastic scene on a smooth sphere's map (1.5 × the Hertz diameter, 250 nm)
from .test_surface import SCENE, _sphere_map

RECORD = {"diameter_mm": 2.0, "e_star_gpa": 20.0, "loads": [5.0, 20.0, 80.0]}
PIXEL_M = 100e-9


def _levelled(side_px):
    return level_afm_map(_sphere_map(side_px, PIXEL_M, 1e-3), PIXEL_M)


def _hertz_diameter_m(load_mn):
    return 2 * contact_radius(load_mn * 1e-3, 1e-3, 20e9)


def test_a_contact_that_fits_with_room_is_solved_on_the_window_the_scan_holds():
    """A 40 µm scan: 80 mN's own window (1.5 × 28.9 µm = 43 µm) does not fit, its contact
    with the margin (1.25 × 28.9 = 36 µm) does: every load is kept, on a window no wider
    than the scan holds, and the record says the window was clipped and by how much."""
    assert geometry.CONTACT_MARGIN * _hertz_diameter_m(80) < 40e-6 < 1.5 * _hertz_diameter_m(80)
    scene, coverage = afm_scene("s", SCENE, "S", RECORD, _levelled(400))
    assert [f * 1e3 for f in scene.loads_n] == pytest.approx(RECORD["loads"])
    assert coverage.left_out == ()
    assert scene.window_m <= coverage.largest_window_m < 1.5 * _hertz_diameter_m(80)
    clipped = coverage.to_record()["window_clipped"]
    assert clipped["own_window_um"] == pytest.approx(1.5 * _hertz_diameter_m(80) * 1e6, rel=0.02)
    assert clipped["clipped_to_um"] == pytest.approx(scene.window_m * 1e6, rel=1e-12)
    assert clipped["fraction"] == pytest.approx(scene.window_m / coverage.clipped_from_m)
    assert 0.8 < clipped["fraction"] < 1.0


def test_a_scan_that_holds_the_own_window_is_not_clipped():
    scene, coverage = afm_scene("s", SCENE, "S", RECORD, _levelled(900))
    assert scene == scene_for_sphere("s", SCENE, "S", RECORD)
    assert coverage.clipped_from_m is None and "window_clipped" not in coverage.to_record()


def test_a_contact_short_of_the_margin_stays_outside_the_scan():
    """A 34 µm scan: 80 mN's contact needs 36 µm with the margin: left out, as before."""
    scene, coverage = afm_scene("s", SCENE, "S", RECORD, _levelled(340))
    assert [load.load_n * 1e3 for load in coverage.left_out] == pytest.approx([80.0])
    assert [f * 1e3 for f in scene.loads_n] == pytest.approx([5.0, 20.0])


def test_the_clipped_window_gives_the_unclipped_contact_pixel_for_pixel():
    """The same grid (250 nm, centred on the apex) on both windows: the contact sets are the
    same pixels and the pressures agree to the solver's tolerance (1e-8 of the load's
    balance; 1e-6 of the peak bounds what two FFT sizes' round-off and stopping points
    leave)."""
    clipped, coverage = afm_scene("s", SCENE, "S", RECORD, _levelled(400))
    full = scene_for_sphere("s", SCENE, "S", RECORD)
    assert coverage.clipped_from_m is not None and clipped.pixel_m == full.pixel_m
    small = solve_scene(clipped, afm_indenter(_levelled(400), clipped, "small.tif"))
    large = solve_scene(full, afm_indenter(_levelled(900), full, "large.tif"))
    n, m = clipped.side_px, full.side_px
    inner = slice((m - n) // 2, (m + n) // 2)
    for a, b in zip(small.fields, large.fields, strict=True):
        assert np.count_nonzero(b["pressure"]) == np.count_nonzero(b["pressure"][inner, inner])
        np.testing.assert_array_equal(a["pressure"] > 0, b["pressure"][inner, inner] > 0)
        peak = b["pressure"].max()
        np.testing.assert_allclose(a["pressure"], b["pressure"][inner, inner], atol=1e-6 * peak)


def test_a_load_whose_contact_reaches_the_clipped_windows_edge_is_left_out():
    """A window of 0.97 × 80 mN's Hertz diameter: its contact reaches the edge (the solver
    refuses it), the two smaller loads are solved as on any window that holds them."""
    scene = scene_for_sphere("s", SCENE, "S", RECORD)
    tight = replace(scene, window_m=0.97 * _hertz_diameter_m(80))
    indenter = afm_indenter(_levelled(900), tight, "map.tif")
    solution, dropped = solve_on_clipped_window(tight, indenter)
    assert [f * 1e3 for f in dropped] == pytest.approx([80.0])
    assert [row["load_mn"] for row in solution.per_load] == pytest.approx([5.0, 20.0])
    reference = solve_scene(replace(tight, loads_n=tight.loads_n[:2]), indenter)
    for a, b in zip(solution.fields, reference.fields, strict=True):
        np.testing.assert_array_equal(a["pressure"], b["pressure"])
    too_small = replace(scene, window_m=0.9 * _hertz_diameter_m(5))
    none, all_loads = solve_on_clipped_window(
        too_small, afm_indenter(_levelled(900), too_small, "m")
    )
    assert none is None and all_loads == scene.loads_n
