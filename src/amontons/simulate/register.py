"""Register a simulated contact image onto the measured fluorescence image.

The contact is simulated in the AFM frame; the fluorescence image is taken in the microscope
frame. The two differ by a translation and, for real data, a rotation and a mirror, because
the sphere is turned over between the AFM and the microscope. As in the appendix B.2.4
comparison of Weber et al., Nat. Commun. 9, 888 (2018), the transform is found by
cross-correlating the rendered simulation with the measured image, once, at the largest load;
the same transform then serves every load of that sphere. Both images share one pixel size,
so everything here is in pixels (px) of the fluorescence image and angles in degrees.

Coordinates. A pixel position is (row, col), rows growing downward as displayed. For a
simulated position p relative to the simulated image's centre ((n - 1)/2 along each axis),
the measured position is

    q = R(θ) · M · p + c_meas + shift,

with M = diag(1, -1) when ``mirrored`` (the column axis is flipped first) and the identity
otherwise, c_meas the measured image's centre, and R(θ) the counter-clockwise rotation as
displayed, which in (row, col) reads

    R(θ) = [[cos θ, -sin θ],
            [sin θ,  cos θ]],

so that a point right of the centre, p = (0, +1), goes up to (-1, 0) at θ = 90°.
:func:`warp_to_measured` applies the inverse map, p = M · R(-θ) · (q - c_meas - shift), with
``scipy.ndimage.map_coordinates`` (mode ``constant``, 0 outside the simulated image).

What is compared. The simulation is a rendering, 0 where nothing emits. Its background is
taken as the median of its outermost pixel ring (0 for a noiseless rendering) and removed, so
that the edge of the simulated frame, where the warp pads with 0, is not a feature. The score
of a transform is the Pearson correlation, over every pixel of the measured image, of the
warped simulation with the measured image: insensitive to the measured gain and uniform
background, and in [-1, 1].

Method.

1. Coarse search. Both images are block-averaged to ~128 px across (a contact blurred by the
   PSF loses nothing the coarse search needs). For each mirror and each angle of a grid over
   the full circle (``angle_step_deg``), the simulation is warped, centred, onto a canvas just
   large enough for its signal, and the Pearson correlation at every integer translation is
   computed at once from five FFTs: Σ m·w, Σ w and Σ w² over the overlap with the measured
   image (the measured image is made zero-mean). Translations that leave more than half of
   the simulated signal (Σ w²) outside the measured image are not considered, because a
   correlation over a sliver of the signal is noise.
2. The few best local maxima over angle (both mirrors) are refined at full resolution:
   bounded Brent search of the angle within one coarse step, the translation found again by
   FFT in a window around the coarse one, with a parabolic sub-pixel fit of the peak.
3. The best of them is polished by Nelder-Mead on the exact score (angle, row and column
   shift together), so that the returned transform is a local maximum of the returned score.

A simulation with a rotational or mirror symmetry (a smooth Hertz disc) has several equally
good transforms; one of them is returned, and the score cannot tell them apart.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import fft as sfft
from scipy.ndimage import map_coordinates
from scipy.optimize import minimize, minimize_scalar

from amontons.simulate.grid import block_mean

# The coarse search works on images about this many pixels across (px).
_COARSE_SIZE_PX = 128
# A downsampled image narrower than this (px) has too little left to register on.
_MIN_COARSE_SIDE_PX = 16
# Local maxima over angle carried from the coarse search to the full-resolution refinement.
_CANDIDATES = 3
# Translations must keep at least this fraction of the simulated signal (Σ w²) in view.
_MIN_SIGNAL_IN_VIEW = 0.5
# Pixels weaker than this fraction of the strongest carry no signal (sizes the canvas).
_SIGNAL_FLOOR = 1e-3
# Relative peak-to-peak below which an image counts as featureless.
_FEATURELESS_RTOL = 1e-12


@dataclass(frozen=True)
class Registration:
    """Transform from the simulated image to the measured one (see the module docstring).

    ``mirrored``: the simulated column axis is flipped first; ``rotation_deg``: then rotated
    counter-clockwise as displayed about its centre (degrees, in [-180, 180)); ``shift_px``:
    then its centre lands at the measured centre + (d_row, d_col) (px); ``score``: Pearson
    correlation of the warped simulation with the measured image, in [-1, 1].
    """

    mirrored: bool
    rotation_deg: float
    shift_px: tuple[float, float]
    score: float

    def map_offset_px(self, offset_px) -> np.ndarray:
        """Where a point ``offset_px`` (row, col) from the simulated image's centre lands, as
        an offset (px) from the measured image's centre: R(θ)·M·p + shift."""
        forward = _forward_matrix(self.mirrored, self.rotation_deg)
        return forward @ np.asarray(offset_px, dtype=float) + np.asarray(self.shift_px)

    @classmethod
    def from_record(cls, record: dict) -> Registration:
        """The registration of a record written by :meth:`to_record` (registration.json)."""
        return cls(
            mirrored=bool(record["mirrored"]),
            rotation_deg=float(record["rotation_deg"]),
            shift_px=(float(record["shift_row_px"]), float(record["shift_col_px"])),
            score=float(record["score"]),
        )

    def to_record(self) -> dict:
        """JSON-ready fields (plain Python types)."""
        return {
            "mirrored": bool(self.mirrored),
            "rotation_deg": float(self.rotation_deg),
            "shift_row_px": float(self.shift_px[0]),
            "shift_col_px": float(self.shift_px[1]),
            "score": float(self.score),
        }


