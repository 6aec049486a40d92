"""The virtual experiment's contact: a rough sphere with contact hardening, solved per load.

Forward model (docs/models.md §3): the sphere is a paraboloid of radius R
plus self-affine roughness (:mod:`amontons.virtual.roughness`) on the solver grid; it is
pressed onto the glass (elastic half-space of contact modulus E*) with the contact-hardening
law p = k·|h_pl| (appendix B.2.3), the loads stepping upward and each step carrying the
plastic displacement of the previous one (:func:`amontons.contact.solve_load_series`).

The solver grid is a setting (``solver_pixel_nm``, capped at ``solver_max_grid_px`` per
side), separate from the AFM pixel and from the image pixel. Its window holds the largest
contact and the Newton rings of the reflection load with a margin; a solve whose contact
reaches the window edge, or whose rings fall outside it, is repeated on a larger window.

:func:`image_contact_states` maps the solution onto an instrument's pixel grid (the
ContactState every instrument of :mod:`amontons.virtual.experiment` reads).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import scipy.fft
from scipy import ndimage

from amontons.contact import ContactResult, FreeBoundaryError, solve_load_series
from amontons.contact.surfaces import sphere as sphere_cap
from amontons.physics import hertz
from amontons.physics.emission import confined_emission
from amontons.physics.newton_rings import ring_gap
from amontons.simulate.grid import PixelAverager, resample
from amontons.virtual.roughness import Roughness, synthesize
from amontons.virtual.state import ContactState, load_index

log = logging.getLogger(__name__)

# Hardening enlarges the contact over Hertz (PMMA, 512² benchmark: area ×1.45 at 10 mN, so
# radius ×1.2); the first window assumes ×1.3 and grows by WINDOW_GROWTH when too small.
HARDENING_RADIUS_GUESS = 1.3
WINDOW_GROWTH = 1.5
MAX_WINDOW_ATTEMPTS = 4


@dataclass(frozen=True)
class SolverSettings:
    """Grid of the forward contact solve: pixel (m), largest side (px), window margin (×)."""

    pixel_m: float
    max_grid_px: int
    window_factor: float
    tol: float = 1e-8


@dataclass(frozen=True)
class RoughSphereSolution:
    """The rough sphere's load series on the solver grid (apex at the window centre).

    ``heights``: indenter heights (m, larger = closer to the glass); ``roughness``: the
    roughness part of them (m); ``results``: one ContactResult per load (SI units);
    ``ring_reach_m``: the radius (m) within which the reflection load's image holds its
    Newton rings.
    """

    heights: np.ndarray
    roughness: np.ndarray
    spacing_m: float
    results: list[ContactResult]
    ring_reach_m: float

    @property
    def centre_px(self) -> tuple[float, float]:
        n0, n1 = self.heights.shape
        return ((n0 - 1) / 2, (n1 - 1) / 2)

    @property
    def window_m(self) -> float:
        return self.heights.shape[0] * self.spacing_m


def ring_reach_gap(rings: int, wavelength_m: float, n_medium: float) -> float:
    """Gap (m) half-way between the last bright ring an image must hold and the next one
    (light of ``wavelength_m`` in a medium of refractive index ``n_medium``)."""
    gaps = ring_gap(np.arange(rings + 1), wavelength_m, n_medium)
    return float(0.5 * (gaps[-2] + gaps[-1]))


def hertz_reach_radius(gap_m: float, load_n: float, radius_m: float, e_star_pa: float) -> float:
    """Distance (m) at which a Hertz sphere's gap reaches ``gap_m``: the far field is
    r²/2R − d + u with u ≤ the Hertz displacement, so r² ≤ 2R(g + d) bounds it from above."""
    d = hertz.contact_radius(load_n, radius_m, e_star_pa) ** 2 / radius_m
    return float(np.sqrt(2 * radius_m * (gap_m + d)))


def initial_window_m(
    loads_n, radius_m, e_star_pa, reflection_load_n, reach_gap_m, settings: SolverSettings
) -> float:
    """First solver window (m): the larger of the hardened contact diameter and the reach
    of the Newton rings (the radius where the gap is ``reach_gap_m``) at the reflection
    load, times ``window_factor``."""
    a_max = hertz.contact_radius(max(loads_n), radius_m, e_star_pa) * HARDENING_RADIUS_GUESS
    reach = hertz_reach_radius(reach_gap_m, reflection_load_n, radius_m, e_star_pa)
    return settings.window_factor * 2 * max(a_max, reach)


def solver_grid(window_m: float, settings: SolverSettings) -> tuple[int, float]:
    """Side (px, even) and pixel (m) of the solver grid: ``settings.pixel_m`` unless the
    window would then exceed ``max_grid_px``, in which case the pixel grows."""
    n = fast_even(int(np.ceil(window_m / settings.pixel_m)))
    if n <= settings.max_grid_px:
        return n, settings.pixel_m
    n = settings.max_grid_px - settings.max_grid_px % 2
    return n, window_m / n


def fast_even(n: int) -> int:
    """Smallest even n' >= n whose FFT is fast (a product of 2, 3, 5, 7): a 962² window pads
    to 1924 = 4·13·37, whose transforms are ~4x slower than those of 1000 (measured)."""
    m = scipy.fft.next_fast_len(n, real=True)
    while m % 2:
        m = scipy.fft.next_fast_len(m + 1, real=True)
    return m


def rough_sphere_heights(n: int, spacing_m: float, radius_m: float, roughness: Roughness, rng):
    """(heights, roughness) on an n² grid, m: the paraboloid plus the solver-band roughness."""
    rough = synthesize((n, n), spacing_m, roughness, rng)
    return sphere_cap((n, n), spacing_m, radius_m) + rough, rough


def azimuthal_mean(field: np.ndarray, spacing_m: float, radii_m: np.ndarray) -> np.ndarray:
    """Mean of ``field`` over circles of the given radii (m) about the window centre, sampled
    at 720 angles with bilinear interpolation."""
    n0, n1 = field.shape
    theta = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    r = np.asarray(radii_m, dtype=float)[:, None] / spacing_m
    rows = (n0 - 1) / 2 + r * np.sin(theta)
    cols = (n1 - 1) / 2 + r * np.cos(theta)
    values = ndimage.map_coordinates(field, [rows.ravel(), cols.ravel()], order=1)
    return values.reshape(rows.shape).mean(axis=1)


def reach_radius_m(result: ContactResult, gap_m: float) -> float:
    """Smallest radius (m) at which the azimuthally averaged gap exceeds ``gap_m``; inf when
    it does not within the window."""
    spacing = result.spacing
    radii = np.arange(0, result.gap.shape[0] // 2 - 1) * spacing
    mean_gap = azimuthal_mean(result.gap, spacing, radii)
    beyond = np.nonzero(mean_gap > gap_m)[0]
    return float(radii[beyond[0]]) if beyond.size else float("inf")


def contact_radius_m(contact: np.ndarray, spacing_m: float) -> float:
    """Largest distance (m) of a contact pixel's centre from the window centre."""
    n0, n1 = contact.shape
    rows, cols = np.nonzero(contact)
    if rows.size == 0:
        return 0.0
    return float(np.hypot(rows - (n0 - 1) / 2, cols - (n1 - 1) / 2).max() * spacing_m)


