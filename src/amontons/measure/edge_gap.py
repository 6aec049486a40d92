"""Gap at the fluorescent contact edge from the Newton rings of the reflection image
(appendix Figs. B.6, B.7; docs/models.md §1.5): the contact and its edge come from the
fluorescence image at the same load, the ring analysis from amontons.measure.newton_rings."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.ndimage import binary_fill_holes

from amontons.io.layout import RawDataError
from amontons.io.rawdata import read_fluorescence, read_reflection
from amontons.measure.area import OtsuSettings, contact_geometry, separated_contact
from amontons.measure.errors import RingsUnreadable
from amontons.measure.newton_rings import NewtonRingError, NewtonRingGap, newton_ring_gap


@dataclass(frozen=True)
class EdgeGap:
    """Newton-ring gap at the fluorescent contact edge, with where the edge was found."""

    rings: NewtonRingGap
    centre_px: tuple[float, float]  # (row, col), from the fluorescence Otsu mask
    contact_radius_m: float
    fluorescence_path: Path
    reflection_path: Path
    load_mn: float

    def to_record(self) -> dict:
        """JSON-ready record, units in the key names: per-profile gaps, their mean and sd,
        the refused half-profiles and where the edge was found."""
        rings = self.rings
        return {
            "quantity": "gap at the fluorescent contact edge from Newton rings, "
            f"d = (m + 1/2) λ/2n, '{rings.edge_model}' curve extrapolated to the Otsu edge",
            "edge_gap_nm": {
                "mean": rings.edge_gap_mean_m * 1e9,
                "sd": rings.edge_gap_sd_m * 1e9,
                "n": int(rings.edge_gaps_m.size),
            },
            "edge_gaps_nm": (rings.edge_gaps_m * 1e9).tolist(),
            "profile_angles_deg": [float(a) for a in rings.angles_rad * 180 / np.pi],
            "first_ring_gap_nm": rings.first_ring_gap_m * 1e9,
            "rings_per_half_profile": [int(p.ring_r_m.size) for p in rings.half_profiles],
            # profiles without usable rings (roughness scatters them) are left out, not hidden
            "rejected_half_profiles": list(rings.rejected),
            "flag": (
                f"{len(rings.rejected)} of {len(rings.rejected) + rings.edge_gaps_m.size} "
                "half-profiles refused; see rejected_half_profiles"
                if rings.rejected
                else None
            ),
            "contact_radius_um": self.contact_radius_m * 1e6,
            "contact_centre_px": list(self.centre_px),
            "load_mn": self.load_mn,
            "reflection": str(self.reflection_path),
            "fluorescence": str(self.fluorescence_path),
        }


def unmeasured_edge_gap_record(reason: str, load_mn: float) -> dict:
    """The record of an edge gap that cannot be measured: a flagged null with the reason."""
    return {"edge_gap_nm": None, "flag": reason, "load_mn": load_mn}


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
) -> EdgeGap:
    """Gap at the contact edge from the reflection image (appendix Figs. B.6, B.7).

    The contact centre comes from the Otsu mask of ``fluorescence_path`` (the image at the
    reflection load, on the reflection's pixel grid); the edge is where that image shows it:
    the radius of the circle with the area of the mask with its holes filled (the outer
    boundary of a patchy contact). ``hertz_radius_m``, the Hertz radius of the load from
    the sheet's E* and diameter, is the radius of the exterior shape the rings are fitted
    with (amontons.measure.newton_rings.newton_ring_gap); bright rings sit at the gaps
    (m + ½)·``wavelength_m``/2``n_medium``. ``load_mn`` is the load of both images.
    Raises NoContact if the fluorescence image shows no contact, RingsUnreadable if the
    rings cannot be numbered.
    """
    fluorescence = read_fluorescence(fluorescence_path, fallback_pixel_m)
    area = separated_contact(fluorescence, otsu)
    try:
        centre, _ = contact_geometry(area.mask, fluorescence.pixel_m)
    except ValueError as error:
        raise RawDataError(f"{fluorescence.path}: {error}") from error
    radius = float(np.sqrt(binary_fill_holes(area.mask).sum() / np.pi) * fluorescence.pixel_m)
    reflection = read_reflection(reflection_path, fallback_pixel_m, like=fluorescence)
    try:
        rings = newton_ring_gap(
            reflection.data,
            reflection.pixel_m,
            centre,
            radius,
            n_profiles,
            wavelength_m,
            n_medium,
            edge_model=edge_model,
            max_rings=max_rings,
            shape_radius_m=hertz_radius_m,
        )
    except NewtonRingError as error:
        raise RingsUnreadable(f"{reflection.path}: {error}") from error
    return EdgeGap(rings, centre, radius, fluorescence.path, reflection.path, load_mn)
