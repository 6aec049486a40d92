"""Forward model of the reflection image: Newton rings around the contact (Figs. B.6, B.7).

Light reflected at the slip–liquid and liquid–sphere interfaces interferes (two-beam):
I = B·[1 + V·cos(4π n d/λ + φ)], with d the local gap (m), n the liquid's refractive index,
B the mean counts and V the fringe contrast. Appendix eq. B.1 puts the bright rings (maxima)
at d_m = (m + ½)·λ/2n, so 4πn·d_m/λ = 2πm + π must be a maximum of the cosine: φ = π, i.e.
I = B·[1 − V·cos(4πnd/λ)] — dark where the surfaces touch (d = 0), as in the classic Newton
pattern where one of the two reflections carries a half-wave phase jump.
The image is blurred by the PSF, gets Poisson noise and is written as uint16 counts.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.ndimage import gaussian_filter

from amontons.physics.gaussian import FWHM_PER_SIGMA
from amontons.physics.newton_rings import APPENDIX_WAVELENGTH_M, FORMAMIDE_REFRACTIVE_INDEX
from amontons.virtual.fluorescence import UINT16_MAX


def radial_gap_map(
    shape: tuple[int, int],
    pixel_m: float,
    centre_px: tuple[float, float],
    gap_of_r: Callable[[np.ndarray], np.ndarray],
) -> np.ndarray:
    """Gap map (m) of an axisymmetric gap ``gap_of_r(r_m)`` about ``centre_px`` (row, col)."""
    rows, cols = np.indices(shape)
    r_m = np.hypot(rows - centre_px[0], cols - centre_px[1]) * pixel_m
    return gap_of_r(r_m)


def expected_reflection(
    gap_m: np.ndarray,
    wavelength_m: float,
    n_medium: float,
    background: float,
    contrast: float,
) -> np.ndarray:
    """Noise-free two-beam intensity B·[1 − V·cos(4πnd/λ)] (counts), bright at d_m of eq. B.1."""
    gap_m = np.asarray(gap_m, dtype=float)
    if not np.all(np.isfinite(gap_m)) or np.any(gap_m < 0):
        raise ValueError("gap map must be finite and ≥ 0 m (0 in contact)")
    if not 0 <= contrast <= 1 or background <= 0:
        raise ValueError(
            f"fringe contrast {contrast} must be in [0, 1] and background {background} counts > 0"
        )
    phase = 4 * np.pi * n_medium * gap_m / wavelength_m + np.pi
    return background * (1 + contrast * np.cos(phase))


def render_reflection(
    gap_m: np.ndarray,
    pixel_m: float,
    wavelength_m: float = APPENDIX_WAVELENGTH_M,
    n_medium: float = FORMAMIDE_REFRACTIVE_INDEX,
    background: float = 400.0,
    contrast: float = 0.6,
    psf_fwhm_m: float = 450e-9,
    *,
    rng: np.random.Generator,
) -> np.ndarray:
    """Reflection image (uint16 counts) of a gap map ``gap_m`` (m) with square pixels.

    Raises ValueError when the expected counts would saturate 16 bits.
    """
    expected = expected_reflection(gap_m, wavelength_m, n_medium, background, contrast)
    sigma_px = psf_fwhm_m / FWHM_PER_SIGMA / pixel_m
    expected = gaussian_filter(expected, sigma_px, mode="nearest")
    peak = float(expected.max())
    if peak + 6 * np.sqrt(peak) > UINT16_MAX:
        raise ValueError(
            f"reflection peak of {peak:.0f} expected counts would saturate uint16 "
            f"({UINT16_MAX}); lower the background"
        )
    return rng.poisson(expected).astype(np.uint16)