def simulate_rough_sphere(
    *,
    radius_m: float,
    e_star_pa: float,
    law,
    loads_n: list[float],
    reflection_load_n: float,
    ring_reach_gap_m: float,
    roughness: Roughness,
    settings: SolverSettings,
    rng_seed,
    threads: int = 1,
    min_window_m: float = 0.0,
) -> RoughSphereSolution:
    """Solve the load series of a rough sphere under the plasticity ``law`` (SI; None:
    elastic) on a window that holds the largest contact and the reflection load's Newton
    rings, out to the radius where the gap is ``ring_reach_gap_m`` (:func:`ring_reach_gap`),
    grown and re-solved if not; the window is at least ``min_window_m`` wide (the footprint
    of the AFM scans that sample it)."""
    window = max(
        min_window_m,
        initial_window_m(
            loads_n, radius_m, e_star_pa, reflection_load_n, ring_reach_gap_m, settings
        ),
    )
    reach_gap = ring_reach_gap_m
    for attempt in range(1, MAX_WINDOW_ATTEMPTS + 1):
        n, dx = solver_grid(window, settings)
        heights, rough = rough_sphere_heights(
            n, dx, radius_m, roughness, np.random.default_rng(rng_seed)
        )
        log.info(
            "solver grid %d² at %.1f nm (window %.1f µm, attempt %d)",
            n,
            dx * 1e9,
            n * dx * 1e6,
            attempt,
        )
        try:
            results = solve_load_series(
                heights, dx, e_star_pa, loads_n, plasticity=law, tol=settings.tol, threads=threads
            )
        except FreeBoundaryError as error:
            log.info("window too small (%s); growing it", error)
            window *= WINDOW_GROWTH
            continue
        reach = reach_radius_m(results[load_index(loads_n, reflection_load_n)], reach_gap)
        largest = contact_radius_m(results[-1].contact, dx)
        needed = max(min_window_m, settings.window_factor * 2 * max(reach, largest))
        if needed <= n * dx:
            return RoughSphereSolution(heights, rough, dx, results, reach)
        log.info("rings or contact reach %.1f µm beyond the window; growing it", needed * 1e6)
        window = max(needed, window * WINDOW_GROWTH)
    raise RuntimeError(
        f"no solver window held the contact and the Newton rings after {MAX_WINDOW_ATTEMPTS} "
        f"attempts (last {window * 1e6:.0f} µm); raise solver_max_grid_px or lower the loads"
    )


