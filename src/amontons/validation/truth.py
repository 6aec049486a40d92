"""A validation case's truth (docs/study.md §7): the rough sphere solved under its true model
``ratio`` times finer in pixel than the study's solver pixel, at a tight tolerance, and seen
by the microscope: each load's fluorescence image (the probe's emission averaged over the
image pixels, blurred by the PSF, on a background with shot noise) thresholded by the study's
own Otsu code. The study reads only those measured areas and the surface; never the truth's
fields.

The surface is one field on the fine grid: the study's indenter is its area average onto the
study's pixel (what a noiseless AFM map averaged to that pixel gives; AFM noise, levelling
and registration are not part of this study)."""

from __future__ import annotations

import time
import zlib
from collections.abc import Mapping
from dataclasses import dataclass
from importlib.metadata import version

import numpy as np

from amontons.config import geometry
from amontons.config.geometry import Frame
from amontons.contact import FreeBoundaryError, solve_load_series
from amontons.contact.options import DEFAULT_ITERATION
from amontons.contact.surfaces import sphere as sphere_cap
from amontons.measure.area import ContactArea, OtsuSettings, otsu_contact_area
from amontons.model_laws import law_of
from amontons.physics import hertz
from amontons.physics.emission import confined_emission
from amontons.simulate.grid import PixelAverager
from amontons.simulate.render import image_side_px
from amontons.validation.cases import CONTACTMECHANICS, Case, Truth
from amontons.validation.independent import contactmechanics_load_series, solver_label
from amontons.virtual.fluorescence import render_fluorescence
from amontons.virtual.rough_contact import HARDENING_RADIUS_GUESS, fast_even
from amontons.virtual.roughness import Roughness, synthesize


@dataclass(frozen=True)
class Sphere:
    """The validation sphere and how it is seen (SI units): radius, contact modulus, loads
    (increasing), roughness, the fluorescence image (pixel, PSF FWHM and the standard error
    the study is told it has, background and contact counts, confinement floor), the
    solver window over the Hertz contact diameter at the largest load."""

    radius_m: float
    e_star_pa: float
    loads_n: tuple[float, ...]
    roughness: Roughness
    image_pixel_m: float
    psf_fwhm_m: float
    psf_se_m: float
    background_counts: float
    contact_counts: float
    confinement_floor_pa: float
    window_factor: float

    @classmethod
    def from_config(cls, v: Mapping) -> Sphere:
        return cls(
            radius_m=v["diameter_mm"] * 0.5e-3,
            e_star_pa=v["e_star_gpa"] * 1e9,
            loads_n=tuple(f * 1e-3 for f in v["loads_mn"]),
            roughness=Roughness(
                v["roughness_rms_nm"] * 1e-9,
                v["roughness_hurst"],
                v["roughness_rolloff_um"] * 1e-6,
                v["roughness_reference_pixel_nm"] * 1e-9,
            ),
            image_pixel_m=v["image_pixel_nm"] * 1e-9,
            psf_fwhm_m=v["psf_fwhm_nm"] * 1e-9,
            psf_se_m=v["psf_se_nm"] * 1e-9,
            background_counts=v["background_counts"],
            contact_counts=v["contact_counts"],
            confinement_floor_pa=v["confinement_floor_mpa"] * 1e6,
            window_factor=v["window_factor"],
        )

    @classmethod
    def from_sheet(cls, record: Mapping, validation: Mapping, virtual: Mapping) -> Sphere:
        """A sphere of the materials sheet (``record``: diameter, E*, loads, roughness rms,
        fluorescence pixel) as the virtual experiment makes and images it (``virtual``: the
        roughness spectrum at the AFM pixel, the PSF, the counts, the confinement floor), told
        its PSF to ``validation.psf_se_nm``, on ``validation.spheres.window_factor``."""
        return cls.from_config(
            {
                "diameter_mm": record["diameter_mm"],
                "e_star_gpa": record["e_star_gpa"],
                "loads_mn": record["loads"],
                "roughness_rms_nm": record["roughness_rms_nm"],
                "roughness_hurst": virtual["roughness_hurst"],
                "roughness_rolloff_um": virtual["roughness_rolloff_um"],
                "roughness_reference_pixel_nm": virtual["afm_pixel_nm"],
                "image_pixel_nm": record.get("fluorescence_pixel_nm")
                or validation["image_pixel_nm"],
                "psf_fwhm_nm": virtual["psf_fwhm_nm"],
                "psf_se_nm": validation["psf_se_nm"],
                "background_counts": virtual["background_counts"],
                "contact_counts": virtual["contact_counts"],
                "confinement_floor_mpa": virtual["confinement_floor_mpa"],
                "window_factor": validation["spheres"]["window_factor"],
            }
        )

    @property
    def frame(self) -> Frame:
        """The sphere as a scene's frame (amontons.config.geometry)."""
        return Frame(self.loads_n, self.radius_m, self.e_star_pa)


def study_pixel_m(sphere: Sphere, preset: Mapping) -> float:
    """The pixel (m) the run's solver ``preset`` solves the sphere's scenes at: its
    ``pixel_nm``, coarsened where its window would need more than ``max_side_px`` pixels
    (amontons.config.geometry), as the reproduction solves its large spheres."""
    window = geometry.window_m("validation", preset, sphere.frame)
    return geometry.solver_pixel_m(preset, window)


def truth_law(truth: Truth):
    """The plasticity law the truth is solved with (SI), None for elastic."""
    return law_of(truth.model, truth.value)


