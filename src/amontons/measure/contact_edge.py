"""Where each line profile leaves the contact: the per-profile fluorescent edge of appendix
Fig. B.7a (docs/models.md §1.5).

The appendix marks the edge on each line profile where that profile crosses the Otsu
threshold (its green squares) and averages the profiles afterwards. Along a ray from the
contact centre the edge is therefore the outermost contact pixel of the Otsu mask on that
ray. For a round, compact contact this is the radius of the disc with the mask's area; for a
patchy contact, whose islands reach far beyond that disc, only the per-ray edge is where the
profile's light stops.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

# Samples per pixel along a ray: the edge is found to ±1/20 px, far below the PSF.
_STEP_PX = 0.1


def close_mask(mask: np.ndarray, radius_px: int) -> np.ndarray:
    """``mask`` closed (dilated, then eroded) by a disc of ``radius_px`` pixels: gaps between
    contact patches narrower than the disc, which the microscope does not resolve, join the
    contact. The image is padded first, so a contact at the border is not eroded by it.
    ``radius_px`` 0 returns the mask unchanged."""
    mask = np.asarray(mask, dtype=bool)
    if radius_px < 0:
        raise ValueError(f"closing radius {radius_px} px; expected ≥ 0")
    if radius_px == 0:
        return mask.copy()
    yy, xx = np.mgrid[-radius_px : radius_px + 1, -radius_px : radius_px + 1]
    disc = xx**2 + yy**2 <= radius_px**2
    pad = radius_px + 1
    closed = ndimage.binary_closing(np.pad(mask, pad), structure=disc)
    return closed[pad:-pad, pad:-pad]


def ray_edge_radii(
    mask: np.ndarray, centre_px: tuple[float, float], angles_rad: np.ndarray
) -> np.ndarray:
    """Distance (px) from ``centre_px`` (row, col) at which each ray leaves the outermost
    contact pixel of ``mask`` on it; NaN for a ray that meets no contact pixel.

    A ray at angle φ (from the +column axis towards +row) is sampled every 0.1 px out to the
    image border; each sample takes the pixel it falls in. The edge is half a step past the
    last sample in contact: where the ray leaves that pixel, to ±0.05 px. Islands and holes
    further in do not matter; only the outermost contact pixel on the ray does.
    """
    mask = np.asarray(mask, dtype=bool)
    if mask.ndim != 2:
        raise ValueError(f"contact mask has shape {mask.shape}; expected 2-D")
    row, col = centre_px
    reach = float(np.hypot(*mask.shape))
    r = np.arange(0.0, reach, _STEP_PX)
    radii = np.full(len(angles_rad), np.nan)
    for k, angle in enumerate(angles_rad):
        rows = np.floor(row + r * np.sin(angle) + 0.5).astype(int)
        cols = np.floor(col + r * np.cos(angle) + 0.5).astype(int)
        inside = (rows >= 0) & (rows < mask.shape[0]) & (cols >= 0) & (cols < mask.shape[1])
        hits = np.nonzero(mask[rows[inside], cols[inside]])[0]
        if hits.size:
            # samples inside the image are a prefix of the ray (it starts at the centre)
            radii[k] = r[hits[-1]] + _STEP_PX / 2
    return radii