def closed_envelope(contact: np.ndarray, spacing_m: float, closing_m: float) -> np.ndarray:
    """The contact mask closed with a disc of radius ``closing_m`` (the gaps between patches
    that the microscope cannot resolve), padded so the window edge does not erode it."""
    r = max(1, int(round(closing_m / spacing_m)))
    yy, xx = np.mgrid[-r : r + 1, -r : r + 1]
    disc = xx**2 + yy**2 <= r * r
    closed = ndimage.binary_closing(np.pad(contact, r + 1), structure=disc)
    return closed[r + 1 : -(r + 1), r + 1 : -(r + 1)]


def edge_radius_m(contact: np.ndarray, spacing_m: float, closing_m: float) -> float:
    """Radius (m) of the disc with the area of the contact's envelope: the contact mask closed
    with a disc of radius ``closing_m`` (the gaps between patches that the microscope cannot
    resolve) and its holes filled - the edge a thresholded fluorescence image shows."""
    envelope = ndimage.binary_fill_holes(closed_envelope(contact, spacing_m, closing_m))
    return float(np.sqrt(envelope.sum() * spacing_m**2 / np.pi))


# Rays of the per-profile edge truth: every degree, so that any n_profiles dividing 180 of the
# measurement's rays (kπ/n and kπ/n + π) is among them.
TRUTH_RAY_ANGLES = np.radians(np.arange(360.0))


def ray_edges_m(contact: np.ndarray, spacing_m: float, angles_rad: np.ndarray) -> np.ndarray:
    """Distance (m) from the window centre at which each ray leaves the outermost contact
    pixel on it (sampled every 0.1 px, half a step past the last sample in contact); NaN for a
    ray without contact."""
    n0, n1 = contact.shape
    r = np.arange(0.0, np.hypot(n0, n1) / 2, 0.1)
    radii = np.full(len(angles_rad), np.nan)
    for k, angle in enumerate(angles_rad):
        rows = np.floor((n0 - 1) / 2 + r * np.sin(angle) + 0.5).astype(int)
        cols = np.floor((n1 - 1) / 2 + r * np.cos(angle) + 0.5).astype(int)
        inside = (rows >= 0) & (rows < n0) & (cols >= 0) & (cols < n1)
        hits = np.nonzero(contact[rows[inside], cols[inside]])[0]
        if hits.size:
            radii[k] = (r[hits[-1]] + 0.05) * spacing_m
    return radii


