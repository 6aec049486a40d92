"""Where each line profile leaves the contact (appendix Fig. B.7a's green squares)."""

import numpy as np
import pytest

from amontons.measure.contact_edge import close_mask, ray_edge_radii

CENTRE = (50.0, 50.0)
EAST, NORTH, WEST, SOUTH = 0.0, np.pi / 2, np.pi, 3 * np.pi / 2


def _disc(mask, centre, radius):
    rows, cols = np.indices(mask.shape)
    mask[np.hypot(rows - centre[0], cols - centre[1]) <= radius] = True


def test_two_islands_on_one_ray_give_the_outer_island_edge():
    # A central patch of radius 10 px and an island at 30–34 px east: the east ray leaves the
    # contact at the island's outer pixel (col 84, whose far side is 34.5 px from the
    # centre), the west ray at the patch (col 40: 10.5 px).
    mask = np.zeros((101, 101), bool)
    _disc(mask, CENTRE, 10)
    mask[48:53, 80:85] = True
    east, west = ray_edge_radii(mask, CENTRE, np.array([EAST, WEST]))
    assert east == pytest.approx(34.5, abs=0.06)
    assert west == pytest.approx(10.5, abs=0.06)


def test_a_hole_does_not_move_the_edge():
    # An annulus of radii 5 and 20 px: the hole in the middle is ignored; every ray leaves
    # the contact at its outer rim, 20.5 px along the axes.
    mask = np.zeros((101, 101), bool)
    _disc(mask, CENTRE, 20)
    hole = np.zeros_like(mask)
    _disc(hole, CENTRE, 5)
    mask &= ~hole
    radii = ray_edge_radii(mask, CENTRE, np.array([EAST, NORTH, WEST, SOUTH]))
    np.testing.assert_allclose(radii, 20.5, atol=0.06)


def test_a_ray_meeting_no_contact_has_no_edge():
    # A crescent: contact only east of the centre; the west ray meets none (NaN).
    mask = np.zeros((101, 101), bool)
    mask[40:61, 55:70] = True
    east, west = ray_edge_radii(mask, CENTRE, np.array([EAST, WEST]))
    assert east == pytest.approx(19.5, abs=0.06)
    assert np.isnan(west)


def test_per_ray_edges_of_a_disc_average_to_its_equal_area_radius():
    # A compact contact: the per-profile edge agrees with the equal-area radius (within
    # 0.1 px averaged over 40 rays; single rays differ by the pixel staircase, a pixel's
    # corner reaching √2/2 px beyond its centre: spread < 1.5 px).
    mask = np.zeros((101, 101), bool)
    _disc(mask, (50.3, 49.6), 17.2)
    rows, cols = np.nonzero(mask)
    centre = (rows.mean(), cols.mean())
    radii = ray_edge_radii(mask, centre, np.arange(40) * np.pi / 20)
    assert np.mean(radii) == pytest.approx(np.sqrt(mask.sum() / np.pi), abs=0.1)
    assert np.ptp(radii) < 1.5


def test_closing_joins_patches_closer_than_the_disc():
    # Two patches 2 px apart on the east ray: unclosed, the ray between them still sees the
    # outer one; the closing fills the 2 px gap (and never removes a pixel).
    mask = np.zeros((101, 101), bool)
    mask[45:56, 45:61] = True
    mask[45:56, 63:70] = True
    closed = close_mask(mask, 2)
    assert closed[50, 61] and closed[50, 62]
    assert np.all(closed[mask])
    np.testing.assert_array_equal(close_mask(mask, 0), mask)
    with pytest.raises(ValueError, match="closing radius -1 px"):
        close_mask(mask, -1)
