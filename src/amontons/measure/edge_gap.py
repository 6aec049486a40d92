"""Gap at the fluorescent contact edge from Newton rings of the reflection image
(appendix Figs. B.6, B.7; docs/models.md §1.5): the contact, its centre and the edge of each
line profile come from the fluorescence image at the same load
(amontons.measure.contact_edge), the ring analysis from amontons.measure.newton_rings.

The result is a number only when it is resolved by its own uncertainty
(:func:`undetermined_reason`); otherwise it is a flagged null that keeps the figures that led
to it.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import stats
from scipy.ndimage import binary_fill_holes

from amontons.io.confocal import NO_CHOICE, ImageChoice
from amontons.io.layout import RawDataError
from amontons.io.rawdata import read_fluorescence, read_reflection
from amontons.measure.area import OtsuSettings, contact_geometry, separated_contact
from amontons.measure.contact_edge import close_mask, ray_edge_radii
from amontons.measure.errors import RingsUnreadable
from amontons.measure.newton_rings import (
    SHEET_RADIUS,
    NewtonRingError,
    NewtonRingGap,
    extrapolate_to_edges,
    half_profile_angles,
    newton_ring_gap,
)

CONFIDENCE = 0.95
# E* steps of the sheet-radius sensitivity: ±10 %; the Hertz radius scales as E*^(-1/3).
E_STAR_STEP = 0.10


@dataclass(frozen=True)
class GapInterval:
    """Mean of the half-profiles' edge gaps with its standard error and 95 % interval (m).

    ``n_effective``: the number of independent profiles the standard error counts;
    neighbouring half-profiles cross the same roughness, so it is n·(1 − ρ)/(1 + ρ) with ρ
    the lag-1 correlation of the gaps around the circle (n when ρ ≤ 0).
    """

    mean_m: float
    sd_m: float
    se_m: float
    low_m: float
    high_m: float
    n: int
    n_effective: float

    @property
    def half_width_m(self) -> float:
        return (self.high_m - self.low_m) / 2


def neighbour_correlation(gaps_by_angle: np.ndarray) -> float:
    """Lag-1 correlation of values ordered around a circle (the last one neighbours the
    first); 0 for fewer than 3 values or values without spread."""
    x = np.asarray(gaps_by_angle, dtype=float)
    if x.size < 3 or np.ptp(x) == 0:
        return 0.0
    d = x - x.mean()
    return float(np.sum(d * np.roll(d, 1)) / np.sum(d * d))


def gap_interval(gaps_m: np.ndarray, angles_rad: np.ndarray) -> GapInterval:
    """Mean, sd, standard error and the 95 % Student-t interval of the edge gaps (m), with
    the standard error counting n_effective = n·(1 − ρ)/(1 + ρ) independent profiles (ρ: the
    lag-1 correlation around the circle, :func:`neighbour_correlation`; at least 2)."""
    gaps = np.asarray(gaps_m, dtype=float)
    order = np.argsort(np.mod(angles_rad, 2 * np.pi))
    rho = neighbour_correlation(gaps[order])
    n = gaps.size
    n_eff = float(np.clip(n * (1 - rho) / (1 + rho), 2, n)) if rho > 0 else float(n)
    mean, sd = float(gaps.mean()), float(gaps.std(ddof=1))
    se = sd / np.sqrt(n_eff)
    half = float(stats.t.ppf(0.5 + CONFIDENCE / 2, n_eff - 1) * se)
    return GapInterval(mean, sd, se, mean - half, mean + half, n, n_eff)


def undetermined_reason(
    interval: GapInterval, margin_m: float, spread_margin_m: float = 10e-9
) -> str | None:
    """Why the mean edge gap is not a measurement, or None when it is.

    The rule (docs/models.md §1.5), with m = ``margin_m`` and s = ``spread_margin_m``: the gap
    is undetermined when
    - the profiles disagree by more than the gap: their sd > max(|mean|, s). A mean of
      profiles that scatter more than it (a patchy contact: edges from 1 to 14 µm, rings
      misnumbered by a patch, single gaps from −20 to +150 nm) is no single gap at the edge;
    - its 95 % interval (:func:`gap_interval`) is wider than the gap: half-width >
      max(|mean|, m); or
    - that interval reaches below −m. A gap cannot be negative; an interval that reaches
      there says the extrapolated curve does not describe the profiles.
    The margins keep a well-resolved gap near 0 a number: the virtual glass sphere's profiles
    scatter by an sd of 3-4 nm (its 3 nm roughness under the rings) around a mean within 2 nm
    of its truth. The spread margin s (10 nm, an eighth of the first ring's gap λ/4n = 84 nm)
    separates profiles that cross one edge at the ring fit's precision from profiles that do
    not measure one gap (the patchy sphere: sd 48 nm).
    """
    nm = 1e9
    mean, half, sd = interval.mean_m, interval.half_width_m, interval.sd_m
    figures = (
        f"{mean * nm:.1f} nm, 95 % interval {interval.low_m * nm:.1f} to "
        f"{interval.high_m * nm:.1f} nm, profiles' sd {sd * nm:.1f} nm over {interval.n} "
        "half-profiles"
    )
    if sd > max(abs(mean), spread_margin_m):
        return f"undetermined: single profiles scatter more than the mean gap ({figures})"
    if half > max(abs(mean), margin_m):
        return f"undetermined: the 95 % interval is wider than the gap itself ({figures})"
    if interval.low_m < -margin_m:
        return (
            f"undetermined: the 95 % interval reaches below −{margin_m * nm:g} nm, and a gap "
            f"cannot be negative: the extrapolated curve does not describe these profiles "
            f"({figures})"
        )
    return None


def _gap_record(interval: GapInterval) -> dict:
    nm = 1e9
    return {
        "mean": interval.mean_m * nm,
        "sd": interval.sd_m * nm,
        "se": float(interval.se_m * nm),
        "ci95_low": interval.low_m * nm,
        "ci95_high": interval.high_m * nm,
        "n": interval.n,
        "n_effective": interval.n_effective,
    }


@dataclass(frozen=True)
class EdgeGap:
    """Newton-ring gap at the fluorescent contact edge, with where the edges were found."""

    rings: NewtonRingGap
    interval: GapInterval
    undetermined: str | None  # the reason the mean is not a measurement, or None
    centre_px: tuple[float, float]  # (row, col), from the fluorescence Otsu mask
    equal_area_radius_m: float  # radius of the disc with the filled mask's area
    mask_closing_m: float
    margin_m: float
    spread_margin_m: float
    fluorescence_path: Path
    reflection_path: Path
    load_mn: float
    sheet_radius_m: float | None = None  # Hertz radius of the load from the sheet's E*
    sheet_gap_m: float | None = None  # mean gap of the sheet-radius model
    gap_per_10pct_e_star_m: float | None = None  # its change per +10 % of E*
    pixel_source: str = "file"  # where the images' pixel size came from: 'file' or 'sheet'

    @property
    def edge_gap_m(self) -> float | None:
        """The measured mean edge gap (m), None when undetermined."""
        return None if self.undetermined else self.interval.mean_m

    def to_record(self) -> dict:
        """JSON-ready record, units in the key names: the mean edge gap (null when
        undetermined, with the reason in ``flag`` and the would-be figures in
        ``undetermined_edge_gap_nm``), per-profile edges and gaps, the refused half-profiles,
        the Hertz radii and the gap's sensitivity to the sheet's E*."""
        rings = self.rings
        refused = (
            f"{len(rings.rejected)} of {len(rings.rejected) + rings.edge_gaps_m.size} "
            "half-profiles refused; see rejected_half_profiles"
            if rings.rejected
            else None
        )
        nm, um = 1e9, 1e6
        return {
            "quantity": "gap at the fluorescent contact edge from Newton rings, "
            f"d = (m + 1/2) λ/2n, '{rings.edge_model}' curve of each half-profile "
            "extrapolated to that profile's own Otsu edge",
            "edge_gap_nm": None if self.undetermined else _gap_record(self.interval),
            "undetermined_edge_gap_nm": _gap_record(self.interval) if self.undetermined else None,
            "flag": "; ".join(f for f in (self.undetermined, refused) if f) or None,
            "undetermined_rule": "null when the profiles' sd exceeds both |mean| and "
            f"{self.spread_margin_m * nm:g} nm, the 95 % interval's half-width exceeds both "
            f"|mean| and {self.margin_m * nm:g} nm, or the interval's lower end lies below "
            f"-{self.margin_m * nm:g} nm",
            "edge_model": rings.edge_model,
            "edge_gaps_nm": (rings.edge_gaps_m * nm).tolist(),
            "edge_radii_um": (rings.edge_radii_m * um).tolist(),
            "profile_angles_deg": [float(a) for a in np.degrees(rings.angles_rad)],
            "first_ring_gap_nm": rings.first_ring_gap_m * nm,
            "rings_per_half_profile": [int(p.ring_r_m.size) for p in rings.half_profiles],
            # profiles without usable rings (roughness scatters them) are left out, not hidden
            "rejected_half_profiles": list(rings.rejected),
            "equal_area_radius_um": self.equal_area_radius_m * um,
            "edge_radius_over_equal_area": float(
                np.median(rings.edge_radii_m) / self.equal_area_radius_m
            ),
            "mask_closing_um": self.mask_closing_m * um,
            "hertz_radius_um": {
                "sheet": None if self.sheet_radius_m is None else self.sheet_radius_m * um,
                "fitted": None
                if rings.edge_model == SHEET_RADIUS or rings.shape_radius_m is None
                else rings.shape_radius_m * um,
            },
            "sheet_radius_edge_gap_nm": None if self.sheet_gap_m is None else self.sheet_gap_m * nm,
            "edge_gap_change_nm_per_10pct_e_star": None
            if self.gap_per_10pct_e_star_m is None
            else self.gap_per_10pct_e_star_m * nm,
            "contact_centre_px": list(self.centre_px),
            "load_mn": self.load_mn,
            "reflection": str(self.reflection_path),
            "fluorescence": str(self.fluorescence_path),
            "pixel_source": self.pixel_source,
        }


def unmeasured_edge_gap_record(reason: str, load_mn: float) -> dict:
    """The record of an edge gap that cannot be measured: a flagged null with the reason."""
    return {"edge_gap_nm": None, "flag": reason, "load_mn": load_mn}


def sheet_radius_sensitivity(rings: NewtonRingGap, sheet_radius_m: float) -> tuple[float, float]:
    """Mean edge gap (m) of the sheet-radius model on the same rings and edges, and its
    change (m) per +10 % of E*: half the difference between the Hertz radii of E*·1.1 and
    E*·0.9 (a ∝ E*^(-1/3))."""
    profiles = rings.half_profiles

    def mean_gap(radius_m: float) -> float:
        return float(extrapolate_to_edges(profiles, SHEET_RADIUS, radius_m)[0].mean())

    stiffer = sheet_radius_m * (1 + E_STAR_STEP) ** (-1 / 3)
    softer = sheet_radius_m * (1 - E_STAR_STEP) ** (-1 / 3)
    return mean_gap(sheet_radius_m), (mean_gap(stiffer) - mean_gap(softer)) / 2


def profile_edges(
    mask: np.ndarray, centre_px: tuple[float, float], n_profiles: int, closing_px: int
) -> np.ndarray:
    """Edge radius (px) of each half-profile (order of
    amontons.measure.newton_rings.half_profile_angles): the outermost contact pixel on the
    ray after closing the mask by ``closing_px``; NaN where the ray meets no contact."""
    return ray_edge_radii(close_mask(mask, closing_px), centre_px, half_profile_angles(n_profiles))


def measure_edge_gap(
    reflection_path: str | Path,
    fluorescence_path: str | Path,
    fallback_pixel_m: float | None,
    *,
    load_mn: float,
    otsu: OtsuSettings,
    n_profiles: int,
    edge_model: str,
    wavelength_m: float,
    n_medium: float,
    max_rings: int | None = None,
    hertz_radius_m: float | None = None,
    mask_closing_m: float = 0.25e-6,
    margin_m: float = 4e-9,
    spread_margin_m: float = 10e-9,
    choice: ImageChoice = NO_CHOICE,
    reflection_choice: ImageChoice = NO_CHOICE,
) -> EdgeGap:
    """Gap at the contact edge from the reflection image (appendix Figs. B.6, B.7).

    The contact centre is the centroid of the Otsu mask of ``fluorescence_path`` (the image
    at the reflection load, on the reflection's pixel grid). The edge of each half-profile is
    where that profile leaves the contact: the outermost contact pixel on its ray, after
    closing the mask with a disc of ``mask_closing_m`` (m; rounded to whole pixels) so that
    patches closer than the PSF count as one (:func:`profile_edges`). Each profile's ring fit
    is extrapolated to its own edge. ``edge_model`` and ``hertz_radius_m`` (the Hertz radius
    of the load from the sheet's E* and diameter; needed by 'hertz_sheet_radius', and for
    the E* sensitivity that every model reports) as in
    amontons.measure.newton_rings.newton_ring_gap; bright rings sit at the gaps
    (m + ½)·``wavelength_m``/2``n_medium``. ``load_mn`` is the load of both images.
    ``margin_m`` and ``spread_margin_m``: the margins of :func:`undetermined_reason`.
    ``choice`` and ``reflection_choice``: the planes of confocal files (amontons.io.confocal;
    both images may be channels of one file).

    Raises NoContact if the fluorescence image shows no contact, RingsUnreadable if the
    rings cannot be numbered; an unresolved mean comes back with ``undetermined`` set.
    """
    if mask_closing_m < 0 or margin_m < 0 or spread_margin_m < 0:
        raise ValueError(
            f"mask closing {mask_closing_m} m, margins {margin_m} and {spread_margin_m} m; "
            "expected all ≥ 0"
        )
    fluorescence = read_fluorescence(fluorescence_path, fallback_pixel_m, choice)
    area = separated_contact(fluorescence, otsu)
    try:
        centre, _ = contact_geometry(area.mask, fluorescence.pixel_m)
    except ValueError as error:
        raise RawDataError(f"{fluorescence.path}: {error}") from error
    pixel = fluorescence.pixel_m
    equal_area = float(np.sqrt(binary_fill_holes(area.mask).sum() / np.pi) * pixel)
    closing_px = int(round(mask_closing_m / pixel))
    edges_m = profile_edges(area.mask, centre, n_profiles, closing_px) * pixel
    reflection = read_reflection(
        reflection_path, fallback_pixel_m, like=fluorescence, choice=reflection_choice
    )
    try:
        rings = newton_ring_gap(
            reflection.data,
            reflection.pixel_m,
            centre,
            edges_m,
            n_profiles,
            wavelength_m,
            n_medium,
            edge_model=edge_model,
            max_rings=max_rings,
            shape_radius_m=hertz_radius_m,
        )
    except NewtonRingError as error:
        raise RingsUnreadable(f"{reflection.path}: {error}") from error
    interval = gap_interval(rings.edge_gaps_m, rings.angles_rad)
    sheet_gap = per_10pct = None
    if hertz_radius_m is not None:
        sheet_gap, per_10pct = sheet_radius_sensitivity(rings, hertz_radius_m)
    return EdgeGap(
        rings=rings,
        interval=interval,
        undetermined=undetermined_reason(interval, margin_m, spread_margin_m),
        centre_px=centre,
        equal_area_radius_m=equal_area,
        mask_closing_m=closing_px * pixel,
        margin_m=margin_m,
        spread_margin_m=spread_margin_m,
        fluorescence_path=fluorescence.path,
        reflection_path=reflection.path,
        load_mn=load_mn,
        sheet_radius_m=hertz_radius_m,
        sheet_gap_m=sheet_gap,
        gap_per_10pct_e_star_m=per_10pct,
        pixel_source=fluorescence.pixel_source,
    )
