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
- ``edge_model="hertz_sheet_radius"``: d(r) = δ + c·S(r; a) with the Hertz exterior shape
  S(r) = [a·√(r² − a²) − (2a² − r²)·acos(a/r)]/π about a given radius a (the Hertz radius
  of the load from the sheet's E* and diameter); per half-profile a linear least-squares fit
  for δ and the curvature c = 1/R_eff. Exact for a Hertz contact of that radius, also when
  the gap outside is offset by δ; biased when a is: ±20 % on E* moves a by ∓6–7 %.
- ``edge_model="hertz_free_radius"`` (default): the same shape with a fitted to the rings
  themselves, one radius shared by every half-profile (the load's far field is
  axisymmetric), δ and c per half-profile (variable projection: for each trial a the
  per-profile fits are linear; a minimises the summed squared residuals).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.ndimage import gaussian_filter, map_coordinates
from scipy.optimize import minimize_scalar
from scipy.signal import find_peaks

from amontons.physics.newton_rings import (
    APPENDIX_WAVELENGTH_M,
    FORMAMIDE_REFRACTIVE_INDEX,
    ring_gap,
)

SHEET_RADIUS, FREE_RADIUS, QUADRATIC = "hertz_sheet_radius", "hertz_free_radius", "quadratic"
EDGE_MODELS = (FREE_RADIUS, SHEET_RADIUS, QUADRATIC)
# Fewest rings a half-profile needs: two for two linear unknowns (δ, c; the free radius is
# shared by all profiles), three for the parabola's three.
_MIN_RINGS = {FREE_RADIUS: 2, SHEET_RADIUS: 2, QUADRATIC: 3}


class NewtonRingError(ValueError):
    """A reflection image from which no gap profile can be read."""


# A missed ring on a few half-profiles is local (roughness scatters a ring); on more than
# this fraction of them it is the image's ring sequence that cannot be numbered.
MAX_MISSED_FRACTION = 0.25


class MissedRingError(NewtonRingError):
    """A half-profile whose ring spacing says a ring was not detected."""


@dataclass(frozen=True)
class HalfProfile:
    """Rings along one ray from the contact centre; lengths in m."""

    angle_rad: float
    edge_radius_m: float  # the fluorescent contact edge on this ray
    ring_r_m: np.ndarray  # distance of each ring maximum from the centre
    ring_gap_m: np.ndarray  # its gap from eq. B.1
    edge_gap_m: float = float("nan")  # the fitted gap extrapolated to this ray's edge


@dataclass(frozen=True)
class NewtonRingGap:
    """Gap at the contact edge from 2 × n_profiles half-profiles; lengths in m."""

    edge_gap_mean_m: float
    edge_gap_sd_m: float
    edge_gaps_m: np.ndarray  # one per half-profile, in the order of angles_rad
    angles_rad: np.ndarray
    first_ring_gap_m: float  # d_0 = λ/4n
    edge_radii_m: np.ndarray  # the fluorescent edge of each accepted half-profile
    edge_model: str
    half_profiles: tuple[HalfProfile, ...]
    # half-profiles left out, each with its reason (a rough sphere scatters its rings)
    rejected: tuple[str, ...] = ()
    # radius of the Hertz shape the rings were fitted with (None for the parabola)
    shape_radius_m: float | None = None


def half_profile_angles(n_profiles: int) -> np.ndarray:
    """Angles (rad) of the 2·n_profiles half-profiles: kπ/n and kπ/n + π, k = 0 … n − 1,
    measured from the +column axis towards +row."""
    if n_profiles < 1:
        raise NewtonRingError(f"n_profiles = {n_profiles}; expected at least 1")
    base = np.arange(n_profiles) * np.pi / n_profiles
    return np.concatenate([base, base + np.pi])


def hertz_exterior_shape(r_m: np.ndarray, edge_radius_m: float) -> np.ndarray:
    """S(r) = [a·√(r² − a²) − (2a² − r²)·acos(a/r)]/π (m²): Hertz gap × R outside r = a."""
    a = edge_radius_m
    r = np.maximum(np.asarray(r_m, dtype=float), a)
    if a <= 0:
        return r**2 / 2  # the limit a → 0: a bare paraboloid
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


def _hertz_coefficients(ring_r_m, ring_gap_m, shape_radius_m):
    """(δ, c) of d = δ + c·S(r; a) by linear least squares, and the squared residual sum."""
    design = np.column_stack(
        [np.ones_like(ring_r_m), hertz_exterior_shape(ring_r_m, shape_radius_m)]
    )
    coefficients, *_ = np.linalg.lstsq(design, ring_gap_m, rcond=None)
    residual = ring_gap_m - design @ coefficients
    return coefficients, float(residual @ residual)


def fit_edge_gap(
    ring_r_m: np.ndarray,
    ring_gap_m: np.ndarray,
    edge_radius_m: float,
    edge_model: str,
    shape_radius_m: float | None = None,
) -> float:
    """Gap (m) at ``edge_radius_m`` from a fit to the ring points (r in m, gaps in m).

    'quadratic': the parabola through the rings. The Hertz models: gap = δ + c·S(r; a) with
    a = ``shape_radius_m`` (the sheet's Hertz radius, or the radius fitted to every
    profile's rings by :func:`fit_hertz_radius`), δ and c fitted.
    """
    if edge_model == QUADRATIC:
        coefficients = np.polyfit(ring_r_m, ring_gap_m, 2)
        return float(np.polyval(coefficients, edge_radius_m))
    if shape_radius_m is None:
        raise NewtonRingError(f"edge model '{edge_model}' needs the radius of its Hertz shape")
    (offset, scale), _ = _hertz_coefficients(ring_r_m, ring_gap_m, shape_radius_m)
    return float(
        offset + scale * hertz_exterior_shape(np.array([edge_radius_m]), shape_radius_m)[0]
    )


def _summed_residuals(profiles, shape_radius_m: float) -> float:
    return sum(_hertz_coefficients(p.ring_r_m, p.ring_gap_m, shape_radius_m)[1] for p in profiles)


def fit_hertz_radius(profiles, grid_points: int = 200) -> float:
    """Radius a (m) of the Hertz exterior shape that fits every half-profile's rings best.

    One a for all profiles, δ and c per profile (each linear once a is fixed): a grid search
    over 0 ≤ a < the innermost ring of any profile (the rings lie outside the contact), then
    a bounded scalar minimisation around the best grid point. The rings constrain a only
    through the shape's (r − a)^{3/2} rise near the edge and its 4a³/3πRr tail, so a needs
    the rings of many profiles; a single profile's a would scatter by microns.
    """
    upper = min(float(p.ring_r_m[0]) for p in profiles) * (1 - 1e-6)
    grid = np.linspace(0.0, upper, grid_points)
    costs = np.array([_summed_residuals(profiles, a) for a in grid])
    best = int(np.argmin(costs))
    lo, hi = grid[max(best - 1, 0)], grid[min(best + 1, grid.size - 1)]
    refined = minimize_scalar(
        lambda a: _summed_residuals(profiles, a), bounds=(lo, hi), method="bounded"
    )
    return float(refined.x) if refined.fun <= costs[best] else float(grid[best])


def extrapolate_to_edges(
    profiles, edge_model: str, shape_radius_m: float | None = None
) -> tuple[np.ndarray, float | None]:
    """Gap (m) of each half-profile's fit at its own edge, and the Hertz radius (m) used.

    ``shape_radius_m`` is the sheet's Hertz radius for 'hertz_sheet_radius'; the free-radius
    model fits it (:func:`fit_hertz_radius`); the parabola has none (None).
    """
    if edge_model == FREE_RADIUS:
        shape_radius_m = fit_hertz_radius(profiles)
    elif edge_model == QUADRATIC:
        shape_radius_m = None
    gaps = np.array(
        [
            fit_edge_gap(p.ring_r_m, p.ring_gap_m, p.edge_radius_m, edge_model, shape_radius_m)
            for p in profiles
        ]
    )
    return gaps, shape_radius_m


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
    edge_radius_m: float,
    settings: dict,
) -> HalfProfile:
    """The numbered rings outside ``edge_radius_m`` along one ray (not yet extrapolated)."""
    degrees = np.degrees(angle)
    if not np.isfinite(edge_radius_m):
        raise NewtonRingError(
            f"profile at {degrees:.1f}°: the ray meets no contact pixel, so it has no edge to "
            "extrapolate to"
        )
    r_px, values = _ray(image, centre_px, angle, settings["step_px"])
    r_m = r_px * pixel_m
    reach_m = float(r_m[-1]) if r_m.size else 0.0
    peaks, _ = find_peaks(values, prominence=settings["prominence"])
    inside = peaks[r_m[peaks] <= edge_radius_m]
    if inside.size:
        raise NewtonRingError(
            f"profile at {degrees:.1f}°: a bright ring at r = {r_m[inside[0]]:.3g} m lies inside "
            f"the contact edge ({edge_radius_m:.3g} m), so the ring orders are ambiguous; "
            "expected the first ring (m = 0) outside the edge — check the centre and radius"
        )
    if settings["max_rings"] is not None and settings["edge_model"] != FREE_RADIUS:
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
    spacing = np.diff(np.concatenate([[edge_radius_m / pixel_m / settings["step_px"]], peaks]))
    ring_r = np.array(
        [
            refine_peak(r_m, values, int(p), max(2, round(0.125 * s)))
            for p, s in zip(peaks, spacing, strict=True)
        ]
    )
    _check_spacing(ring_r, degrees, settings["max_spacing_ratio"])
    gaps = ring_gap(np.arange(ring_r.size), settings["wavelength_m"], settings["n_medium"])
    return HalfProfile(float(angle), float(edge_radius_m), ring_r, gaps)


