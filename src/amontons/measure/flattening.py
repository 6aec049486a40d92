"""The plastic flattening between two AFM scans of the same field (docs/models.md §1.8,
appendix Fig. B.9): how deep the surface went down where it flowed, with its uncertainty.

The deepest point of after − before is the extreme of ~10⁶ noisy differences: it grows with
the scan noise (a uniform 5 nm flattening reads 6.7 nm at 0.3 nm noise per scan, 10.6 nm at
1 nm). The depth here is a median instead, over the pixels that went down by more than half of
it, which noise scatters but does not push one way.

Heights in m; the change map is after − before, negative where the surface went down.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from amontons.physics.roughness import FLATTENING_SMOOTHING_PX, flattening_depth

# Gaussian smoothing of the drop before it is thresholded, px (part of the depth's
# definition, shared with the virtual experiment's truth).
SMOOTHING_PX = FLATTENING_SMOOTHING_PX
# The flattened region: smoothed drop above this many sd of the smoothed noise (a false pixel
# in ~10⁶ for normal noise).
REGION_THRESHOLD_SD = 5.0
# A depth whose half stands less than this many thresholds above the noise is flagged: the
# shallow part of an uneven flattening is then below the threshold, and the depth is that of
# the deeper patches the noise lets through (virtual glass: 0.73 nm read, 0.20 nm true).
NEAR_NOISE_FACTOR = 2.0
# Least drop taken as flattening, m: 0.01 nm, below the height noise of any AFM (≥ 0.03 nm);
# it keeps the far tails of the smoothing out of the region of a noise-free map.
MIN_DEPTH_M = 1e-11
# Unchanged pixels needed to find their level again without the flattened region; with fewer
# (a scan flattened nearly everywhere) the first level, from the whole map, stands.
_MIN_UNCHANGED_PX = 1000
_MAD_TO_SD = 1.4826  # σ of a normal population per median absolute deviation
_MEDIAN_SE_PER_SD = np.sqrt(np.pi / 2)  # SE of a median of n normal values: √(π/2) σ/√n


@dataclass(frozen=True)
class Flattening:
    """Where and how deep two scans say the surface flowed (lengths in m, area in m²).

    ``change_m``: after − before minus the level of the points that did not flow.
    ``depth_m``: median drop over the pixels that went down by more than half of it
    (:func:`amontons.physics.roughness.flattening_depth`); ``depth_se_m`` its standard error
    from the scan noise. Both None, and ``flag`` says why, when no pixel stands out of the
    noise or when half the depth does not (the threshold, not the surface, would then set
    it). ``area_m2``: the area whose smoothed drop stands out of the noise.
    ``noise_m``: per-pixel noise sd of the difference; ``threshold_m`` the least smoothed drop
    counted as flattened.
    """

    change_m: np.ndarray
    depth_m: float | None
    depth_se_m: float | None
    flag: str | None
    area_m2: float
    noise_m: float
    threshold_m: float
    pixel_m: float

    def to_record(self) -> dict:
        """JSON-ready record, units in the key names."""
        depth = {"estimate": None, "standard_error": None, "flag": self.flag}
        if self.depth_m is not None:
            depth.update(estimate=self.depth_m * 1e9, standard_error=self.depth_se_m * 1e9)
        return {
            "flattening_depth_nm": depth,
            "flattened_area_um2": self.area_m2 * 1e12,
            "flattening_noise_nm": self.noise_m * 1e9,
            "flattening_threshold_nm": self.threshold_m * 1e9,
            "flattening_smoothing_nm": SMOOTHING_PX * self.pixel_m * 1e9,
        }


def difference_noise(change_m: np.ndarray) -> float:
    """Per-pixel sd (m) of the white noise in a map: robust sd of the differences between
    neighbours along the rows, / √2. A flattening is smooth at the pixel scale and its edges
    are few, so the median absolute deviation sees the noise."""
    steps = np.diff(change_m, axis=-1).ravel()
    return float(_MAD_TO_SD * np.median(np.abs(steps - np.median(steps))) / np.sqrt(2))


def _unchanged_population(
    change_m: np.ndarray, noise_m: float, bin_m: float = 0.25e-9
) -> tuple[float, int]:
    """Level (m) and size (px) of the population of points that did not flow."""
    low, high = np.percentile(change_m, [0.5, 99.5])
    if high - low < bin_m:
        return float(np.median(change_m)), change_m.size  # nothing flowed: one population
    bins = int(np.ceil((high - low) / bin_m))
    counts, edges = np.histogram(change_m, bins=bins, range=(low, high))
    peak = int(np.argmax(counts))
    level = 0.5 * (edges[peak] + edges[peak + 1])
    # The peak bin locates the population; a median in a window of ±2 noise sd (at least a
    # bin), re-centred until it settles, places it without the bin's error: the noise of a
    # symmetric population has its median at the window's centre only at the true level.
    half_width = max(2 * noise_m, bin_m)
    inside = np.zeros(change_m.shape, dtype=bool)
    for _ in range(20):
        inside = np.abs(change_m - level) <= half_width
        new_level = float(np.median(change_m[inside]))
        if abs(new_level - level) < 1e-3 * half_width:
            break
        level = new_level
    return new_level, int(inside.sum())


def unchanged_level(change_m: np.ndarray, bin_m: float = 0.25e-9) -> float:
    """The height change (m) of the points that did not flow: the mode of after − before.

    Two AFM scans share no absolute height, and flattened points are not a minority near a
    large contact, so neither 0 nor the median is the reference; the points that never
    touched (most of a rough sphere, even inside the contact) form a peak as narrow as the
    scan noise.
    """
    return _unchanged_population(change_m, difference_noise(change_m), bin_m)[0]


def _smoothed_drop(change_m: np.ndarray, noise_m: float) -> tuple[np.ndarray, float]:
    """The drop −change smoothed by ``SMOOTHING_PX`` (m) and the least smoothed drop that
    stands out of the noise (m)."""
    smoothed = ndimage.gaussian_filter(-change_m, SMOOTHING_PX, mode="nearest")
    smoothed_noise = noise_m / (2 * np.sqrt(np.pi) * SMOOTHING_PX)
    return smoothed, max(REGION_THRESHOLD_SD * smoothed_noise, MIN_DEPTH_M)


def measure_flattening(difference_m: np.ndarray, pixel_m: float) -> Flattening:
    """Flattening from after − before (m; scan-line offsets already removed).

    The drop below the unchanged level is smoothed (Gaussian, ``SMOOTHING_PX``) to decide
    which pixels flowed: those whose smoothed drop exceeds ``REGION_THRESHOLD_SD`` × the
    smoothed noise (and ``MIN_DEPTH_M``) form the flattened region. The unchanged level is
    then found again without that region (widened by the smoothing's reach), so that a
    flattening shallower than a few noise sd cannot pull it. The depth is
    :func:`amontons.physics.roughness.flattening_depth` of the unsmoothed drop with the
    smoothed one deciding membership: the median drop over the pixels whose smoothed drop
    exceeds half of it. Its standard error combines that median's, √(π/2) σ/√n over the n pixels
    it is taken over, and the unchanged level's, the same over its population: the scan
    noise only (an uneven flattening's depth also moves by ~1 % with the smoothing that
    decides membership). A depth whose half lies within the noise threshold is refused
    (None, flagged): the threshold would decide it; one within ``NEAR_NOISE_FACTOR``
    thresholds is kept and flagged.
    """
    noise = difference_noise(difference_m)
    level, n_unchanged = _unchanged_population(difference_m, noise)
    smoothed, threshold = _smoothed_drop(difference_m - level, noise)
    reach = int(np.ceil(2 * SMOOTHING_PX))
    outside = ~ndimage.binary_dilation(smoothed > threshold, iterations=reach)
    if np.count_nonzero(outside) >= _MIN_UNCHANGED_PX:
        level, n_unchanged = _unchanged_population(difference_m[outside], noise)
        smoothed, threshold = _smoothed_drop(difference_m - level, noise)
    change = difference_m - level
    depth, core = flattening_depth(-change, smoothing_px=SMOOTHING_PX, floor_m=threshold)
    se = flag = None
    if depth is None:
        flag = (
            f"no flattening: no smoothed drop exceeds the noise threshold {threshold * 1e9:.3g} nm"
        )
    elif depth / 2 <= threshold:
        flag = (
            f"flattening not resolved: half its depth ({depth / 2 * 1e9:.3g} nm) lies within the "
            f"noise threshold {threshold * 1e9:.3g} nm"
        )
        depth = None
    else:
        se = float(_MEDIAN_SE_PER_SD * noise * np.sqrt(1 / core.sum() + 1 / n_unchanged))
        if depth / 2 < NEAR_NOISE_FACTOR * threshold:
            flag = (
                f"near the noise floor: half the depth ({depth / 2 * 1e9:.3g} nm) is less than "
                f"{NEAR_NOISE_FACTOR:g} × the noise threshold {threshold * 1e9:.3g} nm; "
                "shallower flattening is not seen, so an uneven one may read deeper than it is"
            )
    return Flattening(
        change_m=change,
        depth_m=depth,
        depth_se_m=se,
        flag=flag,
        area_m2=float(np.count_nonzero(smoothed > threshold)) * pixel_m**2,
        noise_m=noise,
        threshold_m=threshold,
        pixel_m=pixel_m,
    )
