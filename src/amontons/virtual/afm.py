"""Forward model of an AFM height map of the sphere near its apex (heights in m, TIFF).

The scan sees the true surface at its own pixel - the paraboloid, the roughness the contact
solve resolves (interpolated from the solver grid, bicubic) plus the finer band the solver
grid cannot carry (:func:`amontons.virtual.roughness.synthesize` with ``above_m``) - and
adds what an AFM adds: white height noise and a few scan lines shifted by a constant offset
(the raw data keeps the sphere curvature; levelling is the analysis' job).

The AFM frame is not the microscope's: the sphere is turned over between the two instruments
and laid down at some angle, so the scan is mirrored and rotated with respect to the
fluorescence images, and its centre sits off the apex. :func:`afm_to_microscope` is that map;
the comparison of simulated with measured contacts has to find it again (registration).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class AfmSettings:
    """Finest pixel (m), side (px), height noise (m rms), number and size (m) of line offsets;
    the scan's side as a multiple of the Hertz contact diameter at the largest load (the
    pixel grows beyond ``pixel_m`` when ``side_px`` cannot cover it); the frame: rotation
    (degrees, counter-clockwise as displayed) and mirror of the scan in the microscope's
    frame."""

    pixel_m: float
    side_px: int
    noise_m: float
    line_offsets: int
    line_offset_m: float
    field_factor: float = 2.0
    rotation_deg: float = 0.0
    mirrored: bool = False

    def scan_pixel_m(self, largest_hertz_radius_m: float) -> float:
        """Pixel (m) of a scan covering ``field_factor`` × the largest Hertz diameter."""
        return max(self.pixel_m, self.field_factor * 2 * largest_hertz_radius_m / self.side_px)

    def footprint_m(self, scan_pixel_m: float) -> float:
        """Side (m) of the axis-aligned square of the microscope frame that holds the rotated
        scan wherever its centre falls (up to ``MAX_APEX_OFFSET`` of its side off the apex)."""
        side = self.side_px * scan_pixel_m
        theta = np.deg2rad(self.rotation_deg)
        return side * (abs(np.cos(theta)) + abs(np.sin(theta)) + 2 * MAX_APEX_OFFSET)


# A real scan is centred near the apex, not on it: up to this fraction of its side off.
MAX_APEX_OFFSET = 0.1


def afm_to_microscope(
    rows_m: np.ndarray, cols_m: np.ndarray, settings: AfmSettings, centre_m: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Microscope-frame positions (row, col; m about the apex) of AFM-frame positions (m about
    the scan centre): mirror the column axis if ``mirrored``, rotate by ``rotation_deg``
    counter-clockwise as displayed (rows grow downward), then shift by ``centre_m`` (the scan
    centre in the microscope frame).

    The same map as amontons.simulate.register.Registration's, written apart on purpose: the
    truth of the registration test must not come from the code under test."""
    theta = np.deg2rad(settings.rotation_deg)
    cols = -cols_m if settings.mirrored else cols_m
    rows_q = np.cos(theta) * rows_m - np.sin(theta) * cols + centre_m[0]
    cols_q = np.sin(theta) * rows_m + np.cos(theta) * cols + centre_m[1]
    return rows_q, cols_q


def scan_artefacts(shape, settings: AfmSettings, rng: np.random.Generator) -> np.ndarray:
    """White noise plus ``line_offsets`` scan lines shifted by ±``line_offset_m``, m."""
    artefacts = rng.normal(0.0, settings.noise_m, shape)
    lines = rng.choice(shape[0], size=min(settings.line_offsets, shape[0]), replace=False)
    signs = rng.choice([-1.0, 1.0], size=lines.size)
    artefacts[lines] += signs[:, None] * settings.line_offset_m
    return artefacts
