"""A scene's load series against analytic and limiting cases: an elastic scene on a smooth
sphere's AFM map is Hertz; an elastic scene runs no plastic loop; the fields survive HDF5."""

import numpy as np
import pytest

from amontons.io.fields import read_load_series, write_load_series
from amontons.measure.topography import sphere_cap
from amontons.physics import hertz
from amontons.power_law import fit_power_law
from amontons.simulate.scene import scene_for_sphere
from amontons.simulate.solve import solve_scene
from amontons.simulate.surface import afm_indenter, level_afm_map

from .test_surface import SCENE

# A smooth sphere unlike the virtual experiment's: R = 1 mm, E* = 2 GPa, 5-80 mN, a 100 nm AFM
# pixel, solved on 250 nm.
RECORD = {"diameter_mm": 2.0, "e_star_gpa": 2.0, "loads": [5.0, 10.0, 20.0, 40.0, 80.0]}


@pytest.fixture(scope="module")
def hertz_scene():
    scene = scene_for_sphere("elastic", SCENE, "smooth", RECORD)
    heights = sphere_cap((1000, 1000), 100e-9, 1e-3, (0.7e-6, -1.1e-6), 0.0)
    indenter = afm_indenter(level_afm_map(heights, 100e-9), scene, "smooth.tif")
    return scene, indenter, solve_scene(scene, indenter)


def test_elastic_scene_on_a_smooth_sphere_is_hertz(hertz_scene):
    """Area within 1 % of πa² at every load (the contact radius is ≥ 49 solver pixels, whose
    discretisation moves the area by < 0.5 %), and the load-area exponent within 0.01 of 2/3."""
    scene, _, solution = hertz_scene
    areas = np.array([row["area_um2"] for row in solution.per_load]) * 1e-12
    loads = np.array(scene.loads_n)
    expected = np.pi * np.array([hertz.contact_radius(f, 1e-3, 2e9) for f in loads]) ** 2
    assert areas == pytest.approx(expected, rel=0.01)
    exponent = fit_power_law(loads, areas, x_ref=loads[0]).exponent.estimate
    assert exponent == pytest.approx(2 / 3, abs=0.01)


def test_elastic_scene_runs_no_plastic_loop(hertz_scene):
    _, _, solution = hertz_scene
    assert [row["outer_iterations"] for row in solution.per_load] == [0] * 5
    assert {row["route"] for row in solution.per_load} == {"elastic"}
    assert all(np.all(f["plastic_displacement"] == 0) for f in solution.fields)


def test_fields_round_trip_through_hdf5_with_units(hertz_scene, tmp_path):
    scene, _, solution = hertz_scene
    path = tmp_path / "fields.h5"
    write_load_series(path, solution.fields, solution.per_load, scene.to_record())
    fields, per_load, settings = read_load_series(path)
    assert settings["loads_mn"] == pytest.approx(RECORD["loads"])
    assert per_load[2]["area_um2"] == solution.per_load[2]["area_um2"]
    for mine, theirs in zip(solution.fields, fields, strict=True):
        assert np.array_equal(mine["pressure"], theirs["pressure"])
        assert np.array_equal(mine["contact"], theirs["contact"])
    import h5py

    with h5py.File(path) as h5:
        assert h5["load_0/pressure"].attrs["unit"] == "Pa"
        assert h5["load_0/gap"].attrs["unit"] == "m"


def test_a_window_the_contact_reaches_fails_loudly():
    """A hardening scene on a rough sphere whose window is the Hertz diameter itself: the
    hardened, rough contact spreads beyond it, so the solver's free-boundary check raises
    (never a silent result)."""
    from amontons.contact import FreeBoundaryError
    from amontons.contact.surfaces import self_affine

    record = {**RECORD, "loads": [20.0, 40.0, 80.0], "hardening_k_mpa_per_nm": 1.0}
    scene = scene_for_sphere(
        "tight", {**SCENE, "model": "hardening", "window_factor": 1.0}, "rough", record
    )
    cap = sphere_cap((1000, 1000), 100e-9, 1e-3, (0.0, 0.0), 0.0)
    rough = self_affine((1000, 1000), 100e-9, 0.8, rms_height=40e-9, long_cutoff=10e-6, rng=2)
    indenter = afm_indenter(level_afm_map(cap + rough, 100e-9), scene, "rough.tif")
    with pytest.raises(FreeBoundaryError, match="contact reaches the window edge"):
        solve_scene(scene, indenter)


def test_synthetic_flat_periodic_scene_is_linear_at_small_contact():
    """A nominally flat, periodic self-affine surface (no padding: the result says periodic):
    at contact fractions of a few per cent the elastic area grows in proportion to the load
    (A = κF/(E*h'_rms), docs/models.md §2.7): doubling the load doubles the area within 10 %
    (κ drifts slowly with the contact fraction), and κ lies in 1.5-2.5."""
    from amontons.simulate.scene import synthetic_scene
    from amontons.simulate.surface import synthetic_indenter

    config = {
        **SCENE,
        "surface": "synthetic",
        "geometry": "flat_periodic",
        "side_px": 256,
        "pixel_nm": 100.0,
        "loads": [2.0, 4.0, 8.0],
        "synthetic": {"hurst": 0.8, "rms_slope": 0.1, "seed": 4, "e_star_gpa": 3.0},
    }
    scene = synthetic_scene("flat", config)
    indenter = synthetic_indenter(scene)
    solution = solve_scene(scene, indenter)
    areas = np.array([row["area_um2"] for row in solution.per_load]) * 1e-12
    assert areas[1] / areas[0] == pytest.approx(2.0, rel=0.1)
    assert areas[2] / areas[1] == pytest.approx(2.0, rel=0.1)
    slope = indenter.solver_statistics["slope_rms"]
    kappa = areas * scene.e_star_pa * slope / np.array(scene.loads_n)
    assert np.all((kappa > 1.5) & (kappa < 2.5)), kappa
    assert [row["outer_iterations"] for row in solution.per_load] == [0, 0, 0]