def _edge_radii(contact_radius_m, n_half_profiles: int) -> np.ndarray:
    """One edge radius (m) per half-profile from a scalar or a per-profile array (NaN: the
    ray meets no contact)."""
    radii = np.broadcast_to(np.asarray(contact_radius_m, dtype=float), (n_half_profiles,))
    if radii.shape != (n_half_profiles,) or np.any(radii[np.isfinite(radii)] <= 0):
        raise NewtonRingError(
            f"contact edge radii {np.asarray(contact_radius_m)!r} m; expected one value > 0 "
            f"or {n_half_profiles} (one per half-profile, NaN where a ray meets no contact)"
        )
    if not np.isfinite(radii).any():
        raise NewtonRingError("no half-profile meets the contact; expected a contact edge")
    return radii


def _checked_image(reflection, edge_model: str, shape_radius_m: float | None) -> np.ndarray:
    """The reflection image as a 2-D float array (counts), once it and the edge model pass.

    Checked before anything is computed so that a wrong call fails with its own reason, not
    with whatever the profile loop would stumble over.
    """
    image = np.asarray(reflection, dtype=float)
    if image.ndim != 2:
        raise NewtonRingError(f"reflection image has shape {image.shape}; expected 2-D")
    if edge_model not in EDGE_MODELS:
        raise NewtonRingError(f"edge_model '{edge_model}'; expected one of {EDGE_MODELS}")
    if edge_model == SHEET_RADIUS and not (shape_radius_m and shape_radius_m > 0):
        raise NewtonRingError(
            f"edge model '{SHEET_RADIUS}' needs the sheet's Hertz radius (shape_radius_m > 0); "
            f"got {shape_radius_m!r}"
        )
    return image


