"""The problems at a setting: one surface for every setting, compared on one grid."""

import numpy as np
import pytest

from amontons.accuracy.compare import on_common_grid, relative_l2
from amontons.accuracy.problems import block_average, periodic_problem
from amontons.accuracy.settings import Setting

SPEC = {
    "side_um": 12.8,
    "pixel_nm": 100.0,
    "hurst": 0.8,
    "rms_height_nm": 5.0,
    "short_cutoff_um": 0.4,
    "long_cutoff_um": 3.0,
    "seed": 1,
    "e_star_gpa": 3.5,
    "loads_mn": [0.1, 0.2, 0.4],
}


def test_block_average_keeps_each_block_mean():
    rng = np.random.default_rng(0)
    h = rng.normal(size=(8, 12))
    coarse = block_average(h, 4)
    assert coarse.shape == (2, 3)
    assert coarse[1, 2] == pytest.approx(h[4:8, 8:12].mean(), rel=1e-12)
    with pytest.raises(ValueError, match="no whole 5"):
        block_average(h, 5)


def test_coarse_periodic_surface_is_the_fine_one_averaged():
    """Every setting sees the same surface: the coarse heights are block means of the fine ones
    (up to the shift that puts the highest point at 0)."""
    fine = periodic_problem(Setting(1, 1e-6, None, False), SPEC)
    coarse = periodic_problem(Setting(4, 1e-6, None, False), SPEC)
    assert coarse.pixel_m == pytest.approx(4 * fine.pixel_m)
    expected = block_average(fine.heights, 4)
    np.testing.assert_allclose(
        coarse.heights - coarse.heights.max(), expected - expected.max(), atol=1e-15
    )


def test_common_grid_keeps_the_force_of_a_centred_field():
    """A pressure patch well inside the window keeps its total force on the common grid."""
    n, a = 64, 50e-9
    p = np.zeros((n, n))
    p[28:36, 26:38] = 1e6
    side, c = 12, 200e-9
    common = on_common_grid(p, a, side, c)
    assert common.sum() * c**2 == pytest.approx(p.sum() * a**2, rel=1e-12)
    assert relative_l2(common, common) == 0.0


def _levelled_sphere():
    """A rough sphere's levelled map: R = 0.3 mm cap plus a self-affine surface, 100 nm pixels."""
    from amontons.contact.surfaces import self_affine
    from amontons.measure.topography import sphere_cap
    from amontons.simulate.surface import LevelledMap

    n, pixel, radius = 256, 100e-9, 0.3e-3
    rough = self_affine((n, n), pixel, 0.8, rms_height=20e-9, short_cutoff=0.4e-6, rng=2)
    heights = sphere_cap((n, n), pixel, radius, (0.0, 0.0)) + rough
    return LevelledMap(heights, pixel, radius, (0.0, 0.0), float(heights.max()))


RECORD = {
    "sphere": "test",
    "diameter_mm": 0.6,
    "e_star_gpa": 3.7,
    "loads": [1.0, 2.0],
    "hardness_mpa": 200.0,
    "hardening_k_mpa_per_nm": 5.0,
}


@pytest.mark.parametrize(("model", "ratio"), [("hardening", 0.3), ("penetration_hardness", 1.2)])
def test_a_timing_point_sets_its_law_from_its_ratio(model, ratio):
    """k = s·πE*/(2Δx) and p_Y = y·E*·h'/2 give back the ratio asked for (to rounding), and
    the contact extent is the Hertz diameter at the largest load in solver pixels."""
    from amontons.accuracy.problems import timing_problem
    from amontons.physics.hertz import contact_radius

    setting = Setting(2, 1e-4, 1.5, False)
    problem = timing_problem(model, ratio, setting, _levelled_sphere(), RECORD, "test map")
    assert problem.ratio == pytest.approx(ratio, rel=1e-12)
    assert problem.pixel_m == pytest.approx(200e-9)
    diameter = 2 * contact_radius(2e-3, 0.3e-3, 3.7e9)
    assert problem.contact_px == pytest.approx(diameter / 200e-9, rel=1e-12)
