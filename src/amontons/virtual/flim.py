"""Forward models of a fluorescence-lifetime image (Fig. B.3).

Confined rigidochromic molecules in the contact emit later (1.3 ns for PS on glass) than the
free molecules outside. Two renderings of the same contact:

- :func:`render_flim`: the mean photon arrival time map (ns, float32) that FLIM software
  exports, each pixel scattered by Gaussian noise of ``noise_ns`` standing in for the photon
  statistics (``flim.tif``);
- :func:`photon_histograms`: what the MicroTime 200 records (``flim.ptu``): per pixel a
  Poisson number of photons, each arriving after the sync pulse at the instrument response's
  peak plus a Gaussian jitter (the instrument response) plus an exponential delay of the
  pixel's lifetime, folded into the laser period and counted in its TCSPC bin.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from amontons.physics.gaussian import FWHM_PER_SIGMA


def render_flim(
    contact_mask: np.ndarray,
    in_contact_ns: float = 1.3,
    outside_ns: float = 0.5,
    noise_ns: float = 0.1,
    *,
    rng: np.random.Generator,
) -> np.ndarray:
    """Mean photon arrival time map (ns, float32) of a contact given as a boolean mask."""
    mask = np.asarray(contact_mask, dtype=bool)
    if noise_ns < 0 or in_contact_ns <= 0 or outside_ns <= 0:
        raise ValueError(
            f"arrival times {in_contact_ns}, {outside_ns} ns must be > 0 and noise {noise_ns} "
            "ns ≥ 0"
        )
    mean = np.where(mask, in_contact_ns, outside_ns)
    return (mean + rng.normal(0.0, noise_ns, mask.shape)).astype(np.float32)


@dataclass(frozen=True)
class TcspcSettings:
    """The virtual FLIM microscope's photon counting, SI units.

    ``photons_per_pixel``: mean photons per pixel (each pixel's count is Poisson);
    ``irf_fwhm_s``: FWHM of the Gaussian instrument response; ``irf_peak_s``: its peak after
    the sync pulse; ``bin_s``: the TCSPC bin; ``sync_period_s``: the laser period.
    """

    photons_per_pixel: float
    irf_fwhm_s: float
    irf_peak_s: float
    bin_s: float
    sync_period_s: float

    def __post_init__(self):
        if not 0 < self.bin_s < self.sync_period_s:
            raise ValueError(
                f"TCSPC bin {self.bin_s:g} s must be > 0 and shorter than the laser period "
                f"{self.sync_period_s:g} s"
            )
        if self.photons_per_pixel <= 0 or self.irf_fwhm_s <= 0:
            raise ValueError(
                f"photons per pixel {self.photons_per_pixel:g} and instrument response FWHM "
                f"{self.irf_fwhm_s:g} s must be > 0"
            )
        if not 0 <= self.irf_peak_s < self.sync_period_s:
            raise ValueError(
                f"instrument response peak {self.irf_peak_s:g} s must lie within the laser "
                f"period {self.sync_period_s:g} s"
            )

    @property
    def irf_sigma_s(self) -> float:
        """Standard deviation of the Gaussian instrument response (s)."""
        return self.irf_fwhm_s / FWHM_PER_SIGMA

    @property
    def bins(self) -> int:
        """TCSPC bins in one laser period (the last one may be cut by the next sync pulse)."""
        return int(np.ceil(self.sync_period_s / self.bin_s - 1e-9))

    @classmethod
    def from_config(cls, settings: Mapping) -> TcspcSettings:
        """From the ``virtual_experiment`` config slice (units in the key names)."""
        return cls(
            photons_per_pixel=settings["flim_photons_per_pixel"],
            irf_fwhm_s=settings["flim_irf_fwhm_ps"] * 1e-12,
            irf_peak_s=settings["flim_irf_peak_ns"] * 1e-9,
            bin_s=settings["flim_tcspc_bin_ps"] * 1e-12,
            sync_period_s=1.0 / (settings["flim_sync_rate_mhz"] * 1e6),
        )


def photon_histograms(
    lifetime_s: np.ndarray, tcspc: TcspcSettings, *, rng: np.random.Generator
) -> np.ndarray:
    """TCSPC histograms (rows × columns × ``tcspc.bins``, uint16, or uint32 where a bin
    holds more than 65535 photons) of pixels with the mono-exponential lifetimes
    ``lifetime_s`` (s): per pixel Poisson(``photons_per_pixel``) photons, each at
    t = irf_peak + N(0, σ_irf) + Exp(τ) after the sync, folded into the period, in bin
    ⌊t/Δt⌋. The mean arrival time of a pixel is irf_peak + τ (the fold moves a share
    exp(-(T - irf_peak)/τ) of its photons, 1e-8 at 1.3 ns in a 25 ns period)."""
    lifetime = np.asarray(lifetime_s, dtype=float)
    if lifetime.ndim != 2 or not np.all(lifetime > 0):
        raise ValueError(f"lifetimes of shape {lifetime.shape}; expected a 2-D map of values > 0")
    rows, cols = lifetime.shape
    bins = tcspc.bins
    counts = np.zeros((rows, cols, bins), np.int64)
    for row in range(rows):
        photons = rng.poisson(tcspc.photons_per_pixel, cols)
        tau = np.repeat(lifetime[row], photons)
        arrival = tcspc.irf_peak_s + rng.normal(0.0, tcspc.irf_sigma_s, tau.size)
        arrival = np.mod(arrival + rng.exponential(tau), tcspc.sync_period_s)
        bin_index = np.minimum((arrival / tcspc.bin_s).astype(np.int64), bins - 1)
        pixel = np.repeat(np.arange(cols), photons)
        counts[row] = np.bincount(pixel * bins + bin_index, minlength=cols * bins).reshape(
            cols, bins
        )
    dtype = np.uint16 if counts.max() <= np.iinfo(np.uint16).max else np.uint32
    return counts.astype(dtype)