def _centre(shape: tuple[int, ...]) -> np.ndarray:
    """Centre of an image of ``shape``, (row, col) in px: (n - 1)/2 per axis."""
    return (np.asarray(shape[:2], dtype=float) - 1.0) / 2.0


def _forward_matrix(mirrored: bool, rotation_deg: float) -> np.ndarray:
    """R(θ)·M in (row, col): the linear part of the simulated → measured map."""
    theta = np.deg2rad(rotation_deg)
    c, s = np.cos(theta), np.sin(theta)
    rotation = np.array([[c, -s], [s, c]])
    mirror = np.diag([1.0, -1.0]) if mirrored else np.eye(2)
    return rotation @ mirror


def _wrap_deg(angle: float) -> float:
    """An angle (degrees) brought into [-180, 180)."""
    return float((angle + 180.0) % 360.0 - 180.0)


def warp_to_measured(
    simulated: np.ndarray,
    registration: Registration,
    shape: tuple[int, int],
    order: int = 1,
) -> np.ndarray:
    """The simulated image (any shape) seen on the measured image's grid of ``shape`` (px).

    For each measured pixel q, the value of the simulated image at the inverse-mapped position
    p = M·R(-θ)·(q - c_meas - shift) + c_sim (0 outside the simulated image). ``order`` is the
    spline order: 0 for masks (a boolean image comes back boolean), 1 for intensities.
    """
    image = np.asarray(simulated)
    if image.ndim != 2:
        raise ValueError(f"the simulated image must be 2-D, got shape {image.shape}")
    rows, cols = (int(n) for n in shape)
    if rows < 1 or cols < 1:
        raise ValueError(f"the measured grid must have positive sides, got {shape}")
    # The inverse of R(θ)·M is M·R(-θ), M being its own inverse.
    inverse = np.linalg.inv(_forward_matrix(registration.mirrored, registration.rotation_deg))
    origin = _centre((rows, cols)) + np.asarray(registration.shift_px, dtype=float)
    q_row = (np.arange(rows) - origin[0])[:, None]
    q_col = (np.arange(cols) - origin[1])[None, :]
    c_sim = _centre(image.shape)
    p_row = inverse[0, 0] * q_row + inverse[0, 1] * q_col + c_sim[0]
    p_col = inverse[1, 0] * q_row + inverse[1, 1] * q_col + c_sim[1]
    values = map_coordinates(
        image.astype(float),
        [p_row, p_col],
        order=order,
        mode="constant",
        cval=0.0,
        prefilter=order > 1,
    )
    return values > 0.5 if image.dtype == bool else values


