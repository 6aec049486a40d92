"""Simulated against measured contact, load by load (docs/simulate.md, "Compare").

Registration first: the AFM frame (in which a scene is simulated) and the microscope frame
differ by a shift and, for real data, a rotation and a mirror. They belong to the sphere, not
to the model, so they are found once per sphere, by cross-correlating one scene's rendered
simulation with the measured image at the largest load
(:func:`amontons.simulate.register.register`), and that one registration serves every load
and every scene of the sphere (:func:`scene_registration`).

Per load: the measured and simulated Otsu areas and their ratio; the intersection over union
of the two masks (the simulated one warped onto the measured image's grid); and the per-pixel
agreement, the fraction of the measured image's pixels on which both masks say the same.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from amontons.measure.area import ContactArea
from amontons.simulate.register import Registration, overlay_score, register, warp_to_measured
from amontons.simulate.render import Rendered


@dataclass(frozen=True)
class LoadComparison:
    """One load: areas (m²) measured and simulated (Otsu, each on its own image), IoU and
    per-pixel agreement of the masks on the measured grid."""

    load_n: float
    measured_area_m2: float
    simulated_area_m2: float
    solver_area_m2: float
    iou: float
    pixel_agreement: float
    measured_found: bool

    @property
    def area_ratio(self) -> float:
        return self.simulated_area_m2 / self.measured_area_m2

    def to_record(self) -> dict:
        return {
            "load_mn": self.load_n * 1e3,
            "status": COMPARED,
            "measured_area_um2": self.measured_area_m2 * 1e12,
            "simulated_area_um2": self.simulated_area_m2 * 1e12,
            "area_ratio": self.area_ratio,
            "solver_area_um2": self.solver_area_m2 * 1e12,
            "iou": self.iou,
            "pixel_agreement": self.pixel_agreement,
            "measured_contact_found": self.measured_found,
            "window_um": None,
        }


COMPARED = "compared"
OUTSIDE_SCAN = "outside_scan"


def outside_scan_record(load_mn: float, window_um: float, measured: ContactArea) -> dict:
    """The comparison row of a load the AFM scan did not hold: its measured area, and the
    window (µm) the simulation would have needed; nothing simulated, so no ratio or IoU."""
    return {
        "load_mn": load_mn,
        "status": OUTSIDE_SCAN,
        "measured_area_um2": measured.area_m2 * 1e12,
        "simulated_area_um2": None,
        "area_ratio": None,
        "solver_area_um2": None,
        "iou": None,
        "pixel_agreement": None,
        "measured_contact_found": measured.contact_found,
        "window_um": window_um,
    }


def sheet_load_index(loads_mn: Sequence[float], load_mn: float) -> int:
    """The index of ``load_mn`` among the sheet's loads (mN), to a relative 1e-9: a scene's
    loads went through N and back."""
    for index, load in enumerate(loads_mn):
        if abs(load - load_mn) <= 1e-9 * abs(load):
            return index
    raise ValueError(f"load {load_mn:g} mN is none of the sheet's loads {list(loads_mn)}")


def largest_compared(rows: Sequence[Mapping]) -> Mapping | None:
    """The comparison row of the largest load compared (None where the scan held none)."""
    compared = [row for row in rows if row["status"] == COMPARED]
    return compared[-1] if compared else None


def intersection_over_union(a: np.ndarray, b: np.ndarray) -> float:
    """|a ∩ b| / |a ∪ b| of two boolean masks (0 when both are empty)."""
    union = np.count_nonzero(a | b)
    return float(np.count_nonzero(a & b) / union) if union else 0.0


def warped_mask(rendered: Rendered, registration: Registration, shape) -> np.ndarray:
    """The rendered contact on the measured grid: the image warped (linear interpolation) and
    thresholded at its own Otsu threshold."""
    image = warp_to_measured(rendered.image, registration, shape, order=1)
    return image > rendered.otsu.threshold


def register_at_largest_load(
    rendered: Sequence[Rendered], measured_images: Sequence[np.ndarray]
) -> Registration:
    """The registration of the largest load's rendering on its measured image."""
    measured = np.asarray(measured_images[-1], dtype=float)
    return register(rendered[-1].image, measured)


def scene_registration(
    rendered: Sequence[Rendered],
    measured_images: Sequence[np.ndarray],
    sphere_record: Mapping | None,
) -> tuple[Registration, bool]:
    """The registration a scene is compared under, and whether it was found here.

    ``sphere_record``: the sphere's registration.json, found on another scene of the sphere.
    Its transform is kept, scored on this scene's largest load: a model changes the contact's
    size, not where the sphere lies, and a scene's own search lands within 0.007° and 0.03 px
    of it (docs/simulate.md §5). Where there is none (``None``: this scene finds the sphere's),
    or that scene simulated no load (its window outside the AFM scan), the transform is found
    here, on this scene's largest load.
    """
    if sphere_record is None or sphere_record.get("status") == OUTSIDE_SCAN:
        return register_at_largest_load(rendered, measured_images), True
    found = Registration.from_record(sphere_record)
    score = overlay_score(rendered[-1].image, measured_images[-1], found)
    return replace(found, score=score), False


def compare_loads(
    loads_n: Sequence[float],
    rendered: Sequence[Rendered],
    measured: Sequence[ContactArea],
    solver_areas_m2: Sequence[float],
    registration: Registration,
    pixel_m: float,
) -> list[LoadComparison]:
    """Per load, the measured and simulated contact compared under one registration."""
    out = []
    for load, sim, meas, solver_area in zip(
        loads_n, rendered, measured, solver_areas_m2, strict=True
    ):
        mask = warped_mask(sim, registration, meas.mask.shape)
        out.append(
            LoadComparison(
                load_n=load,
                measured_area_m2=meas.area_m2,
                simulated_area_m2=sim.otsu.area_m2,
                solver_area_m2=solver_area,
                iou=intersection_over_union(mask, meas.mask),
                pixel_agreement=float(np.mean(mask == meas.mask)),
                measured_found=meas.contact_found,
            )
        )
    return out


def afm_scan_centre_in_image_m(
    registration: Registration, window_centre_in_scan_m: tuple[float, float], pixel_m: float
) -> tuple[float, float]:
    """Where the AFM scan's centre lies in the measured image (m about the image centre,
    (row, col)): the registration maps the simulation window's centre, which sits at
    ``window_centre_in_scan_m`` from the scan centre in the AFM frame."""
    row, col = registration.map_offset_px(-np.asarray(window_centre_in_scan_m) / pixel_m)
    return float(row * pixel_m), float(col * pixel_m)
