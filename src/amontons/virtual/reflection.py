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

from amontons import hertz
from amontons.virtual.fluorescence import FWHM_PER_SIGMA, UINT16_MAX

WAVELENGTH_M = 488e-9
N_FORMAMIDE = 1.447


def hertz_gap(r_m: np.ndarray, load_n: float, radius_m: float, e_star_pa: float) -> np.ndarray:
    """Gap (m) between a Hertz sphere and the flat at distance ``r_m`` from the centre.

    Outside the contact (r > a; the surface displacement outside a Hertz pressure distribution,
    Johnson 1985 §3.9, with d = a²/R and p0 = 2aE*/πR as in §4.2):
        g(r) = r²/2R − d + u(r),  u(r) = [(2a² − r²)·asin(a/r) + a·√(r² − a²)] / πR,
    and with asin = π/2 − acos this simplifies to
        g(r) = [a·√(r² − a²) − (2a² − r²)·acos(a/r)] / πR,
    which is 0 at r = a, rises as (r − a)^{3/2} next to the edge, and tends to r²/2R − d far
    away (u → 4a³/3πRr). Inside the contact the gap is 0.
    """
    a = hertz.contact_radius(load_n, radius_m, e_star_pa)
    r = np.asarray(r_m, dtype=float)
    outside = np.maximum(r, a)  # keeps acos and the root real; the result is masked below
    gap = (a * np.sqrt(outside**2 - a**2) - (2 * a**2 - outside**2) * np.arccos(a / outside)) / (
        np.pi * radius_m
    )
    return np.where(r > a, gap, 0.0)


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


def ring_gap(order: np.ndarray, wavelength_m: float, n_medium: float) -> np.ndarray:
    """Gap (m) of the bright ring of order m (eq. B.1): d_m = (m + ½)·λ/2n."""
    return (np.asarray(order, dtype=float) + 0.5) * wavelength_m / (2 * n_medium)


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
    wavelength_m: float = WAVELENGTH_M,
    n_medium: float = N_FORMAMIDE,
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
