"""Statistics of a height map (docs/models.md §1.8, §2.6): rms height, slope and curvature at
the map's own pixel."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage


@dataclass(frozen=True)
class RoughnessStatistics:
    """h_rms (m), h'_rms = √⟨|∇h|²⟩ (dimensionless), h''_rms = rms of the mean curvature ½∇²h
    (1/m; the convention of SurfaceTopography's rms_curvature; rms(∇²h) is twice it)."""

    h_rms_m: float
    slope_rms: float
    curvature_rms_per_m: float


def roughness_statistics(roughness: np.ndarray, pixel_m: float) -> RoughnessStatistics:
    """Statistics of a roughness map by finite differences at its own pixel (the value of h'
    and h'' depends on the pixel: report it with them)."""
    gy, gx = np.gradient(roughness, pixel_m)
    laplacian = (
        roughness[2:, 1:-1]
        + roughness[:-2, 1:-1]
        + roughness[1:-1, 2:]
        + roughness[1:-1, :-2]
        - 4 * roughness[1:-1, 1:-1]
    ) / pixel_m**2
    return RoughnessStatistics(
        h_rms_m=float(np.std(roughness)),
        slope_rms=float(np.sqrt(np.mean(gx**2 + gy**2))),
        curvature_rms_per_m=float(np.sqrt(np.mean((0.5 * laplacian) ** 2))),
    )


# Gaussian smoothing (px) of the drop that decides which pixels count for the flattening
# depth: white noise of sd σ leaves σ/(2√π s) = 0.14 σ at s = 2 px. Part of the definition:
# the measurement and the virtual experiment's truth use the same (docs/models.md §1.8).
FLATTENING_SMOOTHING_PX = 2.0


def flattening_depth(
    drop_m: np.ndarray, *, smoothing_px: float = FLATTENING_SMOOTHING_PX, floor_m: float = 0.0
) -> tuple[float | None, np.ndarray]:
    """Depth of a flattening (m) and the pixels it is taken over (docs/models.md §1.8).

    The depth D is the median of ``drop_m`` (how far the surface went down, m; a 2-D map)
    over the pixels that went down by more than half of it, as seen through a Gaussian of
    ``smoothing_px``: D = median{drop : smoothed drop > max(D/2, floor)}. The smoothing lets
    the noise of a measured map not decide which pixels count; ``floor_m`` is the least
    smoothed drop that counts at all. Of several such D (a deep patch amid a shallow one)
    the largest is taken, found by iterating down from the deepest pixel: the median falls
    as the cut does, so the sequence descends to it.

    For a uniform flattening wider than the smoothing the half-depth contour is its edge,
    wherever a blur or noise put the region's rim, so D is its depth; for an uneven one D is
    the typical depth of its deeper part. None (and an empty mask) when no pixel passes the
    floor.
    """
    membership = ndimage.gaussian_filter(drop_m, smoothing_px, mode="nearest")
    core = membership > floor_m
    if not core.any():
        return None, core
    core = membership >= membership[core].max()
    depth = float(np.median(drop_m[core]))
    for _ in range(200):
        new_core = membership > max(depth / 2, floor_m)
        if not new_core.any():
            break
        core = new_core
        new_depth = float(np.median(drop_m[core]))
        if abs(new_depth - depth) <= 1e-6 * abs(depth):
            return new_depth, core
        depth = new_depth
    return depth, core