def _finite_image(image: np.ndarray, name: str) -> np.ndarray:
    """``image`` as float64, or ValueError if it is not a finite 2-D image."""
    array = np.asarray(image, dtype=float)
    if array.ndim != 2 or min(array.shape) < 2:
        raise ValueError(
            f"the {name} image must be 2-D with at least 2 px per side, got {array.shape}"
        )
    if not np.all(np.isfinite(array)):
        raise ValueError(f"the {name} image has non-finite values (NaN or inf)")
    return array


def _is_featureless(image: np.ndarray) -> bool:
    """True when every pixel has the same value (within rounding)."""
    return float(np.ptp(image)) <= _FEATURELESS_RTOL * float(np.abs(image).max())


def _simulated_signal(simulated: np.ndarray) -> np.ndarray:
    """The simulated image minus its background (median of the outermost pixel ring)."""
    image = _finite_image(simulated, "simulated")
    ring = np.concatenate([image[0], image[-1], image[1:-1, 0], image[1:-1, -1]])
    signal = image - np.median(ring)
    if _is_featureless(signal):
        raise ValueError(
            "the simulated image is uniform (no contact rendered): nothing to register on"
        )
    return signal


def _measured_zero_mean(measured: np.ndarray) -> np.ndarray:
    """The measured image minus its mean, or ValueError if it is featureless."""
    image = _finite_image(measured, "measured")
    if _is_featureless(image):
        raise ValueError(
            f"the measured image is uniform (every pixel {image.flat[0]:g}): nothing to register on"
        )
    return image - image.mean()


def _pearson(warped: np.ndarray, measured_zero_mean: np.ndarray) -> float:
    """Pearson correlation of two images of one shape; 0 when the warped one is uniform
    (the simulation entirely outside the measured grid correlates with nothing)."""
    w = warped - warped.mean()
    norm = np.sqrt(np.sum(w * w) * np.sum(measured_zero_mean * measured_zero_mean))
    return float(np.sum(w * measured_zero_mean) / norm) if norm > 0 else 0.0


def overlay_score(simulated: np.ndarray, measured: np.ndarray, registration: Registration) -> float:
    """Score of ``registration`` (its own ``score`` field is ignored): the Pearson correlation,
    over the measured grid, of the background-subtracted simulation warped (linear
    interpolation) with the measured image, in [-1, 1]; 0 if the warp leaves nothing in view."""
    signal = _simulated_signal(simulated)
    meas = _measured_zero_mean(measured)
    return _pearson(warp_to_measured(signal, registration, meas.shape), meas)


def _signal_canvas_shape(signal: np.ndarray) -> tuple[int, int]:
    """A square canvas (px) holding the signal at any rotation about the image centre: twice
    the largest distance of a signal pixel from the centre, plus interpolation margin."""
    strong = np.abs(signal) > _SIGNAL_FLOOR * np.abs(signal).max()
    rows, cols = np.nonzero(strong)
    c = _centre(signal.shape)
    radius = float(np.sqrt(np.max((rows - c[0]) ** 2 + (cols - c[1]) ** 2)))
    side = int(np.ceil(2.0 * radius)) + 3
    return side, side


