"""Plastic displacement increments of appendix B.2.3 (eqs. B.2 and B.3; docs/models.md §2.3).

Sign convention (as the solver's): heights h of the rigid indenter, larger = closer to the
elastic body; the gap g = u − h − d is negative where the indenter penetrates. A plastic
displacement h_pl ≤ 0 lowers the indenter: the deformed topography is h' = h + h_pl.

* Local (B.2): Δh_pl = g·θ(−g). Every penetration is removed where it happens; volume is lost.
* Volume-conserving (B.3): the penetration G = g·θ(−g) of each pixel is removed there and a
  quarter of it is added to each of its four neighbours (pile-up),

      Δh_pl[x, y] = G[x, y] − (G[x+1, y] + G[x−1, y] + G[x, y+1] + G[x, y−1]) / 4,

  so Σ Δh_pl = 0 exactly. (The appendix prints θ(−g_xy) on the whole bracket, which does not
  sum to zero; the text's intent, "distribution of the deformed volume to neighbouring grid
  points", is the form above.) Neighbours wrap around on a periodic grid; on a non-periodic
  grid, volume pushed past the window edge is lost — the contact must stay inside the window,
  which the solver checks, so in practice G vanishes on the edge and nothing is lost.

All arrays in metres.
"""

from __future__ import annotations

import numpy as np


def penetration(gap: np.ndarray) -> np.ndarray:
    """G = g·θ(−g): the (negative) gap where the indenter penetrates, 0 elsewhere."""
    return np.minimum(gap, 0.0)


def local_increment(gap: np.ndarray) -> np.ndarray:
    """Eq. B.2: Δh_pl = g·θ(−g)."""
    return penetration(gap)


def _neighbour_sum(field: np.ndarray, periodic: bool) -> np.ndarray:
    if periodic:
        return (
            np.roll(field, 1, axis=0)
            + np.roll(field, -1, axis=0)
            + np.roll(field, 1, axis=1)
            + np.roll(field, -1, axis=1)
        )
    padded = np.pad(field, 1)
    return padded[:-2, 1:-1] + padded[2:, 1:-1] + padded[1:-1, :-2] + padded[1:-1, 2:]


def volume_conserving_increment(gap: np.ndarray, periodic: bool) -> np.ndarray:
    """Eq. B.3 as a redistribution: Δh_pl = G − (sum of the four neighbours' G)/4."""
    g = penetration(gap)
    return g - 0.25 * _neighbour_sum(g, periodic)


def increment(gap, increment: str, periodic: bool):
    """The plastic increment (m) of ``gap`` (m): local (eq. B.2) or volume-conserving
    (eq. B.3, ``increment="volume"``)."""
    if increment == "local":
        return local_increment(gap)
    return volume_conserving_increment(gap, periodic)


def penetration_at_bound(pressure, gap, p_max):
    """The negative gap (m) where the pressure is at its bound ``p_max`` (Pa), 0 elsewhere.

    Only points at the bound yield (appendix: "where p = p_Y the material deforms
    plastically"); a free point's gap is the elastic solver's residual, not flow. BoundedWall
    clips to the bound exactly, so ``>=`` is ``==`` there."""
    return np.where((pressure >= p_max) & (gap < 0.0), gap, 0.0)
