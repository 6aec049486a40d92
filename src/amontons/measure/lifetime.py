"""Mean photon arrival time inside and outside the contact (appendix Fig. B.3).

The arrival time is an independent, intensity-free measure of confinement: the appendix
finds 1.3 ns inside a PS–glass contact (2.5 ns in bulk polymer). Pixels next to the mask
boundary mix both populations through the PSF, so ``exclude_edge_px`` can leave a band of
that width out on both sides.

The FLIM file is either the map of mean arrival times that FLIM software exports
(``flim.tif``, ns) or the time-tagged photons the MicroTime 200 saves (``flim.ptu``,
amontons.io.ptu). From the photons, a pixel's mean arrival time is its photons' mean delay
after the sync pulse less the time origin: the peak of the instrument response, either given
(from a measured instrument response) or fitted to the whole image's decay
(:func:`fit_time_origin`; docs/models.md §1.6 says why the peak and not the decay's rise).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.ndimage import binary_erosion
from scipy.optimize import minimize
from scipy.special import expit, log_ndtr, ndtr

from amontons.io.layout import RawDataError
from amontons.io.ptu import PhotonImage
from amontons.io.rawdata import read_flim, read_flim_photons
from amontons.io.tiff import Image
from amontons.measure.area import OtsuSettings, separated_contact
from amontons.physics.gaussian import FWHM_PER_SIGMA


@dataclass(frozen=True)
class TimeOrigin:
    """Where the arrival times start: the instrument response's peak after the sync (ns), with
    its standard error (ns; 0 for a given origin), how it was found, and for a fitted origin
    the fit's instrument response FWHM and two lifetimes (ns)."""

    after_sync_ns: float
    standard_error_ns: float
    method: str
    irf_fwhm_ns: float | None = None
    lifetimes_ns: tuple[float, float] | None = None

    def to_record(self) -> dict:
        """JSON-ready record, units in the key names."""
        return {
            "after_sync_ns": self.after_sync_ns,
            "standard_error_ns": self.standard_error_ns,
            "method": self.method,
            "irf_fwhm_ns": self.irf_fwhm_ns,
            "fit_lifetimes_ns": None if self.lifetimes_ns is None else list(self.lifetimes_ns),
        }


@dataclass(frozen=True)
class LifetimeStatistics:
    """Mean, sd, standard error and pixel count of the arrival time (ns) in and out."""

    inside_mean_ns: float
    inside_sd_ns: float
    inside_se_ns: float
    inside_n: int
    outside_mean_ns: float
    outside_sd_ns: float
    outside_se_ns: float
    outside_n: int
    photons: dict | None = None
    time_origin: TimeOrigin | None = None

    def to_record(self, exclude_edge_px: int) -> dict:
        """JSON-ready record, units in the key names (``exclude_edge_px``: the band left out
        on both sides of the edge); from photons, also the photon counts behind each side's
        means and the time origin."""

        def side(mean, sd, se, n):
            return {"mean": mean, "sd": sd, "standard_error": float(se), "n": n}

        record = {
            "quantity": "mean photon arrival time, ns, inside and outside the contact (Otsu "
            "mask of the arrival-time map, edge band excluded)",
            "inside_ns": side(
                self.inside_mean_ns, self.inside_sd_ns, self.inside_se_ns, self.inside_n
            ),
            "outside_ns": side(
                self.outside_mean_ns, self.outside_sd_ns, self.outside_se_ns, self.outside_n
            ),
            "exclude_edge_px": exclude_edge_px,
        }
        if self.photons is not None:
            record["photons"] = self.photons
        if self.time_origin is not None:
            record["time_origin"] = self.time_origin.to_record()
        return record


def _stats(values: np.ndarray) -> tuple[float, float, float, int]:
    sd = float(values.std(ddof=1))
    return float(values.mean()), sd, sd / np.sqrt(values.size), int(values.size)