class _ShiftCorrelator:
    """Pearson correlation of a fixed measured image with a canvas placed at every integer
    offset, by FFT. Offset index k (per axis) puts canvas pixel i on measured pixel
    i + k - (canvas side - 1)."""

    def __init__(self, measured_zero_mean: np.ndarray, canvas_shape: tuple[int, int]):
        self.measured_shape = measured_zero_mean.shape
        self.canvas_shape = canvas_shape
        self.full = tuple(m + c - 1 for m, c in zip(self.measured_shape, canvas_shape, strict=True))
        # Padding to at least the full size keeps the circular correlation free of wrap-around.
        self.padded = tuple(sfft.next_fast_len(n, real=True) for n in self.full)
        self.f_measured = sfft.rfft2(measured_zero_mean, s=self.padded)
        self.f_ones = sfft.rfft2(np.ones(self.measured_shape), s=self.padded)
        self.sum_mm = float(np.sum(measured_zero_mean**2))
        self.n = measured_zero_mean.size

    def _correlate(self, f_reference: np.ndarray, f_canvas: np.ndarray) -> np.ndarray:
        """Σ_q reference(q)·canvas(q - t) for every offset, reordered so index 0 is the most
        negative offset t = -(canvas side - 1)."""
        circular = sfft.irfft2(f_reference * np.conj(f_canvas), s=self.padded)
        lead = tuple(c - 1 for c in self.canvas_shape)
        return np.roll(circular, lead, axis=(0, 1))[: self.full[0], : self.full[1]]

    def pearson_map(self, canvas: np.ndarray) -> np.ndarray:
        """Pearson correlation over the measured grid at every offset index; -inf where less
        than half the canvas's signal would be in view."""
        f_w = sfft.rfft2(canvas, s=self.padded)
        f_ww = sfft.rfft2(canvas * canvas, s=self.padded)
        s_mw = self._correlate(self.f_measured, f_w)
        s_w = self._correlate(self.f_ones, f_w)
        s_ww = self._correlate(self.f_ones, f_ww)
        variance = s_ww - s_w * s_w / self.n
        in_view = (s_ww >= _MIN_SIGNAL_IN_VIEW * float(np.sum(canvas * canvas))) & (variance > 0)
        scores = np.full(self.full, -np.inf)
        scores[in_view] = s_mw[in_view] / np.sqrt(self.sum_mm * variance[in_view])
        return scores

    def shift_of_index(self, index: np.ndarray) -> np.ndarray:
        """The registration shift (px) whose canvas centre lands at offset ``index``."""
        offset = np.asarray(index, dtype=float) - (np.asarray(self.canvas_shape) - 1)
        return _centre(self.canvas_shape) + offset - _centre(self.measured_shape)

    def index_of_shift(self, shift: np.ndarray) -> np.ndarray:
        """Inverse of :meth:`shift_of_index` (fractional index)."""
        offset = np.asarray(shift) - _centre(self.canvas_shape) + _centre(self.measured_shape)
        return offset + (np.asarray(self.canvas_shape) - 1)


def _parabolic_peak(scores: np.ndarray, peak: tuple[int, int]) -> tuple[np.ndarray, float]:
    """Sub-pixel peak position (fractional index) and height from a parabola through the peak
    and its two neighbours along each axis; no correction where a neighbour is missing."""
    position = np.asarray(peak, dtype=float)
    height = float(scores[peak])
    for axis in (0, 1):
        before, after = list(peak), list(peak)
        before[axis] -= 1
        after[axis] += 1
        if before[axis] < 0 or after[axis] >= scores.shape[axis]:
            continue
        lo, hi = float(scores[tuple(before)]), float(scores[tuple(after)])
        curvature = lo - 2.0 * height + hi
        if not (np.isfinite(lo) and np.isfinite(hi)) or curvature >= 0:
            continue
        step = float(np.clip(0.5 * (lo - hi) / curvature, -0.5, 0.5))
        position[axis] += step
        # The parabola's vertex rises above the sampled peak by (hi - lo)·step/4 per axis.
        height += 0.25 * (hi - lo) * step
    return position, height


def _best_offset(
    scores: np.ndarray, centre: np.ndarray | None = None, half_width: float | None = None
) -> tuple[np.ndarray, float] | None:
    """The highest score (sub-pixel index, height), optionally within ``half_width`` px of
    ``centre`` along each axis; None when no offset there keeps the signal in view."""
    if centre is not None:
        lo = np.maximum(np.floor(centre - half_width).astype(int), 0)
        hi = np.minimum(np.ceil(centre + half_width).astype(int) + 1, scores.shape)
        window = np.full(scores.shape, -np.inf)
        window[lo[0] : hi[0], lo[1] : hi[1]] = scores[lo[0] : hi[0], lo[1] : hi[1]]
        scores_in = window
    else:
        scores_in = scores
    peak = np.unravel_index(int(np.argmax(scores_in)), scores_in.shape)
    if not np.isfinite(scores_in[peak]):
        return None
    return _parabolic_peak(scores_in, (int(peak[0]), int(peak[1])))