@dataclass(frozen=True)
class Grids:
    """The study's solver grid (``study_px``² of ``study_pixel_m``) and the truth's finer one
    over the same window (``truth_px``² of ``truth_pixel_m``), m."""

    study_px: int
    study_pixel_m: float
    truth_px: int

    @property
    def window_m(self) -> float:
        return self.study_px * self.study_pixel_m

    @property
    def truth_pixel_m(self) -> float:
        return self.window_m / self.truth_px

    @property
    def ratio(self) -> float:
        """The truth's pixel against the study's (≥ the case's ratio, by rounding)."""
        return self.study_pixel_m / self.truth_pixel_m


def grids_of(sphere: Sphere, study_pixel_m: float, ratio: float) -> Grids:
    """The window (``window_factor`` × the Hertz diameter at the largest load, grown as a
    plastic contact grows it: the virtual experiment's HARDENING_RADIUS_GUESS) on the study's
    pixel, and the truth's grid ``ratio`` times finer over it."""
    a = hertz.contact_radius(max(sphere.loads_n), sphere.radius_m, sphere.e_star_pa)
    study_px = fast_even(
        int(np.ceil(sphere.window_factor * 2 * a * HARDENING_RADIUS_GUESS / study_pixel_m))
    )
    return Grids(study_px, study_pixel_m, fast_even(int(np.ceil(study_px * ratio))))


def case_rng(case: Case, what: str) -> np.random.Generator:
    """The case's generator for ``what`` (surface, image, psf): one stream per purpose, the
    same for a seed whatever the truth (every truth of a seed presses the same surface)."""
    return np.random.default_rng([case.seed, zlib.crc32(what.encode())])


def fine_surface(sphere: Sphere, grids: Grids, case: Case) -> np.ndarray:
    """The rough sphere's heights (m) on the truth's grid: paraboloid plus roughness."""
    shape = (grids.truth_px, grids.truth_px)
    dx = grids.truth_pixel_m
    rough = synthesize(shape, dx, sphere.roughness, case_rng(case, "surface"))
    return sphere_cap(shape, dx, sphere.radius_m) + rough


@dataclass(frozen=True)
class Measured:
    """The truth seen by the microscope: each load's measured Otsu contact, the true contact
    areas (m²), the surface on the fine grid (m) and the truth solve's wall time (s)."""

    contacts: list[ContactArea]
    true_areas_m2: list[float]
    heights: np.ndarray
    grids: Grids
    wall_time_s: float

    @property
    def areas_m2(self) -> list[float]:
        return [c.area_m2 for c in self.contacts]


def solve_truth(
    sphere: Sphere,
    grids: Grids,
    case: Case,
    heights: np.ndarray,
    tol: float,
    iteration: str = DEFAULT_ITERATION,
):
    """The truth's load series on the fine grid (each load's pressure, contact, area and mean
    pressure), by the truth's solver: ours (its CG ``iteration``, docs/models.md §2), or
    ContactMechanics (amontons.validation.independent), at ``tol``."""
    if case.truth.solver == CONTACTMECHANICS:
        hardness = truth_law(case.truth)
        return contactmechanics_load_series(
            heights,
            grids.truth_pixel_m,
            sphere.e_star_pa,
            list(sphere.loads_n),
            None if hardness is None else hardness.p_y,
            tol,
        )
    try:
        return solve_load_series(
            heights,
            grids.truth_pixel_m,
            sphere.e_star_pa,
            list(sphere.loads_n),
            plasticity=truth_law(case.truth),
            tol=tol,
            iteration=iteration,
        )
    except FreeBoundaryError as error:
        raise ValueError(
            f"validation case {case.name}: the true contact reaches the window's edge "
            f"({error}); expected a larger validation.window_factor"
        ) from error


def truth_solver_label(case: Case) -> str:
    """Who solved the case's truth, with the release: ContactMechanics', or ours."""
    if case.truth.solver == CONTACTMECHANICS:
        return solver_label()
    return f"amontons {version('amontons')}"


def measure_truth(
    sphere: Sphere,
    grids: Grids,
    case: Case,
    tol: float,
    otsu: OtsuSettings,
    iteration: str = DEFAULT_ITERATION,
) -> Measured:
    """Solve the case's truth on the fine grid at ``tol`` (by our CG ``iteration`` where the
    truth is ours) and image every load."""
    heights = fine_surface(sphere, grids, case)
    start = time.perf_counter()
    results = solve_truth(sphere, grids, case, heights, tol, iteration)
    wall = time.perf_counter() - start
    side = image_side_px(grids.window_m, sphere.image_pixel_m)
    average = PixelAverager(heights.shape, grids.truth_pixel_m, (side, side), sphere.image_pixel_m)
    # counts: contact_counts at the smallest load's mean pressure, ∝ √p (the virtual experiment's
    # convention, amontons.virtual.experiment)
    floor = sphere.confinement_floor_pa
    scale = sphere.contact_counts / np.sqrt(max(results[0].mean_pressure, floor))
    rng = case_rng(case, "image")
    contacts = []
    for result in results:
        signal = scale * average(confined_emission(result.pressure, result.contact, floor))
        image = render_fluorescence(
            signal,
            sphere.image_pixel_m,
            psf_fwhm_m=sphere.psf_fwhm_m,
            background_counts=sphere.background_counts,
            rng=rng,
        )
        contacts.append(otsu_contact_area(image, sphere.image_pixel_m, otsu))
    return Measured(contacts, [float(r.area) for r in results], heights, grids, wall)
