"""Gap at the fluorescent contact edge from the Newton rings of the reflection image (B.1.1).

Bright rings sit where the gap is d_m = (m + ½)·λ/2n (eq. B.1; 84.3, 252.9, 421.5 nm … for
λ = 488 nm in formamide, n = 1.447). Along line profiles through the contact centre the ring
maxima give gap-versus-distance points; a curve through them, extrapolated to the contact edge
found in the fluorescence image, gives the gap at which the rigidochromic molecules light up
(the appendix finds 9 nm averaged over 20 profiles).

Per half-profile (a ray from the centre at angle φ, measured from the +column axis towards
+row): sample the lightly smoothed image (scipy.ndimage.map_coordinates), find the maxima with
a prominence criterion (scipy.signal.find_peaks), refine each to sub-sample precision with a
local parabola, number them m = 0, 1, 2 … from the centre outward, and fit the gap:

- ``edge_model="quadratic"``: the appendix's second-degree polynomial d(r). It is biased when
  the gap is Hertz-like: the gap rises as (r − a)^{3/2} from the edge, which no parabola
  through the rings (27–47 µm from the centre for a 4 mm glass sphere at 100 mN, edge at
  16.6 µm) follows, and it extrapolates to −15 nm at the edge where the truth is 0.
- ``edge_model="hertz"`` (default): d(r) = δ + S(r)/R_eff with the Hertz exterior shape
  S(r) = [a·√(r² − a²) − (2a² − r²)·acos(a/r)]/π about the given edge radius a; a linear
  least-squares fit for the edge gap δ and the curvature 1/R_eff. Exact for a Hertz contact,
  also when the gap outside is offset by δ.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import gaussian_filter, map_coordinates
from scipy.signal import find_peaks

from amontons.physics.newton_rings import (
    APPENDIX_WAVELENGTH_M,
    FORMAMIDE_REFRACTIVE_INDEX,
    ring_gap,
)

_EDGE_MODELS = ("hertz", "quadratic")
_MIN_RINGS = {"hertz": 2, "quadratic": 3}


class NewtonRingError(ValueError):
    """A reflection image from which no gap profile can be read."""


# A missed ring on a few half-profiles is local (roughness scatters a ring); on more than
# this fraction of them it is the image's ring sequence that cannot be numbered.
MAX_MISSED_FRACTION = 0.25


class MissedRingError(NewtonRingError):
    """A half-profile whose ring spacing says a ring was not detected."""


@dataclass(frozen=True)
class HalfProfile:
    """Rings along one ray from the contact centre."""

    angle_rad: float
    ring_r_m: np.ndarray  # distance of each ring maximum from the centre
    ring_gap_m: np.ndarray  # its gap from eq. B.1
    edge_gap_m: float  # the fitted gap extrapolated to the contact edge


@dataclass(frozen=True)
class NewtonRingGap:
    """Gap at the contact edge from 2 × n_profiles half-profiles; lengths in m."""

    edge_gap_mean_m: float
    edge_gap_sd_m: float
    edge_gaps_m: np.ndarray  # one per half-profile, in the order of angles_rad
    angles_rad: np.ndarray
    first_ring_gap_m: float  # d_0 = λ/4n
    contact_radius_m: float
    edge_model: str
    half_profiles: tuple[HalfProfile, ...]
    # half-profiles left out, each with its reason (a rough sphere scatters its rings)
    rejected: tuple[str, ...] = ()


def hertz_exterior_shape(r_m: np.ndarray, edge_radius_m: float) -> np.ndarray:
    """S(r) = [a·√(r² − a²) − (2a² − r²)·acos(a/r)]/π (m²): Hertz gap × R outside r = a."""
    a = edge_radius_m
    r = np.maximum(np.asarray(r_m, dtype=float), a)
    return (a * np.sqrt(r**2 - a**2) - (2 * a**2 - r**2) * np.arccos(a / r)) / np.pi


def robust_noise_sd(image: np.ndarray) -> float:
    """Pixel noise sd from second differences along rows (MAD).

    A second difference I[j+1] − 2I[j] + I[j−1] of independent noise has variance 6σ², while
    rings tens of pixels wide contribute only their small curvature, so the estimate is not
    inflated by the fringes as a first difference would be by their slope.
    """
    second = (image[:, 2:] - 2 * image[:, 1:-1] + image[:, :-2]).ravel()
    mad = np.median(np.abs(second - np.median(second)))
    return float(1.4826 * mad / np.sqrt(6))


def refine_peak(r: np.ndarray, values: np.ndarray, index: int, half_width: int) -> float:
    """Sub-sample position of a maximum: vertex of a least-squares parabola around it."""
    lo, hi = max(index - half_width, 0), min(index + half_width + 1, r.size)
    if hi - lo < 3:
        return float(r[index])
    curvature, slope, _ = np.polyfit(r[lo:hi] - r[index], values[lo:hi], 2)
    if curvature >= 0:
        return float(r[index])
    offset = -slope / (2 * curvature)
    if abs(offset) > r[hi - 1] - r[index] or abs(offset) > r[index] - r[lo]:
        return float(r[index])  # vertex outside the window: the parabola does not describe it
    return float(r[index] + offset)


def fit_edge_gap(
    ring_r_m: np.ndarray,
    ring_gap_m: np.ndarray,
    contact_radius_m: float,
    edge_model: str,
    shape_radius_m: float | None = None,
) -> float:
    """Gap (m) at ``contact_radius_m`` from a fit to the ring points.

    'hertz': gap = g0 + c·S(r; a) with the Hertz exterior shape S of radius a =
    ``shape_radius_m`` (default: the contact radius itself), g0 and c fitted.
    """
    if edge_model == "quadratic":
        coefficients = np.polyfit(ring_r_m, ring_gap_m, 2)
        return float(np.polyval(coefficients, contact_radius_m))
    a = contact_radius_m if shape_radius_m is None else shape_radius_m
    design = np.column_stack([np.ones_like(ring_r_m), hertz_exterior_shape(ring_r_m, a)])
    (offset, scale), *_ = np.linalg.lstsq(design, ring_gap_m, rcond=None)
    return float(offset + scale * hertz_exterior_shape(np.array([contact_radius_m]), a)[0])


def _ray(
    image: np.ndarray, centre_px: tuple[float, float], angle: float, step_px: float
) -> tuple[np.ndarray, np.ndarray]:
    """Samples (distance in px, intensity) along a ray from the centre to the image edge."""
    d_row, d_col = np.sin(angle), np.cos(angle)
    limits = []
    for start, direction, size in (
        (centre_px[0], d_row, image.shape[0]),
        (centre_px[1], d_col, image.shape[1]),
    ):
        if direction > 1e-12:
            limits.append((size - 1 - start) / direction)
        elif direction < -1e-12:
            limits.append(start / -direction)
    r_px = np.arange(0.0, min(limits), step_px)
    coordinates = np.vstack([centre_px[0] + r_px * d_row, centre_px[1] + r_px * d_col])
    return r_px, map_coordinates(image, coordinates, order=3)


def _check_spacing(ring_r_m: np.ndarray, degrees: float, max_ratio: float) -> None:
    """Refuse a gap in the ring sequence: a missed ring would shift every later ring order.

    Around a convex body the rings crowd outward (spacing ∝ 1/r far out; successive spacing
    ratios 1.34, 1.19, 1.13 … for Hertz), so a spacing more than ``max_ratio`` times the next
    one means a ring in between was not detected.
    """
    spacing = np.diff(ring_r_m)
    if spacing.size < 2:
        return
    ratios = spacing[:-1] / spacing[1:]
    worst = int(np.argmax(ratios))
    if ratios[worst] > max_ratio:
        raise MissedRingError(
            f"profile at {degrees:.1f}°: rings at {ring_r_m[worst]:.3g} and "
            f"{ring_r_m[worst + 1]:.3g} m are {ratios[worst]:.2f} × further apart than the next "
            f"pair (expected ≤ {max_ratio:g}); a ring in between was probably missed, which "
            "would misnumber the rings outside it"
        )


def _half_profile(
    image: np.ndarray,
    centre_px: tuple[float, float],
    angle: float,
    pixel_m: float,
    contact_radius_m: float,
    settings: dict,
) -> HalfProfile:
    r_px, values = _ray(image, centre_px, angle, settings["step_px"])
    r_m = r_px * pixel_m
    reach_m = float(r_m[-1]) if r_m.size else 0.0
    peaks, _ = find_peaks(values, prominence=settings["prominence"])
    degrees = np.degrees(angle)
    inside = peaks[r_m[peaks] <= contact_radius_m]
    if inside.size:
        raise NewtonRingError(
            f"profile at {degrees:.1f}°: a bright ring at r = {r_m[inside[0]]:.3g} m lies inside "
            f"the contact edge ({contact_radius_m:.3g} m), so the ring orders are ambiguous; "
            "expected the first ring (m = 0) outside the edge — check the centre and radius"
        )
    if settings["max_rings"] is not None:
        peaks = peaks[: settings["max_rings"]]
    needed = _MIN_RINGS[settings["edge_model"]]
    if peaks.size < needed:
        raise NewtonRingError(
            f"profile at {degrees:.1f}°: {peaks.size} ring maxima found (prominence ≥ "
            f"{settings['prominence']:.3g} counts) within {reach_m:.3g} m of the centre; the "
            f"'{settings['edge_model']}' edge fit needs at least {needed}"
        )
    # Refine each maximum over ±1/8 of the local ring spacing (±π/4 of fringe phase), where a
    # fringe is still close to a parabola; ring 0's spacing is its distance from the edge.
    spacing = np.diff(np.concatenate([[contact_radius_m / pixel_m / settings["step_px"]], peaks]))
    ring_r = np.array(
        [
            refine_peak(r_m, values, int(p), max(2, round(0.125 * s)))
            for p, s in zip(peaks, spacing, strict=True)
        ]
    )
    _check_spacing(ring_r, degrees, settings["max_spacing_ratio"])
    gaps = ring_gap(np.arange(ring_r.size), settings["wavelength_m"], settings["n_medium"])
    edge = fit_edge_gap(
        ring_r, gaps, contact_radius_m, settings["edge_model"], settings["shape_radius_m"]
    )
    return HalfProfile(float(angle), ring_r, gaps, edge)


def newton_ring_gap(
    reflection: np.ndarray,
    pixel_m: float,
    centre_px: tuple[float, float],
    contact_radius_m: float,
    n_profiles: int = 20,
    wavelength_m: float = APPENDIX_WAVELENGTH_M,
    n_medium: float = FORMAMIDE_REFRACTIVE_INDEX,
    *,
    edge_model: str = "hertz",
    max_rings: int | None = None,
    prominence_fraction: float = 0.3,
    min_prominence_sd: float = 5.0,
    smooth_px: float = 1.0,
    step_px: float = 0.5,
    max_spacing_ratio: float = 1.8,
    min_accepted_fraction: float = 0.5,
    shape_radius_m: float | None = None,
) -> NewtonRingGap:
    """Gap (m) at the contact edge from ``n_profiles`` lines through ``centre_px`` (row, col).

    Each line gives two half-profiles (angles kπ/n and kπ/n + π), so 2·n_profiles edge gaps
    enter the mean and sd. ``contact_radius_m`` is the fluorescent edge radius (from the Otsu
    mask). A maximum counts as a ring when its prominence exceeds both ``prominence_fraction``
    of the image's 2–98 % intensity range and ``min_prominence_sd`` pixel-noise standard
    deviations (so pure noise never makes rings). ``max_rings`` keeps only the innermost rings.
    ``shape_radius_m``: radius of the Hertz exterior shape the 'hertz' model fits (default
    the fluorescent edge). The far field of a contact is set by its load: a rough or
    flattened sphere's Otsu edge lies well inside the radius whose Hertz shape its rings
    follow, and a shape of the edge's radius then biases the extrapolation by −8 nm (rough
    glass sphere of the virtual experiment); the Hertz radius of the load does not.
    A half-profile whose ring spacing jumps by more than ``max_spacing_ratio`` is refused
    (a missed ring). Refused half-profiles are left out and listed in ``rejected`` with their
    reason, as long as at least ``min_accepted_fraction`` of them remain (roughness on the
    sphere scatters single rings; the rest still measure the average gap).

    Raises NewtonRingError for a centre outside the image, an unknown edge model, or when
    fewer than ``min_accepted_fraction`` of the half-profiles have enough, correctly ordered
    rings outside the contact edge (the message names the first refused profile's reason).
    """
    image = np.asarray(reflection, dtype=float)
    if image.ndim != 2:
        raise NewtonRingError(f"reflection image has shape {image.shape}; expected 2-D")
    if edge_model not in _EDGE_MODELS:
        raise NewtonRingError(f"edge_model '{edge_model}'; expected one of {_EDGE_MODELS}")
    row, col = centre_px
    if not (0 <= row <= image.shape[0] - 1 and 0 <= col <= image.shape[1] - 1):
        raise NewtonRingError(
            f"contact centre (row {row:g}, col {col:g}) px lies outside the {image.shape} "
            "reflection image"
        )
    if contact_radius_m <= 0:
        raise NewtonRingError(f"contact radius {contact_radius_m} m; expected > 0")
    low, high = np.percentile(image, [2, 98])
    settings = {
        "prominence": max(
            prominence_fraction * (high - low), min_prominence_sd * robust_noise_sd(image)
        ),
        "max_rings": max_rings,
        "edge_model": edge_model,
        "step_px": step_px,
        "wavelength_m": wavelength_m,
        "n_medium": n_medium,
        "max_spacing_ratio": max_spacing_ratio,
        "shape_radius_m": shape_radius_m,
    }
    # Noise is independent per pixel while the rings are tens of pixels wide: smoothing by a
    # pixel removes most of the noise and leaves the ring maxima where they are.
    smoothed = gaussian_filter(image, smooth_px, mode="nearest") if smooth_px > 0 else image
    angles = np.concatenate(
        [
            np.arange(n_profiles) * np.pi / n_profiles,
            np.arange(n_profiles) * np.pi / n_profiles + np.pi,
        ]
    )
    profiles, rejected, missed = [], [], []
    for angle in angles:
        try:
            profiles.append(
                _half_profile(smoothed, (row, col), angle, pixel_m, contact_radius_m, settings)
            )
        except MissedRingError as error:
            missed.append(str(error))
        except NewtonRingError as error:
            rejected.append(str(error))
    if len(missed) > MAX_MISSED_FRACTION * angles.size:
        raise NewtonRingError(
            f"{len(missed)} of {angles.size} half-profiles missed a ring (more than "
            f"{MAX_MISSED_FRACTION:.0%}): the ring orders of this image are not safe; first: "
            f"{missed[0]}"
        )
    rejected += missed
    if missed:
        # The spacing test needs three rings; once it has caught a missed ring elsewhere,
        # a two-ring profile may be misnumbered in the same way without showing it.
        unchecked = [p for p in profiles if p.ring_r_m.size < 3]
        profiles = [p for p in profiles if p.ring_r_m.size >= 3]
        rejected += [
            f"profile at {np.degrees(p.angle_rad):.1f}°: {p.ring_r_m.size} rings cannot show a "
            "missed ring, and other profiles missed one"
            for p in unchecked
        ]
    if len(profiles) < max(2, min_accepted_fraction * angles.size):
        raise NewtonRingError(
            f"{len(rejected)} of {angles.size} half-profiles refused (at least "
            f"{min_accepted_fraction:.0%} must have usable rings); first: {rejected[0]}"
        )
    edges = np.array([p.edge_gap_m for p in profiles])
    return NewtonRingGap(
        edge_gap_mean_m=float(edges.mean()),
        edge_gap_sd_m=float(edges.std(ddof=1)),
        edge_gaps_m=edges,
        angles_rad=np.array([p.angle_rad for p in profiles]),
        first_ring_gap_m=float(ring_gap(0, wavelength_m, n_medium)),
        contact_radius_m=float(contact_radius_m),
        edge_model=edge_model,
        half_profiles=tuple(profiles),
        rejected=tuple(rejected),
    )