def _canvas(signal: np.ndarray, mirrored: bool, rotation_deg: float, shape) -> np.ndarray:
    """The signal rotated (and mirrored) about its centre, centred on a canvas of ``shape``."""
    return warp_to_measured(signal, Registration(mirrored, rotation_deg, (0.0, 0.0), 0.0), shape)


def _coarse_factor(signal_shape, measured_shape) -> int:
    """Block size (px) that brings the measured image to ~_COARSE_SIZE_PX across without
    leaving either image narrower than _MIN_COARSE_SIDE_PX."""
    factor = max(measured_shape) // _COARSE_SIZE_PX
    factor = min(factor, min(signal_shape) // _MIN_COARSE_SIDE_PX)
    factor = min(factor, min(measured_shape) // _MIN_COARSE_SIDE_PX)
    return max(1, factor)


def _full_resolution_shift(
    coarse_shift: np.ndarray, factor: int, forward: np.ndarray, signal_shape, measured_shape
) -> np.ndarray:
    """A shift found on block-averaged images (coarse px) in full-resolution px.

    Coarse pixel k covers full pixels f·k … f·k + f - 1, so the coarse centres sit
    (n mod f)/2 px before the full ones: with c' those centres, q = A(p - c_sim) + c_meas +
    f·s_coarse + (c'_meas - c_meas) + A(c_sim - c'_sim).
    """
    signal_lag = (np.asarray(signal_shape) % factor) / 2.0
    measured_lag = (np.asarray(measured_shape) % factor) / 2.0
    return factor * coarse_shift - measured_lag + forward @ signal_lag


def _coarse_candidates(
    signal: np.ndarray, measured: np.ndarray, angle_step_deg: float, mirrors: tuple[bool, ...]
) -> list[Registration]:
    """The best local maxima over angle of the correlation on block-averaged images; shifts
    in full-resolution px, scores on the coarse images."""
    factor = _coarse_factor(signal.shape, measured.shape)
    small_signal = block_mean(signal, factor)
    small_measured = block_mean(measured, factor)
    small_measured -= small_measured.mean()
    if _is_featureless(small_signal) or _is_featureless(small_measured):
        raise ValueError("an image has no feature larger than the coarse-search block")
    canvas_shape = _signal_canvas_shape(small_signal)
    correlator = _ShiftCorrelator(small_measured, canvas_shape)
    n_angles = int(np.ceil(360.0 / angle_step_deg - 1e-9))
    angles = np.arange(n_angles) * (360.0 / n_angles)
    found = []
    for mirrored in mirrors:
        peaks = []
        for angle in angles:
            canvas = _canvas(small_signal, mirrored, angle, canvas_shape)
            best = _best_offset(correlator.pearson_map(canvas))
            peaks.append(best)
        heights = np.array([-np.inf if p is None else p[1] for p in peaks])
        for i, angle in enumerate(angles):
            # Local maxima on the circle of angles.
            neighbours = heights[[(i - 1) % n_angles, (i + 1) % n_angles]]
            if np.isfinite(heights[i]) and np.all(heights[i] >= neighbours):
                shift = _full_resolution_shift(
                    correlator.shift_of_index(peaks[i][0]),
                    factor,
                    _forward_matrix(mirrored, angle),
                    signal.shape,
                    measured.shape,
                )
                found.append(Registration(mirrored, float(angle), tuple(shift), heights[i]))
    if not found:
        raise ValueError(
            "no placement keeps half of the simulated contact inside the measured image: "
            "the measured field of view is too small for the simulation"
        )
    found.sort(key=lambda r: r.score, reverse=True)
    return found[:_CANDIDATES]


def _refine_angle(
    signal: np.ndarray,
    correlator: _ShiftCorrelator,
    candidate: Registration,
    angle_step_deg: float,
    search_px: float,
) -> Registration:
    """Full-resolution angle within one coarse step of the candidate (bounded Brent), the
    shift re-found by FFT within ``search_px`` of the candidate's, to sub-pixel."""
    expected_index = correlator.index_of_shift(np.asarray(candidate.shift_px))

    def peak_at(angle: float) -> tuple[np.ndarray, float]:
        canvas = _canvas(signal, candidate.mirrored, angle, correlator.canvas_shape)
        best = _best_offset(correlator.pearson_map(canvas), expected_index, search_px)
        return (expected_index, -np.inf) if best is None else best

    result = minimize_scalar(
        lambda angle: -peak_at(angle)[1],
        bounds=(candidate.rotation_deg - angle_step_deg, candidate.rotation_deg + angle_step_deg),
        method="bounded",
        options={"xatol": 0.02},
    )
    index, height = peak_at(float(result.x))
    shift = correlator.shift_of_index(index)
    return Registration(candidate.mirrored, float(result.x), tuple(shift), height)


def _polish(signal: np.ndarray, measured: np.ndarray, start: Registration) -> Registration:
    """Nelder-Mead on the exact score over (angle, row shift, column shift)."""

    def transform(x: np.ndarray) -> Registration:
        return Registration(start.mirrored, float(x[0]), (float(x[1]), float(x[2])), 0.0)

    def negative_score(x: np.ndarray) -> float:
        return -_pearson(warp_to_measured(signal, transform(x), measured.shape), measured)

    x0 = np.array([start.rotation_deg, *start.shift_px])
    # Steps of a fraction of a degree and of a pixel: the refinement is already that close.
    simplex = np.vstack([x0, x0 + [0.3, 0, 0], x0 + [0, 0.3, 0], x0 + [0, 0, 0.3]])
    result = minimize(
        negative_score,
        x0,
        method="Nelder-Mead",
        options={"initial_simplex": simplex, "xatol": 1e-3, "fatol": 1e-9, "maxiter": 400},
    )
    x = result.x if result.fun <= negative_score(x0) else x0
    return Registration(
        start.mirrored,
        _wrap_deg(float(x[0])),
        (float(x[1]), float(x[2])),
        -negative_score(x),
    )


def register(
    simulated: np.ndarray,
    measured: np.ndarray,
    *,
    angle_step_deg: float = 4.0,
    mirror: bool = True,
) -> Registration:
    """Find the transform that best overlays ``simulated`` on ``measured`` (shapes may
    differ; same pixel size).

    ``angle_step_deg`` (degrees) is the coarse angular grid; features far from the centre
    move by radius × step, so keep radius·step/2 (radians) within a few blur widths.
    ``mirror=False`` searches rotations only. Raises ValueError for an image with nothing
    to register on (uniform, all zero, non-finite) or a simulation that cannot fit.
    """
    if not 0.0 < angle_step_deg <= 45.0:
        raise ValueError(f"angle_step_deg must be in (0, 45] degrees, got {angle_step_deg}")
    signal = _simulated_signal(simulated)
    meas = _measured_zero_mean(measured)
    mirrors = (False, True) if mirror else (False,)
    candidates = _coarse_candidates(signal, meas, angle_step_deg, mirrors)

    factor = _coarse_factor(signal.shape, meas.shape)
    correlator = _ShiftCorrelator(meas, _signal_canvas_shape(signal))
    # The window must cover the coarse shift's error: a block, and the drift of the best
    # shift as the angle moves by a step about a signal that may lie off the centre.
    radius = (correlator.canvas_shape[0] - 3) / 2.0
    search_px = 2.0 * factor + 2.0 + radius * np.deg2rad(angle_step_deg)
    refined = [_refine_angle(signal, correlator, c, angle_step_deg, search_px) for c in candidates]
    return _polish(signal, meas, max(refined, key=lambda r: r.score))