def _centre_inside(image: np.ndarray, centre_px: tuple[float, float]) -> tuple[float, float]:
    """The contact centre (row, col) in px, refused when it lies outside the image."""
    row, col = centre_px
    if not (0 <= row <= image.shape[0] - 1 and 0 <= col <= image.shape[1] - 1):
        raise NewtonRingError(
            f"contact centre (row {row:g}, col {col:g}) px lies outside the {image.shape} "
            "reflection image"
        )
    return row, col


def _ring_prominence(
    image: np.ndarray, prominence_fraction: float, min_prominence_sd: float
) -> float:
    """Least prominence (counts) of a maximum that counts as a ring: ``prominence_fraction``
    of the 2–98 % intensity range or ``min_prominence_sd`` noise sds, whichever is larger."""
    low, high = np.percentile(image, [2, 98])
    if not high > low:
        # no intensity range, no prominence threshold: round-off of the smoothing would
        # otherwise pass for ring maxima
        raise NewtonRingError(
            f"reflection image is uniform ({low:g} counts over 96 % of its pixels); expected "
            "Newton rings around the contact"
        )
    return max(prominence_fraction * (high - low), min_prominence_sd * robust_noise_sd(image))


def _read_half_profiles(
    smoothed: np.ndarray,
    centre_px: tuple[float, float],
    angles: np.ndarray,
    edge_radii: np.ndarray,
    pixel_m: float,
    settings: dict,
) -> tuple[list[HalfProfile], list[str], list[str]]:
    """Every ray's half-profile (angles in rad, radii and pixel in m), or why it was refused:
    (profiles, other refusals, missed-ring refusals), in the order of ``angles``.

    Missed rings are kept apart because their count decides whether the image's ring
    numbering can be trusted at all (:func:`_drop_missed_ring_profiles`).
    """
    profiles, rejected, missed = [], [], []
    for angle, edge in zip(angles, edge_radii, strict=True):
        try:
            profiles.append(_half_profile(smoothed, centre_px, angle, pixel_m, edge, settings))
        except MissedRingError as error:
            missed.append(str(error))
        except NewtonRingError as error:
            rejected.append(str(error))
    return profiles, rejected, missed


