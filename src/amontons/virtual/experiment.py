"""Write one sphere's virtual experiment: every instrument's raw file and the truth behind them.

Two halves, kept apart on purpose:

1. *The contact state* per load — a pressure map, a gap map and a contact mask on the
   fluorescence image grid (``ContactState``): the rough sphere under contact hardening
   (``rough_contact.image_contact_states``), or a smooth Hertz sphere
   (``state.hertz_contact_state``) where a test needs an analytic contact.
2. *The instruments* (amontons.virtual.instruments), each writing one file of the raw-data
   layout from a contact state.

This module runs both for one sphere and writes ``truth.json``: every true value the
analysis is tested against (it never reads it).
"""

from __future__ import annotations

import logging
import zlib
from pathlib import Path

import numpy as np

from amontons.io.files import write_json
from amontons.io.layout import (
    ABSORBANCE_NAME,
    BEAD_STEM,
    FLIM_NAME,
    FLIM_PTU_NAME,
    REFLECTION_STEM,
    fluorescence_name,
    rheometer_name,
)
from amontons.io.rheometer_export_shapes import EXPORT_SHAPES
from amontons.model_laws import law_of
from amontons.models import model_named
from amontons.physics import hertz
from amontons.physics.newton_rings import ring_gap
from amontons.power_law import fit_power_law
from amontons.virtual.instruments import (
    ABSORBANCE_PEAK_NM,
    COATED_FACES,
    instrument_rng,
    write_absorbance,
    write_afm_scans,
    write_bead,
    write_flim,
    write_flim_ptu,
    write_fluorescence,
    write_reflection,
    write_rheometer,
)
from amontons.virtual.rough_contact import (
    RoughSphereSolution,
    contact_radius_m,
    edge_radius_m,
    image_contact_states,
    ring_reach_gap,
    simulate_rough_sphere,
)
from amontons.virtual.roughness import Roughness
from amontons.virtual.settings import (
    TIFF_AND_CSV,
    InstrumentSettings,
    OutputFormats,
    SurfaceSettings,
)
from amontons.virtual.state import ContactState, load_index

log = logging.getLogger(__name__)


def field_of_view_px(largest_radius_m: float, pixel_m: float, factor: float) -> int:
    """Image side in pixels: ``factor`` × the largest contact diameter, rounded up to 32."""
    side = int(np.ceil(factor * 2 * largest_radius_m / pixel_m))
    return int(32 * np.ceil(side / 32))


def _check_load_listed(sphere: str, what: str, load_n: float | None, loads_n: list[float]):
    if load_n is not None and load_index(loads_n, load_n) is None:
        raise ValueError(
            f"{sphere}: {what} load {load_n * 1e3:g} mN is not one of the loads "
            f"{[f * 1e3 for f in loads_n]} mN"
        )


