"""Forward model of an AFM height map of the sphere near its apex (heights in m, TIFF).

The scan sees the true surface at its own pixel - the paraboloid, the roughness the contact
solve resolves (interpolated from the solver grid, bicubic) plus the finer band the solver
grid cannot carry (:func:`amontons.virtual.roughness.synthesize` with ``above_m``) - and
adds what an AFM adds: white height noise and a few scan lines shifted by a constant offset
(the raw data keeps the sphere curvature; levelling is the analysis' job).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class AfmSettings:
    """Pixel (m), side (px), height noise (m rms), number and size (m) of line offsets."""

    pixel_m: float
    side_px: int
    noise_m: float
    line_offsets: int
    line_offset_m: float


def scan_artefacts(shape, settings: AfmSettings, rng: np.random.Generator) -> np.ndarray:
    """White noise plus ``line_offsets`` scan lines shifted by ±``line_offset_m``, m."""
    artefacts = rng.normal(0.0, settings.noise_m, shape)
    lines = rng.choice(shape[0], size=min(settings.line_offsets, shape[0]), replace=False)
    signs = rng.choice([-1.0, 1.0], size=lines.size)
    artefacts[lines] += signs[:, None] * settings.line_offset_m
    return artefacts
