"""Forward model of a confocal fluorescence image of a rigidochromic contact.

Emission: molecules light up where they are confined in the contact, and brighten with the
degree of confinement as √(local pressure) (appendix Fig. B.4). A molecule trapped in the
contact is confined even where the contact pressure vanishes, so its brightness does not fall
below that of a confinement floor p_c: emission ∝ √max(p, p_c) in contact, 0 outside. With
p_c > 0 the contact and background populations hardly overlap and the contact looks
homogeneous, as the appendix reports (B.1.1, Fig. B.3) and as its comparison of PSF-blurred
binary contact maps with Otsu areas (B.2.4) presumes; p_c = 0 is the bare √p law, whose rim
fades to the background. The signal is blurred by a Gaussian PSF, put on a uniform background
with Poisson (shot) noise and written as 16-bit counts.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import gaussian_filter

from amontons.physics.gaussian import FWHM_PER_SIGMA

UINT16_MAX = np.iinfo(np.uint16).max


def pixel_averaged(field, shape: tuple[int, int], pixel_m: float, supersample: int = 4):
    """Average ``field(x, y)`` (x, y in m, origin at the image centre) over each pixel.

    Each pixel is sampled on a ``supersample``² sub-grid, so that an edge crossing a pixel
    contributes its covered fraction rather than all or nothing.
    """
    ny, nx = shape
    sub = pixel_m / supersample
    xs = (np.arange(nx * supersample) - (nx * supersample - 1) / 2) * sub
    ys = (np.arange(ny * supersample) - (ny * supersample - 1) / 2) * sub
    values = field(xs[None, :], ys[:, None])
    return values.reshape(ny, supersample, nx, supersample).mean(axis=(1, 3))


def render_fluorescence(
    signal: np.ndarray,
    pixel_m: float,
    *,
    psf_fwhm_m: float,
    background_counts: float,
    rng: np.random.Generator,
) -> np.ndarray:
    """Blur a noiseless contact signal (counts) with the PSF, add background and shot noise.

    Returns uint16 counts; raises ValueError if the expected counts would saturate 16 bits,
    because a clipped image is not what the forward model describes.
    """
    sigma_px = psf_fwhm_m / FWHM_PER_SIGMA / pixel_m
    expected = gaussian_filter(np.asarray(signal, dtype=float), sigma_px, mode="constant")
    expected += background_counts
    if expected.max() > UINT16_MAX:
        raise ValueError(
            f"expected counts reach {expected.max():.0f} > {UINT16_MAX}; lower contact_counts"
        )
    counts = rng.poisson(np.clip(expected, 0, None))
    return np.minimum(counts, UINT16_MAX).astype(np.uint16)