def _drop_missed_ring_profiles(
    profiles: list[HalfProfile], rejected: list[str], missed: list[str], n_half_profiles: int
) -> tuple[list[HalfProfile], list[str]]:
    """The profiles still trusted once rings were missed, and all refusals with reasons.

    Refuses the image when more than :data:`MAX_MISSED_FRACTION` of its half-profiles
    missed a ring.
    """
    if len(missed) > MAX_MISSED_FRACTION * n_half_profiles:
        raise NewtonRingError(
            f"{len(missed)} of {n_half_profiles} half-profiles missed a ring (more than "
            f"{MAX_MISSED_FRACTION:.0%}): the ring orders of this image are not safe; first: "
            f"{missed[0]}"
        )
    rejected = rejected + missed
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
    return profiles, rejected


def _check_enough_accepted(
    profiles: list[HalfProfile],
    rejected: list[str],
    n_half_profiles: int,
    min_accepted_fraction: float,
) -> None:
    """Refuse the image when fewer than ``min_accepted_fraction`` of its half-profiles (and
    fewer than two, the least an sd needs) remain; the message names the first refusal."""
    if len(profiles) < max(2, min_accepted_fraction * n_half_profiles):
        raise NewtonRingError(
            f"{len(rejected)} of {n_half_profiles} half-profiles refused (at least "
            f"{min_accepted_fraction:.0%} must have usable rings); first: {rejected[0]}"
        )


def _edge_gap_result(
    profiles: list[HalfProfile],
    rejected: list[str],
    edge_model: str,
    shape_radius_m: float | None,
    wavelength_m: float,
    n_medium: float,
) -> NewtonRingGap:
    """Extrapolate the accepted profiles to their edges and gather the gaps (m) with them."""
    edges, shape_radius = extrapolate_to_edges(profiles, edge_model, shape_radius_m)
    profiles = [replace(p, edge_gap_m=float(g)) for p, g in zip(profiles, edges, strict=True)]
    return NewtonRingGap(
        edge_gap_mean_m=float(edges.mean()),
        edge_gap_sd_m=float(edges.std(ddof=1)),
        edge_gaps_m=edges,
        angles_rad=np.array([p.angle_rad for p in profiles]),
        first_ring_gap_m=float(ring_gap(0, wavelength_m, n_medium)),
        edge_radii_m=np.array([p.edge_radius_m for p in profiles]),
        edge_model=edge_model,
        half_profiles=tuple(profiles),
        rejected=tuple(rejected),
        shape_radius_m=shape_radius,
    )