def sides(mask: np.ndarray, exclude_edge_px: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """The pixels inside ``mask`` and outside it, each without the band of
    ``exclude_edge_px`` pixels next to the edge."""
    mask = np.asarray(mask, dtype=bool)
    if exclude_edge_px <= 0:
        return mask, ~mask
    inside = binary_erosion(mask, iterations=exclude_edge_px)
    outside = binary_erosion(~mask, iterations=exclude_edge_px, border_value=1)
    return inside, outside


def lifetime_statistics(
    arrival_ns: np.ndarray, mask: np.ndarray, *, exclude_edge_px: int = 0
) -> LifetimeStatistics:
    """Arrival-time statistics (ns) inside ``mask`` (contact) and outside it.

    Raises ValueError for shape mismatch, non-finite arrival times, or fewer than two pixels
    on either side after the edge band is excluded.
    """
    arrival = np.asarray(arrival_ns, dtype=float)
    mask = np.asarray(mask, dtype=bool)
    if arrival.shape != mask.shape:
        raise ValueError(f"arrival-time map {arrival.shape} and mask {mask.shape} differ")
    if not np.all(np.isfinite(arrival)):
        bad = int(np.count_nonzero(~np.isfinite(arrival)))
        raise ValueError(f"arrival-time map has {bad} non-finite pixels; expected finite ns")
    inside, outside = sides(mask, exclude_edge_px)
    for name, region in (("inside", inside), ("outside", outside)):
        if region.sum() < 2:
            raise ValueError(
                f"{int(region.sum())} pixels {name} the contact (edge band "
                f"{exclude_edge_px} px); expected at least 2"
            )
    in_stats, out_stats = _stats(arrival[inside]), _stats(arrival[outside])
    return LifetimeStatistics(*in_stats, *out_stats)


# --- the time origin of time-tagged photons ---------------------------------------------------


def exgaussian_cdf(t_ns, mu_ns: float, sigma_ns: float, tau_ns: float) -> np.ndarray:
    """Probability that a photon has arrived by ``t_ns``, for an exponential decay of lifetime
    ``tau_ns`` excited through a Gaussian instrument response (peak ``mu_ns``, sd
    ``sigma_ns``): the exponentially modified Gaussian, whose mean is μ + τ. The exponential
    term is summed in logs so that neither tail overflows."""
    t = np.asarray(t_ns, dtype=float)
    z = (t - mu_ns) / sigma_ns
    tail = -(t - mu_ns) / tau_ns + sigma_ns**2 / (2 * tau_ns**2) + log_ndtr(z - sigma_ns / tau_ns)
    return ndtr(z) - np.exp(tail)


def _bin_edges(bins: int, bin_ns: float, period_ns: float) -> np.ndarray:
    # the last bin ends at the next sync pulse where the period is no whole number of bins
    return np.minimum(np.arange(bins + 1) * bin_ns, period_ns)


def decay_model(params, edges_ns: np.ndarray, period_ns: float) -> np.ndarray:
    """Expected photons per TCSPC bin of a two-lifetime decay through a Gaussian instrument
    response, folded into the laser period, over a flat background.

    ``params``: μ (ns, the response's peak after the sync), σ (ns), τ₁, τ₂ (ns), the share of
    τ₁, the photons of the decay, and the background (photons per ns). Photons of one pulse
    that arrive after the next sync (or, through the response's left tail, before their own)
    are counted where the detector puts them, a period earlier (later).
    """
    mu, sigma, tau1, tau2, share, photons, background = params

    def folded(tau):
        return sum(
            np.diff(exgaussian_cdf(edges_ns + n * period_ns, mu, sigma, tau)) for n in (-1, 0, 1)
        )

    decay = share * folded(tau1) + (1 - share) * folded(tau2)
    return photons * decay + background * np.diff(edges_ns)


def _natural(x: np.ndarray) -> np.ndarray:
    """Model parameters from the unconstrained ones the optimiser moves (logs, a logit)."""
    mu, log_sigma, log_tau1, log_tau2, logit_share, log_photons, log_background = x
    return np.array(
        [
            mu,
            np.exp(log_sigma),
            np.exp(log_tau1),
            np.exp(log_tau2),
            expit(logit_share),
            np.exp(log_photons),
            np.exp(log_background),
        ]
    )


def _start(decay: np.ndarray, centres: np.ndarray, bin_ns: float) -> np.ndarray:
    """Starting values from the decay's shape: σ from its rise (half maximum to peak, ≈1.18 σ
    for a Gaussian), μ half-way up the rise, lifetimes around the mean delay after μ."""
    smooth = np.convolve(decay, np.ones(5) / 5, mode="same")
    peak = int(np.argmax(smooth))
    below = np.nonzero(smooth[:peak] < smooth[peak] / 2)[0]
    half = centres[below[-1]] if below.size else centres[peak] - 2 * bin_ns
    sigma = max((centres[peak] - half) / 1.18, bin_ns)
    mu = half + 1.18 * sigma / 2
    mean_delay = max(float(decay @ centres / decay.sum()) - mu, 2 * bin_ns)
    floor = max(float(np.percentile(decay, 5)), 0.5) / bin_ns
    return np.array(
        [
            mu,
            np.log(sigma),
            np.log(2 * mean_delay),
            np.log(mean_delay / 2),
            0.0,
            np.log(decay.sum()),
            np.log(floor),
        ]
    )


def _fisher_se_of_peak(params: np.ndarray, edges_ns: np.ndarray, period_ns: float) -> float:
    """Standard error of μ from the Poisson Fisher information Σ_k ∂λ_k∂λ_kᵀ/λ_k, with the
    derivatives by central differences in the model parameters."""
    expected = decay_model(params, edges_ns, period_ns)
    steps = np.maximum(np.abs(params) * 1e-5, 1e-9)
    jacobian = np.empty((expected.size, params.size))
    for i, step in enumerate(steps):
        up, down = params.copy(), params.copy()
        up[i] += step
        down[i] -= step
        jacobian[:, i] = (
            decay_model(up, edges_ns, period_ns) - decay_model(down, edges_ns, period_ns)
        ) / (2 * step)
    weights = 1.0 / np.maximum(expected, 1e-12)
    information = jacobian.T @ (jacobian * weights[:, None])
    return float(np.sqrt(np.linalg.pinv(information)[0, 0]))


def fit_time_origin(decay: np.ndarray, bin_ns: float, period_ns: float) -> TimeOrigin:
    """The instrument response's peak after the sync (ns), by a Poisson maximum-likelihood fit
    of :func:`decay_model` to ``decay`` (photons per TCSPC bin of the whole image, bins of
    ``bin_ns``, laser period ``period_ns``).

    Two lifetimes, because a contact image holds two populations (confined and free
    molecules): one lifetime would bend the rise to fit both tails and move the peak. The
    standard error is the Fisher information's. Raises ValueError when the fit does not
    converge or puts the peak outside the period.
    """
    counts = np.asarray(decay, dtype=float)
    edges = _bin_edges(counts.size, bin_ns, period_ns)
    centres = (edges[:-1] + edges[1:]) / 2

    def negative_log_likelihood(x):
        expected = np.maximum(decay_model(_natural(x), edges, period_ns), 1e-300)
        return float(np.sum(expected - counts * np.log(expected)))

    result = minimize(
        negative_log_likelihood,
        _start(counts, centres, bin_ns),
        method="Nelder-Mead",
        options={"maxiter": 20000, "maxfev": 20000, "xatol": 1e-7, "fatol": 1e-7},
    )
    params = _natural(result.x)
    if not result.success or not 0 <= params[0] < period_ns:
        raise ValueError(
            f"the instrument-response fit of the image's decay did not converge "
            f"({result.message}; peak {params[0]:.4g} ns of a {period_ns:.4g} ns period); give "
            "the instrument response's peak instead"
        )
    return TimeOrigin(
        after_sync_ns=float(params[0]),
        standard_error_ns=_fisher_se_of_peak(params, edges, period_ns),
        method="fitted: Gaussian instrument response with two exponential decays and a flat "
        "background, Poisson maximum likelihood on the image's decay",
        irf_fwhm_ns=float(params[1] * FWHM_PER_SIGMA),
        lifetimes_ns=(float(params[2]), float(params[3])),
    )


def time_origin(photons: PhotonImage, irf_peak_ns: float | None = None) -> TimeOrigin:
    """The time origin of ``photons``: ``irf_peak_ns`` where given (ns after the sync, from a
    measured instrument response), else fitted to the image's decay (:func:`fit_time_origin`).
    """
    if irf_peak_ns is not None:
        if not 0 <= irf_peak_ns < photons.period_ns:
            raise ValueError(
                f"instrument response peak {irf_peak_ns:g} ns; expected a delay within the "
                f"{photons.period_ns:.4g} ns laser period"
            )
        return TimeOrigin(float(irf_peak_ns), 0.0, "given: the instrument response's peak")
    return fit_time_origin(photons.decay, photons.bin_ns, photons.period_ns)


def arrival_time_map(photons: PhotonImage, origin: TimeOrigin) -> Image:
    """Each pixel's mean photon arrival time after the time origin (ns), as an image.

    Raises ValueError for pixels without a photon (no arrival time: bin the image or acquire
    longer)."""
    empty = int(np.count_nonzero(photons.photons == 0))
    if empty:
        raise ValueError(
            f"{empty} pixels hold no photon, so no arrival time; expected at least one photon "
            "per pixel"
        )
    arrival = photons.mean_after_sync_ns - origin.after_sync_ns
    return Image(data=arrival, pixel_m=photons.pixel_m, path=photons.path)


def photon_counts(photons: np.ndarray, inside: np.ndarray, outside: np.ndarray) -> dict:
    """The photons behind each side's mean: total and per pixel (min, median, max)."""

    def side(region):
        values = photons[region]
        return {
            "total": int(values.sum()),
            "per_pixel_min": int(values.min()),
            "per_pixel_median": float(np.median(values)),
            "per_pixel_max": int(values.max()),
        }

    return {"inside": side(inside), "outside": side(outside)}


# --- the measurement ---------------------------------------------------------------------------


def measure_lifetime(
    path: str | Path,
    fallback_pixel_m: float | None,
    *,
    otsu: OtsuSettings,
    exclude_edge_px: int,
    channel: int | None = None,
    irf_peak_ns: float | None = None,
) -> LifetimeStatistics:
    """Arrival-time statistics inside and outside the contact of the FLIM file ``path``: a
    map of mean arrival times (``.tif``, ns) or time-tagged photons (``.ptu``; ``channel``
    the detector channel, None: all; ``irf_peak_ns`` the time origin, None: fitted).

    The FLIM map comes from another microscope (appendix Fig. B.3), so its contact mask is
    found in the map itself: confined molecules emit later, so the contact is the Otsu class of
    long arrival times. Raises NoContact if no such class stands out, RawDataError naming the
    file for a file that cannot be measured.
    """
    if Path(path).suffix.lower() == ".ptu":
        return _measure_photons(path, fallback_pixel_m, otsu, exclude_edge_px, channel, irf_peak_ns)
    image = read_flim(path, fallback_pixel_m)
    mask = separated_contact(image, otsu).mask
    try:
        return lifetime_statistics(image.data, mask, exclude_edge_px=exclude_edge_px)
    except ValueError as error:
        raise RawDataError(f"{image.path}: {error}") from error


def _measure_photons(
    path: str | Path,
    fallback_pixel_m: float | None,
    otsu: OtsuSettings,
    exclude_edge_px: int,
    channel: int | None,
    irf_peak_ns: float | None,
) -> LifetimeStatistics:
    photons = read_flim_photons(path, fallback_pixel_m, channel=channel)
    try:
        origin = time_origin(photons, irf_peak_ns)
        image = arrival_time_map(photons, origin)
    except ValueError as error:
        raise RawDataError(f"{photons.path}: {error}") from error
    mask = separated_contact(image, otsu).mask
    try:
        stats = lifetime_statistics(image.data, mask, exclude_edge_px=exclude_edge_px)
    except ValueError as error:
        raise RawDataError(f"{image.path}: {error}") from error
    inside, outside = sides(mask, exclude_edge_px)
    return dataclasses.replace(
        stats, photons=photon_counts(photons.photons, inside, outside), time_origin=origin
    )
