"""Self-affine sphere roughness with one power spectrum across grids (SI units, heights in m).

The virtual experiment needs the *same* surface at two resolutions: the AFM's own pixel
(32 nm, a window of tens of µm near the apex) and the coarser grid of the contact solve
(which must hold the largest contact, up to a few hundred µm). Both are drawn from one
isotropic power spectral density

    C(q) = C0 · max(q, q_r)^(-2-2H)        (<h²> = ∫ C(q) d²q)

with Hurst exponent H and roll-off wavevector q_r = 2π/λ_r. The solver grid carries the
modes it can represent (|q_x|, |q_y| below its Nyquist limit); the AFM window adds the band
between that limit and its own Nyquist limit as an independent field. C0 is fixed by the rms
height the sphere shows at the AFM pixel (the number a tribologist reads off their AFM
map), so the spectrum, and not a grid, is the truth.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Roughness:
    """Roughness of a sphere: ``rms_m`` (m) over the band from the roll-off wavelength
    ``rolloff_m`` (m) down to the Nyquist wavelength of ``reference_pixel_m`` (m), Hurst
    exponent ``hurst``."""

    rms_m: float
    hurst: float
    rolloff_m: float
    reference_pixel_m: float

    def __post_init__(self):
        if not (np.isfinite(self.rms_m) and self.rms_m >= 0):
            raise ValueError(f"roughness rms must be >= 0 (m), got {self.rms_m!r}")
        if not 0 < self.hurst < 1:
            raise ValueError(f"Hurst exponent must be in (0, 1), got {self.hurst!r}")
        if not self.rolloff_m > 2 * self.reference_pixel_m > 0:
            raise ValueError(
                f"roll-off wavelength {self.rolloff_m!r} m must exceed two reference pixels "
                f"({2 * self.reference_pixel_m!r} m)"
            )

    @property
    def prefactor(self) -> float:
        """C0 of the spectrum (m^(2-2H)), such that ∫ C d²q over the reference band = rms²."""
        h = self.hurst
        q_r = 2 * np.pi / self.rolloff_m
        q_max = np.pi / self.reference_pixel_m
        # flat disc below q_r: π q_r² · q_r^(-2-2H); power law above: 2π ∫ q^(-1-2H) dq
        integral = np.pi * q_r ** (-2 * h) + 2 * np.pi * (q_r ** (-2 * h) - q_max ** (-2 * h)) / (
            2 * h
        )
        return self.rms_m**2 / integral

    def psd(self, q: np.ndarray) -> np.ndarray:
        """C(q), m⁴ (isotropic, 2-D)."""
        q_r = 2 * np.pi / self.rolloff_m
        return self.prefactor * np.maximum(q, q_r) ** (-2 - 2 * self.hurst)


def synthesize(
    shape: tuple[int, int],
    spacing: float,
    roughness: Roughness,
    rng: np.random.Generator,
    *,
    above_m: float | None = None,
) -> np.ndarray:
    """A periodic random field (m) on ``shape`` with the spectrum of ``roughness``.

    Modes beyond the grid's Nyquist limit are absent (Nyquist modes themselves are dropped:
    their derivatives are undefined on the grid). ``above_m``: keep only the modes that a grid
    of this spacing cannot carry (max(|q_x|, |q_y|) ≥ π/above_m) - the band a finer window
    adds to a coarser one.
    """
    n0, n1 = shape
    q0 = 2 * np.pi * np.fft.fftfreq(n0, d=spacing)[:, None]
    q1 = 2 * np.pi * np.fft.rfftfreq(n1, d=spacing)[None, :]
    q = np.hypot(q0, q1)
    # a mode of a periodic n·Δx window carries the power C(q)·Δq², Δq² = (2π)²/(n0 n1 Δx²);
    # white noise through rfft2/irfft2 turns a filter amp into a power amp²/(n0 n1)
    amp = np.sqrt(roughness.psd(np.where(q > 0, q, 1.0))) * (2 * np.pi / spacing)
    amp[0, 0] = 0.0
    if n0 % 2 == 0:
        amp[n0 // 2, :] = 0.0
    if n1 % 2 == 0:
        amp[:, n1 // 2] = 0.0
    if above_m is not None:
        limit = np.pi / above_m
        amp[np.maximum(np.abs(q0), np.abs(q1)) < limit] = 0.0
    spectrum = np.fft.rfft2(rng.standard_normal(shape)) * amp
    return np.fft.irfft2(spectrum, s=shape)