def edge_profile_truth(result: ContactResult, closing_m: float) -> dict:
    """The true edge of each ray (every degree from the apex) and the gap there, JSON-ready
    (µm, nm): the per-profile edge the measurement finds (docs/models.md §1.5), on the true
    contact closed by ``closing_m``. ``ring_gap_nm``: the azimuthal mean gap at each ray's
    edge radius, the average local gap the Newton rings see at that distance;
    ``local_gap_nm``: the gap at the edge point itself (≈ 0: the last contact pixel, what the
    molecules see)."""
    dx = result.spacing
    closed = closed_envelope(result.contact, dx, closing_m)
    radii = ray_edges_m(closed, dx, TRUTH_RAY_ANGLES)
    found = np.isfinite(radii)
    ring_gap_m = np.full(radii.shape, np.nan)
    ring_gap_m[found] = azimuthal_mean(result.gap, dx, radii[found])
    n0, n1 = result.gap.shape
    rows = (n0 - 1) / 2 + np.nan_to_num(radii) / dx * np.sin(TRUTH_RAY_ANGLES)
    cols = (n1 - 1) / 2 + np.nan_to_num(radii) / dx * np.cos(TRUTH_RAY_ANGLES)
    local = ndimage.map_coordinates(result.gap, [rows, cols], order=1)
    local = np.where(found, np.maximum(local, 0.0), np.nan)

    def listed(values, scale):
        return [None if not np.isfinite(v) else float(v * scale) for v in values]

    return {
        "angles_deg": np.degrees(TRUTH_RAY_ANGLES).tolist(),
        "edge_radius_um": listed(radii, 1e6),
        "ring_gap_nm": listed(ring_gap_m, 1e9),
        "local_gap_nm": listed(local, 1e9),
        "mean_ring_gap_nm": float(np.nanmean(ring_gap_m) * 1e9),
        "mean_edge_radius_um": float(np.nanmean(radii) * 1e6),
        "max_edge_radius_um": float(np.nanmax(radii) * 1e6),
        "definition": "per ray from the apex (every degree): the outermost pixel of the true "
        f"contact closed by {closing_m * 1e9:.0f} nm, the azimuthal mean gap at that radius "
        "(ring_gap_nm, what the Newton rings average) and the gap at the point (local_gap_nm)",
    }


def image_contact_states(
    solution: RoughSphereSolution,
    shape: tuple[int, int],
    pixel_m: float,
    *,
    gap_index: int | None,
    closing_m: float,
    confinement_floor_pa: float,
) -> list[ContactState]:
    """Every load of the solution on an image grid (image centre = sphere apex).

    Pressure and the probe's emission √max(p, ``confinement_floor_pa``) in contact: averaged
    over each image pixel (:class:`PixelAverager`: 4×4 sub-samples, nearest solver pixel, so
    patch edges keep their covered fraction); contact:
    pixels more than half covered by contact; area: the solver's true contact area. Gap, at
    load ``gap_index`` only (the reflection image is the one instrument that needs it):
    bilinear at pixel centres. The edge gap is the azimuthal mean gap at
    :func:`edge_radius_m` - the average local gap the Newton rings measure, at the edge a
    thresholded fluorescence image shows.
    """
    dx = solution.spacing_m
    average = PixelAverager(solution.heights.shape, dx, shape, pixel_m)
    centre = ((shape[0] - 1) / 2, (shape[1] - 1) / 2)
    states = []
    for index, result in enumerate(solution.results):
        gap = edge_gap = profiles = None
        if index == gap_index:
            rows_m = (np.arange(shape[0]) - centre[0]) * pixel_m
            cols_m = (np.arange(shape[1]) - centre[1]) * pixel_m
            gap = np.maximum(resample(result.gap, dx, rows_m, cols_m, 1, "constant"), 0.0)
            r_edge = edge_radius_m(result.contact, dx, closing_m)
            edge_gap = float(azimuthal_mean(result.gap, dx, np.array([r_edge]))[0])
            profiles = edge_profile_truth(result, closing_m)
        states.append(
            ContactState(
                load_n=float(result.load),
                pressure_pa=average(result.pressure),
                emission_sqrt_pa=average(
                    confined_emission(result.pressure, result.contact, confinement_floor_pa)
                ),
                gap_m=gap,
                contact=average(result.contact) > 0.5,
                area_m2=result.area,
                edge_gap_m=edge_gap,
                centre_px=centre,
                edge_profiles=profiles,
            )
        )
    return states