def generate_sphere(
    out_dir: str | Path,
    *,
    sphere: str,
    diameter_m: float,
    e_star_pa: float,
    roughness_rms_m: float,
    true_model: str,
    true_value: float | None,
    loads_n: list[float],
    pixel_m: float,
    reflection_load_n: float,
    flim_load_n: float | None,
    shear_strength_pa: float,
    settings: InstrumentSettings,
    surface: SurfaceSettings,
    seed: int,
    threads: int = 1,
    formats: OutputFormats = TIFF_AND_CSV,
) -> dict:
    """Write every raw file of one sphere into ``out_dir`` and ``truth.json``; return the truth.

    The contact is a rough sphere under ``true_model`` (a model solved on a grid: the
    reproduction's spheres flow by contact hardening) at ``true_value`` (its parameter in the
    record's config unit; None for elastic; amontons.virtual.rough_contact), solved once per
    load on the solver grid and seen by each instrument on its own grid.
    ``contact_counts`` (settings) is the expected signal at the mean contact pressure of the
    smallest load; the signal scales as √max(p, p_c) in contact (p_c: the settings'
    ``confinement_floor_pa``). Static friction is ``shear_strength_pa`` × the true contact
    area at each load (F_f = τ·A); dynamic friction is ``dynamic_fraction`` of it. ``formats``
    chooses the FLIM and rheometer file formats (default: TIFF and our CSV).
    """
    out_dir = Path(out_dir)
    radius_m = diameter_m / 2
    _check_load_listed(sphere, "reflection", reflection_load_n, loads_n)
    _check_load_listed(sphere, "FLIM", flim_load_n, loads_n)
    roughness = Roughness(roughness_rms_m, surface.hurst, surface.rolloff_m, surface.afm.pixel_m)
    scan_pixel = surface.afm.scan_pixel_m(hertz.contact_radius(max(loads_n), radius_m, e_star_pa))
    solution = _solve_rough_sphere(
        sphere=sphere,
        seed=seed,
        radius_m=radius_m,
        e_star_pa=e_star_pa,
        law=law_of(true_model, true_value),
        loads_n=loads_n,
        reflection_load_n=reflection_load_n,
        roughness=roughness,
        scan_pixel_m=scan_pixel,
        settings=settings,
        surface=surface,
        threads=threads,
    )
    truth = write_instruments(
        out_dir,
        sphere=sphere,
        states=_image_states(solution, loads_n, reflection_load_n, pixel_m, settings),
        pixel_m=pixel_m,
        reflection_load_n=reflection_load_n,
        flim_load_n=flim_load_n,
        shear_strength_pa=shear_strength_pa,
        settings=settings,
        seed=seed,
        formats=formats,
    )
    afm_rng = instrument_rng(seed, sphere, "afm")
    afm_truth = write_afm_scans(
        out_dir, solution, radius_m, roughness, surface.afm, scan_pixel, afm_rng
    )
    truth.update(_true_model_record(true_model, true_value))
    truth.update(
        _forward_model_truth(solution, roughness, surface, settings, loads_n, diameter_m, e_star_pa)
    )
    truth["afm"] = afm_truth
    write_json(out_dir / "truth.json", truth)
    return truth


def _solve_rough_sphere(
    *,
    sphere: str,
    seed: int,
    radius_m: float,
    e_star_pa: float,
    law,
    loads_n: list[float],
    reflection_load_n: float,
    roughness: Roughness,
    scan_pixel_m: float,
    settings: InstrumentSettings,
    surface: SurfaceSettings,
    threads: int,
) -> RoughSphereSolution:
    """The rough sphere's load series under ``law`` on the solver grid (SI units), its
    surface drawn from the sphere's own roughness stream (seed, sphere, 'roughness'), on a
    window that holds the reflection image's Newton rings and the AFM scans of
    ``scan_pixel_m`` pixels (m)."""
    return simulate_rough_sphere(
        radius_m=radius_m,
        e_star_pa=e_star_pa,
        law=law,
        loads_n=loads_n,
        reflection_load_n=reflection_load_n,
        ring_reach_gap_m=ring_reach_gap(
            settings.reflection_rings, settings.wavelength_m, settings.refractive_index
        ),
        roughness=roughness,
        settings=surface.solver,
        rng_seed=[seed, zlib.crc32(sphere.encode()), zlib.crc32(b"roughness")],
        # the AFM scans sample the solver's surface: its window holds their footprint
        min_window_m=surface.afm.footprint_m(scan_pixel_m),
        threads=threads,
    )


def _closing_m(settings: InstrumentSettings) -> float:
    """Radius (m) of the disc that closes the contact mask into the envelope the microscope
    sees: half the PSF's FWHM (gaps between patches narrower than that are not resolved)."""
    return settings.psf_fwhm_m / 2


