"""Forward model of the absorbance spectrum of a rigidochromic cover slip (Fig. B.1).

A single Gaussian absorption band (the chromophore monolayer, measured against an
APTES-coated reference slip) plus white measurement noise, as a spectrophotometer writes it:
a CSV with columns wavelength_nm, absorbance (decadic, dimensionless).
"""

from __future__ import annotations

import numpy as np

from amontons.physics.gaussian import FWHM_PER_SIGMA


def absorbance_spectrum(
    wavelengths_nm: np.ndarray,
    peak_absorbance: float = 0.0016,
    peak_nm: float = 488.0,
    width_nm: float = 60.0,
    noise_sd: float = 1e-4,
    *,
    rng: np.random.Generator,
) -> np.ndarray:
    """Noisy absorbance at ``wavelengths_nm``: a Gaussian band of FWHM ``width_nm``.

    ``noise_sd`` is the standard deviation of the (white, Gaussian) noise in absorbance units;
    a monolayer's ~10⁻³ absorbance is near the spectrophotometer's noise floor.
    """
    wavelengths_nm = np.asarray(wavelengths_nm, dtype=float)
    if width_nm <= 0 or noise_sd < 0:
        raise ValueError(f"band width {width_nm} nm must be > 0 and noise sd {noise_sd} ≥ 0")
    sigma_nm = width_nm / FWHM_PER_SIGMA
    band = peak_absorbance * np.exp(-0.5 * ((wavelengths_nm - peak_nm) / sigma_nm) ** 2)
    return band + rng.normal(0.0, noise_sd, size=wavelengths_nm.shape)
