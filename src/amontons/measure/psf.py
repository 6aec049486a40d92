"""Point spread function from the image of a sub-resolution fluorescent bead (Fig. B.2).

The appendix's procedure: find the centre of intensity, plot every pixel's intensity against
its distance from that centre, and fit a Gaussian; its FWHM is the PSF width. Here:

1. background and noise from the image border (median and MAD), which the bead does not reach;
2. centroid of the background-subtracted image in a window around the brightest spot,
   re-centred until it settles;
3. a maximum-likelihood fit of every pixel within the profile radius of the centroid: a
   Gaussian spot (free centre, amplitude, σ) integrated over each square pixel, plus a
   uniform background, under Poisson counting statistics (Fisher scoring). Integrating over
   the pixel is the pixel-size correction (a pixel of side p adds about p²/12 to the
   variance of the image along each axis: at 200 nm pixels and a 450 nm PSF the image is
   ~4 % wider than the PSF). The standard error comes from the inverse Fisher information,
   widened by the Pearson dispersion of the counts when it exceeds Poisson's (gain, read
   noise). An unweighted least-squares fit of the radial profile, as before, let the many
   background pixels dominate and ignored the centre's uncertainty: its SE was ~2.8× too
   small (a ±1.96 SE interval covered the truth in 55 % of beads);
4. the radial profile (mean intensity in rings half a pixel wide) is returned for plotting.

Pixel coordinates: the centre of pixel (row i, column j) is at x = j·pixel_m, y = i·pixel_m.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from scipy.ndimage import uniform_filter
from scipy.special import erf

from amontons.io.confocal import NO_CHOICE, ImageChoice
from amontons.io.layout import RawDataError
from amontons.io.rawdata import read_bead
from amontons.io.tiff import saturated_pixels
from amontons.physics.gaussian import FWHM_PER_SIGMA

_MAD_TO_SD = 1.4826  # σ of a normal population per median absolute deviation
_MAX_ITERATIONS = 100  # Fisher scoring settles in ~5-10 steps from the centroid start
_MIN_SIGMA_PX = 0.1  # a narrower spot is a hot pixel or an unresolved PSF, not a width


class PsfError(ValueError):
    """A bead image from which no PSF can be measured."""


@dataclass(frozen=True)
class PsfMeasurement:
    """PSF width from one bead image; lengths in m, intensities in counts."""

    fwhm_m: float
    fwhm_se_m: float
    sigma_m: float
    fitted_fwhm_m: float  # of the pixelated image, √(σ² + p²/12): without the pixel correction
    peak_counts: float  # fitted Gaussian amplitude above the background, counts per pixel area
    background_counts: float  # fitted background
    border_background_counts: float  # median of the image border
    noise_sd_counts: float  # background noise, from the border
    centroid_m: tuple[float, float]  # (x, y)
    profile_r_m: np.ndarray  # radial average: ring centres
    profile_counts: np.ndarray  # radial average: mean counts per ring
    n_pixels_fitted: int
    dispersion: float  # Pearson χ²/(n − 5) of the fit: 1 for Poisson counts
    pixel_source: str | None = None  # 'file' or 'sheet' where read from a bead image

    def to_record(self) -> dict:
        """JSON-ready record, units in the key names."""
        return {
            "quantity": "PSF FWHM from a 100 nm bead (Poisson maximum-likelihood fit of a "
            "pixel-integrated Gaussian spot with background; SE from the Fisher information)",
            "fwhm_nm": {"estimate": self.fwhm_m * 1e9, "standard_error": self.fwhm_se_m * 1e9},
            "fitted_fwhm_nm": self.fitted_fwhm_m * 1e9,
            "n": self.n_pixels_fitted,
            "peak_counts": self.peak_counts,
            "background_counts": self.background_counts,
            "noise_sd_counts": self.noise_sd_counts,
            "poisson_dispersion": self.dispersion,
            "centroid_nm": [c * 1e9 for c in self.centroid_m],
            "pixel_source": self.pixel_source,
        }


def border_background(image: np.ndarray, width: int) -> tuple[float, float]:
    """Median and robust standard deviation (MAD) of a border frame ``width`` pixels wide."""
    frame = np.ones(image.shape, dtype=bool)
    frame[width:-width, width:-width] = False
    values = image[frame]
    median = float(np.median(values))
    return median, float(_MAD_TO_SD * np.median(np.abs(values - median)))


def _check_saturation(image: np.ndarray) -> None:
    n_saturated = saturated_pixels(image)
    if n_saturated:
        raise PsfError(
            f"bead image has {n_saturated} saturated pixels (value {np.iinfo(image.dtype).max}, "
            f"the {image.dtype} maximum); a clipped peak widens the PSF, expected none — lower "
            "the laser or gain"
        )


def intensity_centroid(
    signal: np.ndarray, start_rc: tuple[int, int], radius_px: int, iterations: int = 5
) -> tuple[float, float]:
    """Centre of intensity (row, col) of ``signal`` in a square window re-centred each pass."""
    row, col = start_rc
    for _ in range(iterations):
        r0, r1 = max(row - radius_px, 0), min(row + radius_px + 1, signal.shape[0])
        c0, c1 = max(col - radius_px, 0), min(col + radius_px + 1, signal.shape[1])
        window = signal[r0:r1, c0:c1]
        total = window.sum()
        if total <= 0:
            raise PsfError(
                f"background-subtracted intensity around pixel ({row}, {col}) sums to "
                f"{total:.3g} counts; expected a positive bead signal"
            )
        rows, cols = np.mgrid[r0:r1, c0:c1]
        centroid = (float((rows * window).sum() / total), float((cols * window).sum() / total))
        new_row, new_col = round(centroid[0]), round(centroid[1])
        if (new_row, new_col) == (row, col):
            break
        row, col = new_row, new_col
    return centroid


def radial_profile(
    distance_m: np.ndarray, counts: np.ndarray, bin_m: float
) -> tuple[np.ndarray, np.ndarray]:
    """Mean counts in rings of width ``bin_m``; empty rings are left out."""
    index = (distance_m / bin_m).astype(int)
    sums = np.bincount(index, weights=counts)
    numbers = np.bincount(index)
    filled = numbers > 0
    centres = (np.arange(sums.size) + 0.5) * bin_m
    return centres[filled], sums[filled] / numbers[filled]


def measure_psf(
    image: np.ndarray,
    pixel_m: float,
    *,
    profile_radius_m: float = 2e-6,
    centroid_radius_m: float = 0.6e-6,
    border_px: int = 4,
    min_snr: float = 5.0,
) -> PsfMeasurement:
    """Measure the PSF FWHM (m) and its standard error from the image of one point-like bead.

    ``profile_radius_m`` is how far from the centroid pixels enter the fit; the bead must be at
    least that far from every image edge. The centroid, the start of the fit, uses pixels
    within a square of half-width ``centroid_radius_m`` (default ~1.3 × a 450 nm FWHM). A
    bead is accepted when its 3×3-averaged peak stands ``min_snr`` background standard
    deviations above the background. Raises PsfError for saturated pixels, no bead, a bead
    too close to the edge, or a fit that does not settle.
    """
    raw = np.asarray(image)
    if raw.ndim != 2:
        raise PsfError(f"bead image has shape {raw.shape}; expected a 2-D image")
    _check_saturation(raw)
    data = raw.astype(float)
    background, noise_sd = border_background(data, border_px)
    signal = data - background
    # A 3×3 mean keeps a single hot pixel or noise spike from posing as the bead.
    smoothed = uniform_filter(signal, size=3, mode="nearest")
    peak_rc = np.unravel_index(int(np.argmax(smoothed)), smoothed.shape)
    if smoothed[peak_rc] < min_snr * max(noise_sd, 1e-12):
        raise PsfError(
            f"no bead: the brightest spot is {smoothed[peak_rc]:.3g} counts above the "
            f"background ({background:.3g} counts), expected more than {min_snr:g} × the "
            f"background noise of {noise_sd:.3g} counts"
        )
    window_px = max(1, round(centroid_radius_m / pixel_m))
    centroid_rc = intensity_centroid(signal, (int(peak_rc[0]), int(peak_rc[1])), window_px)
    _check_margin(raw.shape, centroid_rc, pixel_m, profile_radius_m)

    rows, cols = np.indices(raw.shape)
    near = np.hypot(rows - centroid_rc[0], cols - centroid_rc[1]) * pixel_m <= profile_radius_m
    fit = fit_spot(rows[near], cols[near], data[near], centroid_rc, background)
    if fit.sigma_px < _MIN_SIGMA_PX:
        raise PsfError(
            f"fitted PSF σ {fit.sigma_px * pixel_m:.3g} m is less than {_MIN_SIGMA_PX:g} pixel "
            f"({pixel_m:.3g} m); the PSF is unresolved at this pixel size"
        )
    distance_m = np.hypot(rows - fit.centre_rc[0], cols - fit.centre_rc[1]) * pixel_m
    profile_r, profile_counts = radial_profile(distance_m[near], data[near], pixel_m / 2)
    sigma_m = fit.sigma_px * pixel_m
    return PsfMeasurement(
        fwhm_m=float(FWHM_PER_SIGMA * sigma_m),
        fwhm_se_m=float(FWHM_PER_SIGMA * fit.sigma_se_px * pixel_m),
        sigma_m=float(sigma_m),
        fitted_fwhm_m=float(FWHM_PER_SIGMA * np.sqrt(sigma_m**2 + pixel_m**2 / 12)),
        peak_counts=fit.amplitude,
        background_counts=fit.background,
        border_background_counts=background,
        noise_sd_counts=noise_sd,
        centroid_m=(fit.centre_rc[1] * pixel_m, fit.centre_rc[0] * pixel_m),
        profile_r_m=profile_r,
        profile_counts=profile_counts,
        n_pixels_fitted=int(near.sum()),
        dispersion=fit.dispersion,
    )


@dataclass(frozen=True)
class SpotFit:
    """Maximum-likelihood Gaussian spot: centre (row, col) and σ in pixels, amplitude in
    counts per pixel area at the peak, background in counts per pixel; the standard error of
    σ (px, from the Fisher information, widened by the dispersion when above 1) and the
    Pearson dispersion χ²/(n − 5) of the counts about the fit (1 for Poisson counts)."""

    centre_rc: tuple[float, float]
    amplitude: float
    sigma_px: float
    background: float
    sigma_se_px: float
    dispersion: float


def _pixel_fractions(coord: np.ndarray, centre: float, sigma: float):
    """Share of a 1-D Gaussian (centre, σ in px) on unit pixels centred at ``coord``, and its
    derivatives by the centre and by σ."""
    upper = (coord + 0.5 - centre) / sigma
    lower = (coord - 0.5 - centre) / sigma
    share = 0.5 * (erf(upper / np.sqrt(2)) - erf(lower / np.sqrt(2)))
    density_upper = np.exp(-0.5 * upper**2) / np.sqrt(2 * np.pi)
    density_lower = np.exp(-0.5 * lower**2) / np.sqrt(2 * np.pi)
    by_centre = -(density_upper - density_lower) / sigma
    by_sigma = -(upper * density_upper - lower * density_lower) / sigma
    return share, by_centre, by_sigma


def spot_model(rows: np.ndarray, cols: np.ndarray, theta: np.ndarray):
    """Expected counts of pixels (rows, cols) and their Jacobian (n × 5) for
    θ = (row centre, col centre, amplitude, σ, background), lengths in px: a Gaussian of
    peak ``amplitude`` (counts per pixel area) integrated over each pixel, plus background."""
    row0, col0, amplitude, sigma, background = theta
    fy, dfy_centre, dfy_sigma = _pixel_fractions(rows, row0, sigma)
    fx, dfx_centre, dfx_sigma = _pixel_fractions(cols, col0, sigma)
    total = amplitude * 2 * np.pi * sigma**2  # counts of the whole spot
    spot = total * fx * fy
    jacobian = np.stack(
        [
            total * dfy_centre * fx,
            total * fy * dfx_centre,
            spot / amplitude,
            2 * spot / sigma + total * (dfy_sigma * fx + fy * dfx_sigma),
            np.ones_like(spot),
        ],
        axis=1,
    )
    return background + spot, jacobian


def _negative_log_likelihood(counts: np.ndarray, expected: np.ndarray) -> float:
    return float(np.sum(expected - counts * np.log(expected)))


def fit_spot(
    rows: np.ndarray,
    cols: np.ndarray,
    counts: np.ndarray,
    start_rc: tuple[float, float],
    background: float,
) -> SpotFit:
    """Poisson maximum-likelihood fit of :func:`spot_model` to the counts of pixels
    (rows, cols), by Fisher scoring (Newton steps with the expected information Σ ∇μ∇μᵀ/μ,
    halved until the likelihood rises), started at ``start_rc`` and the border
    ``background``. Weighting every pixel by its own Poisson variance keeps the many
    background pixels from outweighing the few bright ones that carry the width."""
    theta = _start(rows, cols, counts, start_rc, background)
    expected, jacobian = spot_model(rows, cols, theta)
    nll = _negative_log_likelihood(counts, expected)
    for _ in range(_MAX_ITERATIONS):
        information = jacobian.T @ (jacobian / expected[:, None])
        step = np.linalg.solve(information, jacobian.T @ (counts / expected - 1))
        scale = 1.0
        while True:
            trial = theta + scale * step
            if trial[2] > 0 and trial[3] > 0:
                trial_expected, trial_jacobian = spot_model(rows, cols, trial)
                if np.all(trial_expected > 0):
                    trial_nll = _negative_log_likelihood(counts, trial_expected)
                    if trial_nll <= nll + 1e-9 * abs(nll):
                        break
            scale /= 2
            if scale < 1e-6:
                raise PsfError(f"Poisson fit of the bead does not settle at {theta}")
        theta, expected, jacobian, nll = trial, trial_expected, trial_jacobian, trial_nll
        standard_errors = np.sqrt(np.diag(np.linalg.inv(information)))
        if np.all(np.abs(scale * step) < 1e-6 * standard_errors):
            break
    else:
        raise PsfError(f"Poisson fit of the bead did not converge in {_MAX_ITERATIONS} steps")
    information = jacobian.T @ (jacobian / expected[:, None])
    covariance = np.linalg.inv(information)
    dispersion = float(np.sum((counts - expected) ** 2 / expected) / (counts.size - theta.size))
    sigma_se = float(np.sqrt(covariance[3, 3] * max(dispersion, 1.0)))
    if not np.isfinite(sigma_se):
        raise PsfError(
            f"Poisson fit of the bead gives σ = {theta[3]:.3g} px with an undefined standard "
            "error; expected a well-determined width"
        )
    return SpotFit(
        centre_rc=(float(theta[0]), float(theta[1])),
        amplitude=float(theta[2]),
        sigma_px=float(theta[3]),
        background=float(theta[4]),
        sigma_se_px=sigma_se,
        dispersion=dispersion,
    )


def _start(rows, cols, counts, start_rc, background) -> np.ndarray:
    """θ to start from: the centroid, the border background, and σ from the spot's counts
    (total = amplitude · 2πσ², amplitude ≈ the brightest pixel above background)."""
    excess = counts - background
    peak = max(float(excess.max()), 1.0)
    sigma = np.sqrt(max(float(excess.sum()), peak) / (2 * np.pi * peak))
    return np.array([start_rc[0], start_rc[1], peak, max(sigma, 0.5), max(background, 1.0)])


def _check_margin(
    shape: tuple[int, int], centroid_rc: tuple[float, float], pixel_m: float, needed_m: float
) -> None:
    margins_px = (
        centroid_rc[0],
        centroid_rc[1],
        shape[0] - 1 - centroid_rc[0],
        shape[1] - 1 - centroid_rc[1],
    )
    distance_m = min(margins_px) * pixel_m
    if distance_m < needed_m:
        raise PsfError(
            f"bead centre ({centroid_rc[1] * pixel_m:.3g}, {centroid_rc[0] * pixel_m:.3g}) m is "
            f"{distance_m:.3g} m from the image edge; the radial profile needs a margin of "
            f"{needed_m:.3g} m"
        )


def measure_bead(
    path: str | Path,
    fallback_pixel_m: float | None,
    *,
    profile_radius_m: float,
    centroid_radius_m: float,
    choice: ImageChoice = NO_CHOICE,
) -> PsfMeasurement:
    """PSF FWHM from the bead image ``path`` (:func:`measure_psf`; ``choice``: its plane, for a
    confocal file), recording where its pixel size came from (file or sheet)."""
    image = read_bead(path, fallback_pixel_m, choice)
    try:
        psf = measure_psf(
            image.data,
            image.pixel_m,
            profile_radius_m=profile_radius_m,
            centroid_radius_m=centroid_radius_m,
        )
    except PsfError as error:
        raise RawDataError(f"{image.path}: {error}") from error
    return replace(psf, pixel_source=image.pixel_source)
