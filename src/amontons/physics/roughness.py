"""Statistics of a height map (docs/models.md §1.8, §2.6): rms height, slope and curvature at
the map's own pixel."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


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
