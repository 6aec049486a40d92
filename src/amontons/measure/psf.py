"""Point spread function from the image of a sub-resolution fluorescent bead (Fig. B.2).

The appendix's procedure: find the centre of intensity, plot every pixel's intensity against
its distance from that centre, and fit a Gaussian; its FWHM is the PSF width. Here:

1. background and noise from the image border (median and MAD), which the bead does not reach;
2. centroid of the background-subtracted image in a window around the brightest spot,
   re-centred until it settles;
3. a Gaussian-plus-background fit (scipy.optimize.curve_fit) of the pixel intensities against
   their distance from the centroid;
4. a pixel-size correction: a pixel integrates the PSF over a square of side p, which adds
   p²/12 to the variance of the profile along each axis (at 200 nm pixels and a 450 nm PSF
   that widens the fitted FWHM by ~4 %), so σ² = σ_fit² − p²/12.

The radial profile (mean intensity in rings half a pixel wide) is returned for plotting.
Pixel coordinates: the centre of pixel (row i, column j) is at x = j·pixel_m, y = i·pixel_m.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.ndimage import uniform_filter
from scipy.optimize import curve_fit

from amontons.io.layout import RawDataError
from amontons.io.rawdata import read_bead
from amontons.io.tiff import saturated_pixels
from amontons.physics.gaussian import FWHM_PER_SIGMA

_MAD_TO_SD = 1.4826  # σ of a normal population per median absolute deviation


class PsfError(ValueError):
    """A bead image from which no PSF can be measured."""


@dataclass(frozen=True)
class PsfMeasurement:
    """PSF width from one bead image; lengths in m, intensities in counts."""

    fwhm_m: float
    fwhm_se_m: float
    sigma_m: float
    fitted_fwhm_m: float  # before the pixel-size correction
    peak_counts: float  # fitted Gaussian amplitude above the background
    background_counts: float  # fitted background
    border_background_counts: float  # median of the image border
    noise_sd_counts: float  # background noise, from the border
    centroid_m: tuple[float, float]  # (x, y)
    profile_r_m: np.ndarray  # radial average: ring centres
    profile_counts: np.ndarray  # radial average: mean counts per ring
    n_pixels_fitted: int

    def to_record(self) -> dict:
        """JSON-ready record, units in the key names."""
        return {
            "quantity": "PSF FWHM from a 100 nm bead (Gaussian fit of the radial profile, "
            "pixel-corrected)",
            "fwhm_nm": {"estimate": self.fwhm_m * 1e9, "standard_error": self.fwhm_se_m * 1e9},
            "fitted_fwhm_nm": self.fitted_fwhm_m * 1e9,
            "n": self.n_pixels_fitted,
            "peak_counts": self.peak_counts,
            "background_counts": self.background_counts,
            "noise_sd_counts": self.noise_sd_counts,
            "centroid_nm": [c * 1e9 for c in self.centroid_m],
        }


def gaussian_with_background(r, amplitude, sigma, background):
    """amplitude·exp(−r²/2σ²) + background."""
    return amplitude * np.exp(-0.5 * (r / sigma) ** 2) + background


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
    pixel_correction: bool = True,
) -> PsfMeasurement:
    """Measure the PSF FWHM (m) from the image of one point-like bead.

    ``profile_radius_m`` is how far from the centroid pixels enter the fit; the bead must be at
    least that far from every image edge. The centroid uses pixels within a square of
    half-width ``centroid_radius_m`` (default ~1.3 × a 450 nm FWHM): a wider window lets the
    background noise of many far pixels move the centroid, which widens the radial profile
    (at ~900 peak counts a 2 µm window biases the FWHM by +2 %, 0.6 µm by +0.3 %). A bead
    is accepted when its 3×3-averaged peak stands ``min_snr`` background standard deviations
    above the background. Raises PsfError for saturated pixels, no bead, or a bead too close
    to the edge.
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
    distance_m = np.hypot(rows - centroid_rc[0], cols - centroid_rc[1]) * pixel_m
    near = distance_m <= profile_radius_m
    r, counts = distance_m[near], data[near]
    amplitude, sigma_fit, fitted_background, sigma_fit_se = _fit_profile(
        r, counts, background, pixel_m, profile_radius_m
    )
    sigma = _pixel_corrected_sigma(sigma_fit, pixel_m) if pixel_correction else sigma_fit
    profile_r, profile_counts = radial_profile(r, counts, pixel_m / 2)
    return PsfMeasurement(
        fwhm_m=float(FWHM_PER_SIGMA * sigma),
        # d(σ)/d(σ_fit) = σ_fit/σ from σ² = σ_fit² − p²/12
        fwhm_se_m=float(FWHM_PER_SIGMA * sigma_fit_se * sigma_fit / sigma),
        sigma_m=float(sigma),
        fitted_fwhm_m=float(FWHM_PER_SIGMA * sigma_fit),
        peak_counts=float(amplitude),
        background_counts=float(fitted_background),
        border_background_counts=background,
        noise_sd_counts=noise_sd,
        centroid_m=(centroid_rc[1] * pixel_m, centroid_rc[0] * pixel_m),
        profile_r_m=profile_r,
        profile_counts=profile_counts,
        n_pixels_fitted=int(near.sum()),
    )


def _fit_profile(
    r: np.ndarray, counts: np.ndarray, background: float, pixel_m: float, max_sigma_m: float
) -> tuple[float, float, float, float]:
    """Gaussian-plus-background fit: amplitude, σ (m), background, standard error of σ (m)."""
    try:
        params, covariance = curve_fit(
            gaussian_with_background,
            r,
            counts,
            p0=(counts.max() - background, max_sigma_m / 4, background),
            bounds=([0, 0.1 * pixel_m, -np.inf], [np.inf, max_sigma_m, np.inf]),
        )
    except RuntimeError as error:
        raise PsfError(f"Gaussian fit of the bead's radial profile failed: {error}") from error
    sigma_se = float(np.sqrt(covariance[1, 1]))
    if not np.isfinite(sigma_se):
        raise PsfError(
            f"Gaussian fit of the bead's radial profile gives σ = {params[1]:.3g} m with an "
            "undefined standard error; expected a well-determined width"
        )
    return float(params[0]), float(params[1]), float(params[2]), sigma_se


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


def _pixel_corrected_sigma(sigma_fit: float, pixel_m: float) -> float:
    variance = sigma_fit**2 - pixel_m**2 / 12
    if variance <= 0:
        raise PsfError(
            f"fitted PSF σ {sigma_fit:.3g} m is not wider than one pixel ({pixel_m:.3g} m); "
            "the PSF is unresolved at this pixel size"
        )
    return float(np.sqrt(variance))


def measure_bead(
    path: str | Path,
    fallback_pixel_m: float | None,
    *,
    profile_radius_m: float,
    centroid_radius_m: float,
) -> PsfMeasurement:
    """PSF FWHM from the bead image ``path`` (:func:`measure_psf`)."""
    image = read_bead(path, fallback_pixel_m)
    try:
        return measure_psf(
            image.data,
            image.pixel_m,
            profile_radius_m=profile_radius_m,
            centroid_radius_m=centroid_radius_m,
        )
    except PsfError as error:
        raise RawDataError(f"{image.path}: {error}") from error