def _image_side_px(
    solution: RoughSphereSolution, pixel_m: float, settings: InstrumentSettings
) -> int:
    """Side (px of ``pixel_m`` m, a multiple of 32) of the square fluorescence image: the
    field of view of the largest contact, or the reflection load's Newton rings if wider."""
    largest = contact_radius_m(solution.results[-1].contact, solution.spacing_m)
    side = max(
        field_of_view_px(largest, pixel_m, settings.field_of_view_factor),
        int(32 * np.ceil(2 * solution.ring_reach_m / pixel_m / 32)),
    )
    # the solver window holds both with a margin (simulate_rough_sphere); never look past it
    return min(side, int(solution.window_m / pixel_m) // 32 * 32)


def _image_states(
    solution: RoughSphereSolution,
    loads_n: list[float],
    reflection_load_n: float,
    pixel_m: float,
    settings: InstrumentSettings,
) -> list[ContactState]:
    """Every load's contact state on the fluorescence image grid (``pixel_m`` m pixels), the
    gap map at the reflection load only."""
    side = _image_side_px(solution, pixel_m, settings)
    return image_contact_states(
        solution,
        (side, side),
        pixel_m,
        gap_index=load_index(loads_n, reflection_load_n),
        closing_m=_closing_m(settings),
        confinement_floor_pa=settings.confinement_floor_pa,
    )


def _forward_model_truth(
    solution: RoughSphereSolution,
    roughness: Roughness,
    surface: SurfaceSettings,
    settings: InstrumentSettings,
    loads_n: list[float],
    diameter_m: float,
    e_star_pa: float,
) -> dict:
    """The truth of the rough sphere's contact solve (JSON-ready, units in the key names)."""
    radius_m = diameter_m / 2
    dx = solution.spacing_m
    closing = _closing_m(settings)
    areas = np.array([r.area for r in solution.results])
    fit = fit_power_law(np.array(loads_n), areas, x_ref=loads_n[0])
    return {
        "diameter_mm": diameter_m * 1e3,
        "e_star_gpa": e_star_pa * 1e-9,
        "roughness": _roughness_truth(roughness, solution),
        "solver": _solver_truth(solution, surface),
        "approach_nm": [r.displacement * 1e9 for r in solution.results],
        "max_plastic_depth_nm": [_max_plastic_depth_nm(r) for r in solution.results],
        "contact_radius_um": [contact_radius_m(r.contact, dx) * 1e6 for r in solution.results],
        "edge_radius_um": [edge_radius_m(r.contact, dx, closing) * 1e6 for r in solution.results],
        "hertz_contact_radius_um": [
            hertz.contact_radius(f, radius_m, e_star_pa) * 1e6 for f in loads_n
        ],
        "area_exponent": fit.exponent.estimate,
    }


def _true_model_record(model: str, value: float | None) -> dict:
    """The forward model's name and its parameter under its sheet column, in its unit (a
    contact-hardening truth's k where the reproduction's truth has always had it)."""
    record = model_named(model)
    out = {"forward_model": f"rough sphere, {record.label}", "true_model": model}
    if record.parameter is not None:
        out[record.parameter.sheet_column] = value
    return out


def _max_plastic_depth_nm(result) -> float:
    """The deepest plastic displacement of a load's solve, nm (0 for an elastic solve)."""
    if result.plastic_displacement is None:
        return 0.0
    return float(-result.plastic_displacement.min() * 1e9)


def _roughness_truth(roughness: Roughness, solution: RoughSphereSolution) -> dict:
    """The drawn roughness: its parameters at the AFM pixel and its rms on the solver grid."""
    return {
        "rms_nm_at_afm_pixel": roughness.rms_m * 1e9,
        "hurst": roughness.hurst,
        "rolloff_um": roughness.rolloff_m * 1e6,
        "solver_grid_rms_nm": float(solution.roughness.std() * 1e9),
    }


def _solver_truth(solution: RoughSphereSolution, surface: SurfaceSettings) -> dict:
    """The solver's grid, tolerance and iterations per load."""
    return {
        "pixel_nm": solution.spacing_m * 1e9,
        "grid_px": int(solution.heights.shape[0]),
        "window_um": solution.window_m * 1e6,
        "tol": surface.solver.tol,
        "iterations": [int(r.iterations) for r in solution.results],
    }


def mean_intensity_exponent(states: list[ContactState], pixel_m: float) -> float:
    """Power-law exponent of the true mean contact intensity (Σ emission·Δx²/A, √Pa) versus
    the true mean pressure F/A over the load series: the quantity the intensity-pressure
    measurement estimates from the images."""
    intensity = [s.emission_sqrt_pa.sum() * pixel_m**2 / s.area_m2 for s in states]
    pressure = [s.load_n / s.area_m2 for s in states]
    return fit_power_law(
        np.array(pressure), np.array(intensity), x_ref=pressure[0]
    ).exponent.estimate


def _matching(states: list[ContactState], load_n: float) -> ContactState:
    return states[load_index([s.load_n for s in states], load_n)]


def write_instruments(
    out_dir: Path,
    *,
    sphere: str,
    states: list[ContactState],
    pixel_m: float,
    reflection_load_n: float,
    flim_load_n: float | None,
    shear_strength_pa: float,
    settings: InstrumentSettings,
    seed: int,
    formats: OutputFormats = TIFF_AND_CSV,
) -> dict:
    """Write every instrument's file from the contact states (one per load, increasing), in
    ``formats``, and return the truth behind them (JSON-ready, units in the key names)."""
    _write_fluorescence_series(out_dir, sphere, states, pixel_m, settings, seed, formats)
    reflected = _matching(states, reflection_load_n)
    write_reflection(
        out_dir / f"{REFLECTION_STEM}{formats.image_suffix}",
        reflected,
        pixel_m,
        settings,
        instrument_rng(seed, sphere, "reflection"),
        formats.images,
    )
    bead_centre = write_bead(
        out_dir / f"{BEAD_STEM}{formats.image_suffix}",
        pixel_m,
        settings,
        instrument_rng(seed, sphere, "bead"),
        formats.images,
    )
    density_per_um2, peak = write_absorbance(
        out_dir / ABSORBANCE_NAME, settings, instrument_rng(seed, sphere, "absorbance")
    )
    static, dynamic = _write_rheometer_series(
        out_dir, sphere, states, shear_strength_pa, settings, seed, formats
    )
    flim_truth = None
    if flim_load_n is not None:
        flim_truth = _write_flim(
            out_dir, _matching(states, flim_load_n), pixel_m, settings, formats, seed, sphere
        )
    return {
        **_load_series_truth(sphere, seed, states, pixel_m, settings),
        **_bead_and_absorbance_truth(bead_centre, density_per_um2, peak),
        **_reflection_truth(reflection_load_n, reflected, settings),
        **_friction_truth(shear_strength_pa, static, dynamic, settings),
        "rheometer_format": formats.rheometer,
        "image_format": formats.images,
        "flim": flim_truth,
    }


def _counts_per_sqrt_pa(smallest: ContactState, settings: InstrumentSettings) -> float:
    """Fluorescence gain (counts/√Pa): ``contact_counts`` at the mean contact pressure (Pa)
    of the smallest load."""
    mean_pressure_min = smallest.load_n / smallest.area_m2
    return settings.contact_counts / np.sqrt(mean_pressure_min)


def _write_fluorescence_series(
    out_dir: Path,
    sphere: str,
    states: list[ContactState],
    pixel_m: float,
    settings: InstrumentSettings,
    seed: int,
    formats: OutputFormats,
) -> None:
    """Write one fluorescence image per load (``pixel_m`` m pixels, in ``formats.images``)."""
    counts_per_sqrt_pa = _counts_per_sqrt_pa(states[0], settings)
    # one stream for the whole series, drawn in load order
    rng = instrument_rng(seed, sphere, "fluorescence")
    suffix, image_format = formats.image_suffix, formats.images
    for state in states:
        path = out_dir / "fluorescence" / fluorescence_name(state.load_n * 1e3, suffix)
        write_fluorescence(path, state, pixel_m, counts_per_sqrt_pa, settings, rng, image_format)
        log.info("%s: %s (%d² px)", sphere, path, state.contact.shape[0])


def _write_rheometer_series(
    out_dir: Path,
    sphere: str,
    states: list[ContactState],
    shear_strength_pa: float,
    settings: InstrumentSettings,
    seed: int,
    formats: OutputFormats,
) -> tuple[list[float], list[float]]:
    """Write one friction test per load (in ``formats.rheometer``); return the true static
    friction (N, ``shear_strength_pa`` × the true contact area) and dynamic friction (N) of
    each."""
    # one stream for the whole series, drawn in load order
    rng = instrument_rng(seed, sphere, "rheometer")
    suffix = ".csv" if formats.rheometer == "csv" else EXPORT_SHAPES[formats.rheometer].suffix
    static, dynamic = [], []
    for state in states:
        static.append(shear_strength_pa * state.area_m2)
        dynamic.append(
            write_rheometer(
                out_dir / "rheometer" / rheometer_name(state.load_n * 1e3, suffix),
                state.load_n,
                static[-1],
                settings,
                rng,
                formats.rheometer,
            )
        )
    return static, dynamic


def _load_series_truth(
    sphere: str,
    seed: int,
    states: list[ContactState],
    pixel_m: float,
    settings: InstrumentSettings,
) -> dict:
    """The truth of the load series and its fluorescence images."""
    return {
        "synthetic": True,
        "sphere": sphere,
        "seed": seed,
        "loads_mn": [s.load_n * 1e3 for s in states],
        "area_um2": [s.area_m2 * 1e12 for s in states],
        "mean_pressure_mpa": [s.load_n / s.area_m2 * 1e-6 for s in states],
        "pixel_nm": pixel_m * 1e9,
        "image_side_px": int(states[0].contact.shape[0]),
        "psf_fwhm_nm": settings.psf_fwhm_m * 1e9,
        "background_counts": settings.background_counts,
        "local_intensity_pressure_exponent": 0.5,
        "confinement_floor_mpa": settings.confinement_floor_pa * 1e-6,
        "intensity_pressure_exponent": mean_intensity_exponent(states, pixel_m),
        "intensity_pressure_definition": "exponent of the true mean contact intensity "
        "(sum of the pixel-averaged emission sqrt(max(p, p_c)) over the true area) versus the "
        "true mean pressure F/A; the local law is I ~ p^0.5 above the confinement floor p_c, "
        "a rough contact's mean follows its own exponent",
    }


def _bead_and_absorbance_truth(
    bead_centre: tuple[float, float], density_per_um2: float, peak: float
) -> dict:
    """The truth of the bead image (its centre, m) and of the absorbance spectrum."""
    return {
        "bead_centre_nm": [c * 1e9 for c in bead_centre],
        "grafting_density_per_um2": density_per_um2,
        "absorbance_peak": peak,
        "absorbance_peak_nm": ABSORBANCE_PEAK_NM,
        "coated_faces": COATED_FACES,
    }


def _reflection_truth(
    reflection_load_n: float, reflected: ContactState, settings: InstrumentSettings
) -> dict:
    """The truth of the reflection image: the edge gap at the reflection load and the optics."""
    return {
        "reflection_load_mn": reflection_load_n * 1e3,
        "edge_gap_nm": reflected.edge_gap_m * 1e9,
        "edge_gap_definition": "gap just outside the true (mechanical) contact edge at the "
        "reflection load; the Otsu edge of the fluorescence lies slightly inside it",
        "edge_profiles": reflected.edge_profiles,
        "first_ring_gap_nm": float(ring_gap(0, settings.wavelength_m, settings.refractive_index))
        * 1e9,
        "wavelength_nm": settings.wavelength_m * 1e9,
        "refractive_index": settings.refractive_index,
    }


def _friction_truth(
    shear_strength_pa: float,
    static: list[float],
    dynamic: list[float],
    settings: InstrumentSettings,
) -> dict:
    """The truth of the friction tests (``static``, ``dynamic``: friction per load, N)."""
    return {
        "shear_strength_mpa": shear_strength_pa * 1e-6,
        "static_friction_mn": [f * 1e3 for f in static],
        "dynamic_friction_mn": [f * 1e3 for f in dynamic],
        "rotation_radius_mm": settings.rotation_radius_m * 1e3,
        "sliding_speed_um_s": settings.sliding_speed_m_s * 1e6,
    }


def _write_flim(
    out_dir: Path,
    state: ContactState,
    pixel_m: float,
    settings: InstrumentSettings,
    formats: OutputFormats,
    seed: int,
    sphere: str,
) -> dict:
    """Write the FLIM file in its format; return its truth."""
    rng = instrument_rng(seed, sphere, "flim")
    truth = {
        "load_mn": state.load_n * 1e3,
        "contact_ns": settings.flim_contact_ns,
        "outside_ns": settings.flim_outside_ns,
    }
    if formats.flim == "tif":
        window = write_flim(out_dir / FLIM_NAME, state, pixel_m, settings, rng)
        truth["noise_ns"] = settings.flim_noise_ns
    else:
        tcspc = formats.tcspc
        window = write_flim_ptu(out_dir / FLIM_PTU_NAME, state, pixel_m, settings, tcspc, rng)
        truth["photons"] = {
            "per_pixel_mean": tcspc.photons_per_pixel,
            "irf_peak_ns": tcspc.irf_peak_s * 1e9,
            "irf_fwhm_ps": tcspc.irf_fwhm_s * 1e12,
            "tcspc_bin_ps": tcspc.bin_s * 1e12,
            "sync_period_ns": tcspc.sync_period_s * 1e9,
            "definition": "mean arrival time after the instrument response's peak = the "
            "lifetime; a pixel's standard error sqrt(tau^2 + sigma_irf^2 / N_photons)",
        }
    truth.update(
        {
            "contact_pixels": int(window.sum()),
            "field_px": int(window.shape[0]),
            "format": formats.flim,
        }
    )
    return truth
