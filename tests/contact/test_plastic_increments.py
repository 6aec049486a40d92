"""Plastic increments (appendix eqs. B.2 and B.3): sign, locality and volume conservation."""

import numpy as np

from amontons.contact.plastic_increments import local_increment, volume_conserving_increment


def _random_gap(seed=0, shape=(64, 48)):
    rng = np.random.default_rng(seed)
    return rng.normal(0, 1e-9, shape)


def test_local_increment_removes_exactly_the_penetration():
    gap = _random_gap()
    increment = local_increment(gap)
    assert np.all(increment <= 0)
    np.testing.assert_array_equal(increment[gap >= 0], 0)
    # After the increment the gap of a fixed elastic field is max(g, 0) >= 0.
    assert np.all(gap - increment >= 0)


def test_volume_conserving_increment_sums_to_zero_periodic():
    gap = _random_gap(1)
    increment = volume_conserving_increment(gap, periodic=True)
    removed = np.abs(np.minimum(gap, 0)).sum()
    # Round-off: a few ulp of the total moved volume.
    assert abs(increment.sum()) < 1e-12 * removed


def test_volume_conserving_increment_sums_to_zero_inside_a_window():
    gap = np.full((32, 32), 1e-9)
    gap[10:20, 12:18] = _random_gap(2, (10, 6))
    increment = volume_conserving_increment(gap, periodic=False)
    assert abs(increment.sum()) < 1e-12 * np.abs(np.minimum(gap, 0)).sum()


def test_single_penetrating_pixel_piles_up_on_its_four_neighbours():
    gap = np.full((5, 5), 1e-9)
    gap[2, 2] = -4e-9
    increment = volume_conserving_increment(gap, periodic=False)
    expected = np.zeros((5, 5))
    expected[2, 2] = -4e-9
    expected[1, 2] = expected[3, 2] = expected[2, 1] = expected[2, 3] = 1e-9
    np.testing.assert_allclose(increment, expected, rtol=0, atol=1e-24)