def newton_ring_gap(
    reflection: np.ndarray,
    pixel_m: float,
    centre_px: tuple[float, float],
    contact_radius_m,
    n_profiles: int = 20,
    wavelength_m: float = APPENDIX_WAVELENGTH_M,
    n_medium: float = FORMAMIDE_REFRACTIVE_INDEX,
    *,
    edge_model: str = FREE_RADIUS,
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

    Each line gives two half-profiles (:func:`half_profile_angles`), so 2·n_profiles edge
    gaps enter the mean and sd. ``contact_radius_m`` is the fluorescent edge: one radius (m)
    for every ray, or one per half-profile in the order of :func:`half_profile_angles` (NaN
    where the ray meets no contact; that profile is refused). Each profile's fit is
    extrapolated to its own edge. A maximum counts as a ring when its prominence exceeds
    both ``prominence_fraction`` of the image's 2–98 % intensity range and
    ``min_prominence_sd`` pixel-noise standard deviations (so pure noise never makes rings).
    ``max_rings`` keeps only the innermost rings for 'hertz_sheet_radius' and 'quadratic';
    'hertz_free_radius' takes every ring: its radius is constrained only by the shape's tail,
    and on the rough virtual glass sphere its gap moved from −1.8 to +4.7 to +0.2 nm with 3,
    4 and all (≤ 6) rings. ``shape_radius_m``: radius of the Hertz
    exterior shape for 'hertz_sheet_radius' (the Hertz radius of the load from the sheet's E*
    and diameter: a rough or flattened sphere's fluorescent edge lies well inside the radius
    whose shape its rings follow, and a shape of the edge's radius biases the extrapolation
    by −8 nm on the rough glass sphere of the virtual experiment); 'hertz_free_radius' fits
    that radius to the rings (:func:`fit_hertz_radius`) and ignores ``shape_radius_m``.
    A half-profile whose ring spacing jumps by more than ``max_spacing_ratio`` is refused
    (a missed ring). Refused half-profiles are left out and listed in ``rejected`` with their
    reason, as long as at least ``min_accepted_fraction`` of them remain (roughness on the
    sphere scatters single rings; the rest still measure the average gap).

    Raises NewtonRingError for a uniform image, a centre outside the image, an unknown edge
    model, a sheet-radius fit without a radius, or when fewer than ``min_accepted_fraction``
    of the half-profiles have enough, correctly ordered rings outside their contact edge
    (the message names the first refused profile's reason).
    """
    image = _checked_image(reflection, edge_model, shape_radius_m)
    row, col = _centre_inside(image, centre_px)
    angles = half_profile_angles(n_profiles)
    edge_radii = _edge_radii(contact_radius_m, angles.size)
    settings = {
        "prominence": _ring_prominence(image, prominence_fraction, min_prominence_sd),
        "max_rings": max_rings,
        "edge_model": edge_model,
        "step_px": step_px,
        "wavelength_m": wavelength_m,
        "n_medium": n_medium,
        "max_spacing_ratio": max_spacing_ratio,
    }
    # Noise is independent per pixel while the rings are tens of pixels wide: smoothing by a
    # pixel removes most of the noise and leaves the ring maxima where they are.
    smoothed = gaussian_filter(image, smooth_px, mode="nearest") if smooth_px > 0 else image
    profiles, rejected, missed = _read_half_profiles(
        smoothed, (row, col), angles, edge_radii, pixel_m, settings
    )
    profiles, rejected = _drop_missed_ring_profiles(profiles, rejected, missed, angles.size)
    _check_enough_accepted(profiles, rejected, angles.size, min_accepted_fraction)
    return _edge_gap_result(profiles, rejected, edge_model, shape_radius_m, wavelength_m, n_medium)
