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
