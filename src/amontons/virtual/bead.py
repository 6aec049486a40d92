"""Forward model of a confocal image of a 100 nm fluorescent bead: the microscope's PSF.

A bead much smaller than the PSF is a point source, so its image is the PSF itself: a Gaussian
of the given FWHM, integrated over each square pixel, on a uniform background, with Poisson
(shot) noise, written as 16-bit counts (appendix B.1.1, Fig. B.2).

Pixel coordinates: the centre of pixel (row i, column j) sits at x = j·pixel_m, y = i·pixel_m.
"""

from __future__ import annotations

import numpy as np
from scipy.special import erf

from amontons.physics.gaussian import FWHM_PER_SIGMA
from amontons.virtual.fluorescence import UINT16_MAX

# Poisson draws reach a few standard deviations above their mean; refuse expected counts this
# many standard deviations below the 16-bit ceiling, so the written image is never clipped.
_SATURATION_MARGIN_SD = 6.0


def _pixel_fractions(n: int, pixel_m: float, centre_m: float, sigma_m: float) -> np.ndarray:
    """Fraction of a 1-D Gaussian (centre, σ in m) falling in each of ``n`` pixels."""
    edges = (np.arange(n + 1) - 0.5) * pixel_m - centre_m
    return np.diff(0.5 * (1 + erf(edges / (np.sqrt(2) * sigma_m))))


def expected_bead_counts(
    shape: tuple[int, int],
    pixel_m: float,
    fwhm_m: float,
    centre_m: tuple[float, float],
    amplitude: float,
    background: float,
) -> np.ndarray:
    """Noise-free expected counts per pixel.

    ``amplitude`` is the peak of the continuous Gaussian in counts per pixel area (the counts a
    pixel centred on the bead would collect if the PSF were flat across it); ``background`` is
    counts per pixel; ``centre_m`` is (x, y) in m.
    """
    if fwhm_m <= 0 or pixel_m <= 0:
        raise ValueError(f"PSF FWHM {fwhm_m} m and pixel {pixel_m} m must be positive")
    if amplitude < 0 or background < 0:
        raise ValueError(
            f"bead amplitude {amplitude} and background {background} counts must be ≥ 0"
        )
    sigma_m = fwhm_m / FWHM_PER_SIGMA
    ny, nx = shape
    fx = _pixel_fractions(nx, pixel_m, centre_m[0], sigma_m)
    fy = _pixel_fractions(ny, pixel_m, centre_m[1], sigma_m)
    # A 2-D Gaussian of unit peak integrates to 2πσ²; per pixel area that is 2πσ²/pixel².
    total = amplitude * 2 * np.pi * sigma_m**2 / pixel_m**2
    return background + total * np.outer(fy, fx)


def render_bead(
    shape: tuple[int, int],
    pixel_m: float,
    fwhm_m: float,
    centre_m: tuple[float, float],
    amplitude: float,
    background: float,
    rng: np.random.Generator,
) -> np.ndarray:
    """Image (uint16 counts) of a point-like bead through a Gaussian PSF of FWHM ``fwhm_m``.

    Raises ValueError when the expected counts come within a few Poisson standard deviations
    of the 16-bit ceiling, because a clipped bead would no longer show the PSF.
    """
    expected = expected_bead_counts(shape, pixel_m, fwhm_m, centre_m, amplitude, background)
    peak = float(expected.max())
    if peak + _SATURATION_MARGIN_SD * np.sqrt(peak) > UINT16_MAX:
        raise ValueError(
            f"bead peak of {peak:.0f} expected counts would saturate uint16 ({UINT16_MAX}); "
            "lower the amplitude or background"
        )
    return rng.poisson(expected).astype(np.uint16)
