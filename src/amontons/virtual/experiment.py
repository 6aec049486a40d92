"""Write one sphere's virtual experiment: every instrument's raw file and the truth behind them.

Two halves, kept apart on purpose:

1. *The contact state* per load — a pressure map, a gap map and a contact mask on the
   fluorescence image grid (``ContactState``): the rough sphere under contact hardening
   (``rough_contact.image_contact_states``), or a smooth Hertz sphere
   (``hertz_contact_state``) where a test needs an analytic contact.
2. *The instruments*, each a function that takes a contact state (or nothing of it) and writes
   one file of the raw-data layout (amontons.rawdata): ``write_fluorescence``,
   ``write_reflection``, ``write_bead``, ``write_absorbance``, ``write_rheometer``,
   ``write_flim``. They never ask how the contact state was obtained.

Every instrument draws its noise from its own random stream (seed, sphere id, instrument name),
so adding or changing one instrument leaves the other files byte-identical.
"""

from __future__ import annotations

import json
import logging
import zlib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from amontons import hertz
from amontons.images import atomic_path, write_image
from amontons.optics.absorbance import AVOGADRO_PER_MOL, EPSILON_M2_PER_MOL
from amontons.powerlaw import fit_power_law
from amontons.rawdata import (
    ABSORBANCE_NAME,
    AFM_AFTER_NAME,
    AFM_BEFORE_NAME,
    BEAD_NAME,
    FLIM_NAME,
    REFLECTION_NAME,
    fluorescence_name,
    rheometer_name,
)
from amontons.surface import roughness_statistics
from amontons.virtual.absorbance import absorbance_spectrum, write_absorbance_csv
from amontons.virtual.afm import AfmSettings, scan_artefacts, write_afm
from amontons.virtual.bead import render_bead
from amontons.virtual.flim import render_flim
from amontons.virtual.fluorescence import confined_emission, pixel_averaged, render_fluorescence
from amontons.virtual.grid import resample
from amontons.virtual.reflection import (
    N_FORMAMIDE,
    WAVELENGTH_M,
    hertz_gap,
    radial_gap_map,
    render_reflection,
    ring_gap,
)
from amontons.virtual.rheometer import rheometer_trace, write_rheometer_trace
from amontons.virtual.rough_contact import (
    RoughSphereSolution,
    SolverSettings,
    contact_radius_m,
    edge_radius_m,
    image_contact_states,
    simulate_rough_sphere,
)
from amontons.virtual.roughness import Roughness, synthesize
from amontons.virtual.state import ContactState, load_index

log = logging.getLogger(__name__)

# A 0.5 nm-step spectrophotometer scan across the band (the grafting-density tests use the same
# scan): 401 points, enough for LOWESS to average the monolayer's noise down.
ABSORBANCE_SCAN_NM = np.arange(400.0, 600.01, 0.5)
# The band maximum: the 488 nm excitation line, where the appendix reads 0.0016 (Fig. B.1).
ABSORBANCE_PEAK_NM = 488.0
# Both faces of the cover slip carry a monolayer and the beam crosses both (science.md §1).
COATED_FACES = 2
# Rheometer record: 20 s at 100 Hz (1 s rest, 4 s loading to the static peak, then sliding).
RHEOMETER_DURATION_S = 20.0
RHEOMETER_RATE_HZ = 100.0


@dataclass(frozen=True)
class InstrumentSettings:
    """The virtual instruments, in SI units (see config/README.md for each key)."""

    psf_fwhm_m: float
    background_counts: float
    contact_counts: float
    confinement_floor_pa: float
    field_of_view_factor: float
    reflection_counts: float
    reflection_contrast: float
    reflection_rings: int
    bead_field_m: float
    bead_peak_counts: float
    absorbance_peak: float
    absorbance_band_fwhm_nm: float
    absorbance_noise_sd: float
    rotation_radius_m: float
    sliding_speed_m_s: float
    dynamic_fraction: float
    flim_field_px: int
    flim_contact_ns: float
    flim_outside_ns: float
    flim_noise_ns: float

    @classmethod
    def from_config(cls, settings: Mapping) -> InstrumentSettings:
        """Convert the ``virtual_experiment`` config slice (units in key names) to SI."""
        return cls(
            psf_fwhm_m=settings["psf_fwhm_nm"] * 1e-9,
            background_counts=settings["background_counts"],
            contact_counts=settings["contact_counts"],
            confinement_floor_pa=settings["confinement_floor_mpa"] * 1e6,
            field_of_view_factor=settings["field_of_view_factor"],
            reflection_counts=settings["reflection_counts"],
            reflection_contrast=settings["reflection_contrast"],
            reflection_rings=settings["reflection_rings"],
            bead_field_m=settings["bead_field_um"] * 1e-6,
            bead_peak_counts=settings["bead_peak_counts"],
            absorbance_peak=settings["absorbance_peak"],
            absorbance_band_fwhm_nm=settings["absorbance_band_fwhm_nm"],
            absorbance_noise_sd=settings["absorbance_noise_sd"],
            rotation_radius_m=settings["rotation_radius_mm"] * 1e-3,
            sliding_speed_m_s=settings["sliding_speed_um_s"] * 1e-6,
            dynamic_fraction=settings["dynamic_fraction"],
            flim_field_px=settings["flim_field_px"],
            flim_contact_ns=settings["flim_contact_ns"],
            flim_outside_ns=settings["flim_outside_ns"],
            flim_noise_ns=settings["flim_noise_ns"],
        )


@dataclass(frozen=True)
class SurfaceSettings:
    """The rough sphere and the grids it is seen on (SI units; config/README.md)."""

    hurst: float
    rolloff_m: float
    solver: SolverSettings
    afm: AfmSettings

    @classmethod
    def from_config(cls, settings: Mapping) -> SurfaceSettings:
        """Convert the ``virtual_experiment`` config slice (units in key names) to SI."""
        return cls(
            hurst=settings["roughness_hurst"],
            rolloff_m=settings["roughness_rolloff_um"] * 1e-6,
            solver=SolverSettings(
                pixel_m=settings["solver_pixel_nm"] * 1e-9,
                max_grid_px=settings["solver_max_grid_px"],
                window_factor=settings["solver_window_factor"],
            ),
            afm=AfmSettings(
                pixel_m=settings["afm_pixel_nm"] * 1e-9,
                side_px=settings["afm_side_px"],
                noise_m=settings["afm_noise_nm"] * 1e-9,
                line_offsets=settings["afm_line_offsets"],
                line_offset_m=settings["afm_line_offset_nm"] * 1e-9,
            ),
        )


def instrument_rng(seed: int, sphere: str, instrument: str) -> np.random.Generator:
    """Random stream of one instrument of one sphere: depends on seed, sphere and instrument
    only (not on job order or on which other instruments ran)."""
    return np.random.default_rng(
        [seed, zlib.crc32(sphere.encode()), zlib.crc32(instrument.encode())]
    )


def field_of_view_px(largest_radius_m: float, pixel_m: float, factor: float) -> int:
    """Image side in pixels: ``factor`` × the largest contact diameter, rounded up to 32."""
    side = int(np.ceil(factor * 2 * largest_radius_m / pixel_m))
    return int(32 * np.ceil(side / 32))


def hertz_contact_state(
    load_n: float,
    radius_m: float,
    e_star_pa: float,
    shape: tuple[int, int],
    pixel_m: float,
    edge_gap_m: float = 0.0,
    confinement_floor_pa: float = 0.0,
) -> ContactState:
    """Contact state of a smooth Hertz sphere (Johnson 1985 §4.2) at the image centre.

    ``edge_gap_m`` lifts the gap outside the contact by a constant: a stand-in for the average
    local gap that roughness leaves at the fluorescent edge (the appendix measures ≤ 9 nm),
    so that the Newton-ring measurement has a non-zero truth to recover. The emission is
    :func:`confined_emission` with ``confinement_floor_pa``.
    """
    centre = ((shape[0] - 1) / 2, (shape[1] - 1) / 2)
    a = hertz.contact_radius(load_n, radius_m, e_star_pa)

    def pressure(x, y):
        return hertz.pressure_profile(np.hypot(x, y), load_n, radius_m, e_star_pa)

    def gap(r):
        return np.where(r > a, hertz_gap(r, load_n, radius_m, e_star_pa) + edge_gap_m, 0.0)

    rows, cols = np.indices(shape)
    contact = np.hypot(rows - centre[0], cols - centre[1]) * pixel_m <= a
    return ContactState(
        load_n=load_n,
        pressure_pa=pixel_averaged(pressure, shape, pixel_m),
        emission_sqrt_pa=pixel_averaged(
            lambda x, y: confined_emission(
                pressure(x, y), np.hypot(x, y) <= a, confinement_floor_pa
            ),
            shape,
            pixel_m,
        ),
        gap_m=radial_gap_map(shape, pixel_m, centre, gap),
        contact=contact,
        area_m2=float(np.pi * a**2),
        edge_gap_m=edge_gap_m,
        centre_px=centre,
    )


# --- the instruments: each writes one file of the raw-data layout -----------------------------


def write_fluorescence(
    path: Path,
    state: ContactState,
    pixel_m: float,
    counts_per_sqrt_pa: float,
    settings: InstrumentSettings,
    rng: np.random.Generator,
) -> None:
    """Confocal image: local intensity ∝ the probe's emission (√max(p, p_c) in contact,
    appendix Fig. B.4), PSF, background, noise."""
    signal = counts_per_sqrt_pa * state.emission_sqrt_pa
    image = render_fluorescence(
        signal,
        pixel_m,
        psf_fwhm_m=settings.psf_fwhm_m,
        background_counts=settings.background_counts,
        rng=rng,
    )
    write_image(path, image, pixel_m)


def write_reflection(
    path: Path,
    state: ContactState,
    pixel_m: float,
    settings: InstrumentSettings,
    rng: np.random.Generator,
) -> None:
    """Reflection image of the gap map: Newton rings (eq. B.1), on the fluorescence grid."""
    image = render_reflection(
        state.gap_m,
        pixel_m,
        background=settings.reflection_counts,
        contrast=settings.reflection_contrast,
        psf_fwhm_m=settings.psf_fwhm_m,
        rng=rng,
    )
    write_image(path, image, pixel_m)


def write_bead(
    path: Path, pixel_m: float, settings: InstrumentSettings, rng: np.random.Generator
) -> tuple[float, float]:
    """Image of a 100 nm bead (the PSF) near the field centre; returns its centre (x, y) in m."""
    side = int(np.ceil(settings.bead_field_m / pixel_m)) | 1
    # Off the pixel grid by a random sub-pixel amount, as a real bead is.
    centre = tuple(((side - 1) / 2 + rng.uniform(-0.5, 0.5)) * pixel_m for _ in range(2))
    image = render_bead(
        (side, side),
        pixel_m,
        settings.psf_fwhm_m,
        centre,
        settings.bead_peak_counts,
        settings.background_counts,
        rng,
    )
    write_image(path, image, pixel_m)
    return centre


def write_absorbance(
    path: Path, settings: InstrumentSettings, rng: np.random.Generator
) -> tuple[float, float]:
    """Absorbance spectrum of the probe cover slip; returns (true density per µm² of one face,
    the true peak absorbance)."""
    spectrum = absorbance_spectrum(
        ABSORBANCE_SCAN_NM,
        peak_absorbance=settings.absorbance_peak,
        peak_nm=ABSORBANCE_PEAK_NM,
        width_nm=settings.absorbance_band_fwhm_nm,
        noise_sd=settings.absorbance_noise_sd,
        rng=rng,
    )
    write_absorbance_csv(path, ABSORBANCE_SCAN_NM, spectrum)
    density_per_m2 = (
        settings.absorbance_peak / (EPSILON_M2_PER_MOL * COATED_FACES) * AVOGADRO_PER_MOL
    )
    return density_per_m2 * 1e-12, settings.absorbance_peak


def write_rheometer(
    path: Path,
    load_n: float,
    static_friction_n: float,
    settings: InstrumentSettings,
    rng: np.random.Generator,
) -> float:
    """One load's friction test (torque, angle, normal force); returns the true dynamic friction
    (N)."""
    dynamic = settings.dynamic_fraction * static_friction_n
    trace = rheometer_trace(
        load_n,
        static_friction_n,
        dynamic,
        settings.rotation_radius_m,
        settings.sliding_speed_m_s,
        RHEOMETER_DURATION_S,
        RHEOMETER_RATE_HZ,
        rng=rng,
    )
    write_rheometer_trace(path, trace)
    return dynamic


def write_flim(
    path: Path,
    state: ContactState,
    pixel_m: float,
    settings: InstrumentSettings,
    rng: np.random.Generator,
) -> np.ndarray:
    """Mean photon arrival time map (ns) of a window centred on the contact's right-hand edge
    (appendix Fig. B.3); returns the window's true contact mask."""
    half = settings.flim_field_px // 2
    row = round(state.centre_px[0])
    inside_cols = np.nonzero(state.contact[row])[0]
    edge_col = int(inside_cols.max()) if inside_cols.size else round(state.centre_px[1])
    # Pad with 'no contact' so a window reaching past the image is still defined.
    padded = np.pad(state.contact, half, constant_values=False)
    window = padded[row : row + 2 * half, edge_col : edge_col + 2 * half]
    arrival = render_flim(
        window,
        settings.flim_contact_ns,
        settings.flim_outside_ns,
        settings.flim_noise_ns,
        rng=rng,
    )
    write_image(path, arrival, pixel_m)
    return window


# --- one sphere ---------------------------------------------------------------------------------


def _check_load_listed(sphere: str, what: str, load_n: float | None, loads_n: list[float]):
    if load_n is not None and load_index(loads_n, load_n) is None:
        raise ValueError(
            f"{sphere}: {what} load {load_n * 1e3:g} mN is not one of the loads "
            f"{[f * 1e3 for f in loads_n]} mN"
        )


def write_afm_scans(
    out_dir: Path,
    solution: RoughSphereSolution,
    radius_m: float,
    roughness: Roughness,
    afm: AfmSettings,
    rng: np.random.Generator,
) -> dict:
    """Write ``afm_before.tif`` and ``afm_after.tif`` (the sphere near its apex before the
    load series and after it); return their truth. The scan centre is off the apex by up to
    a tenth of the window, as a real scan is.

    After: where the solve made the surface flow (h_pl < 0 on the solver grid, nearest
    pixel), the scan sees the deformed surface h + h_pl of the solver where it lies below the
    scan's own surface: asperity tops cut flat (appendix Fig. B.9), the finer roughness the
    solver grid does not carry kept below the cut.
    """
    side = afm.side_px
    offset = rng.uniform(-0.1, 0.1, size=2) * side * afm.pixel_m
    axis = (np.arange(side) - (side - 1) / 2) * afm.pixel_m
    rows_m, cols_m = axis + offset[0], axis + offset[1]
    dx = solution.spacing_m
    fine = synthesize((side, side), afm.pixel_m, roughness, rng, above_m=dx)
    coarse = resample(solution.roughness, dx, rows_m, cols_m, order=3)
    cap = -(rows_m[:, None] ** 2 + cols_m[None, :] ** 2) / (2 * radius_m)
    before = cap + coarse + fine
    plastic = solution.results[-1].plastic_displacement
    deformed = cap + resample(solution.roughness + plastic, dx, rows_m, cols_m, order=3)
    flowed = resample((plastic < 0).astype(float), dx, rows_m, cols_m, order=0) > 0.5
    after = np.where(flowed, np.minimum(before, deformed), before)
    before_scan = before + scan_artefacts(before.shape, afm, rng)
    after_scan = after + scan_artefacts(before.shape, afm, rng)
    write_afm(out_dir / AFM_BEFORE_NAME, before_scan, afm.pixel_m)
    write_afm(out_dir / AFM_AFTER_NAME, after_scan, afm.pixel_m)
    rough = coarse + fine
    stats = roughness_statistics(rough - rough.mean(), afm.pixel_m)
    return {
        "pixel_nm": afm.pixel_m * 1e9,
        "side_px": side,
        "apex_offset_um": [float(-o * 1e6) for o in offset],
        "noise_nm": afm.noise_m * 1e9,
        "line_offsets": afm.line_offsets,
        "line_offset_nm": afm.line_offset_m * 1e9,
        "roughness_rms_nm": stats.h_rms_m * 1e9,
        "slope_rms": stats.slope_rms,
        "curvature_rms_per_um": stats.curvature_rms_per_m * 1e-6,
        "max_plastic_depth_nm": float((before - after).max() * 1e9),
        "flattened_fraction": float(np.mean(after < before)),
    }


def generate_sphere(
    out_dir: str | Path,
    *,
    sphere: str,
    diameter_m: float,
    e_star_pa: float,
    roughness_rms_m: float,
    hardening_k_pa_per_m: float,
    loads_n: list[float],
    pixel_m: float,
    reflection_load_n: float,
    flim_load_n: float | None,
    shear_strength_pa: float,
    settings: InstrumentSettings,
    surface: SurfaceSettings,
    seed: int,
    threads: int = 1,
) -> dict:
    """Write every raw file of one sphere into ``out_dir`` and ``truth.json``; return the truth.

    The contact is a rough sphere under contact hardening (amontons.virtual.rough_contact),
    solved once per load on the solver grid and seen by each instrument on its own grid.
    ``contact_counts`` (settings) is the expected signal at the mean contact pressure of the
    smallest load; the signal scales as √max(p, p_c) in contact (p_c: the settings'
    ``confinement_floor_pa``). Static friction is ``shear_strength_pa`` × the true contact
    area at each load (F_f = τ·A); dynamic friction is ``dynamic_fraction`` of it.
    """
    out_dir = Path(out_dir)
    radius_m = diameter_m / 2
    _check_load_listed(sphere, "reflection", reflection_load_n, loads_n)
    _check_load_listed(sphere, "FLIM", flim_load_n, loads_n)
    roughness = Roughness(roughness_rms_m, surface.hurst, surface.rolloff_m, surface.afm.pixel_m)
    solution = simulate_rough_sphere(
        radius_m=radius_m,
        e_star_pa=e_star_pa,
        k_pa_per_m=hardening_k_pa_per_m,
        loads_n=loads_n,
        reflection_load_n=reflection_load_n,
        rings=settings.reflection_rings,
        roughness=roughness,
        settings=surface.solver,
        rng_seed=[seed, zlib.crc32(sphere.encode()), zlib.crc32(b"roughness")],
        threads=threads,
    )
    dx = solution.spacing_m
    largest = contact_radius_m(solution.results[-1].contact, dx)
    side = max(
        field_of_view_px(largest, pixel_m, settings.field_of_view_factor),
        int(32 * np.ceil(2 * solution.ring_reach_m / pixel_m / 32)),
    )
    # the solver window holds both with a margin (simulate_rough_sphere); never look past it
    side = min(side, int(solution.window_m / pixel_m) // 32 * 32)
    closing = settings.psf_fwhm_m / 2
    states = image_contact_states(
        solution,
        (side, side),
        pixel_m,
        gap_index=load_index(loads_n, reflection_load_n),
        closing_m=closing,
        confinement_floor_pa=settings.confinement_floor_pa,
    )
    truth = write_instruments(
        out_dir,
        sphere=sphere,
        states=states,
        pixel_m=pixel_m,
        reflection_load_n=reflection_load_n,
        flim_load_n=flim_load_n,
        shear_strength_pa=shear_strength_pa,
        settings=settings,
        seed=seed,
    )
    afm_truth = write_afm_scans(
        out_dir, solution, radius_m, roughness, surface.afm, instrument_rng(seed, sphere, "afm")
    )
    areas = np.array([r.area for r in solution.results])
    fit = fit_power_law(np.array(loads_n), areas, x_ref=loads_n[0])
    truth.update(
        {
            "forward_model": "rough sphere, contact hardening (elastic half-space + Winkler layer)",
            "diameter_mm": diameter_m * 1e3,
            "e_star_gpa": e_star_pa * 1e-9,
            "hardening_k_mpa_per_nm": hardening_k_pa_per_m * 1e-15,
            "roughness": {
                "rms_nm_at_afm_pixel": roughness_rms_m * 1e9,
                "hurst": surface.hurst,
                "rolloff_um": surface.rolloff_m * 1e6,
                "solver_grid_rms_nm": float(solution.roughness.std() * 1e9),
            },
            "solver": {
                "pixel_nm": dx * 1e9,
                "grid_px": int(solution.heights.shape[0]),
                "window_um": solution.window_m * 1e6,
                "tol": surface.solver.tol,
                "iterations": [int(r.iterations) for r in solution.results],
            },
            "approach_nm": [r.displacement * 1e9 for r in solution.results],
            "max_plastic_depth_nm": [
                float(-r.plastic_displacement.min() * 1e9) for r in solution.results
            ],
            "contact_radius_um": [contact_radius_m(r.contact, dx) * 1e6 for r in solution.results],
            "edge_radius_um": [
                edge_radius_m(r.contact, dx, closing) * 1e6 for r in solution.results
            ],
            "hertz_contact_radius_um": [
                hertz.contact_radius(f, radius_m, e_star_pa) * 1e6 for f in loads_n
            ],
            "area_exponent": fit.exponent.estimate,
            "afm": afm_truth,
        }
    )
    with atomic_path(out_dir / "truth.json") as tmp:
        tmp.write_text(json.dumps(truth, indent=2))
    return truth


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
) -> dict:
    """Write every instrument's file from the contact states (one per load, increasing) and
    return the truth behind them (JSON-ready, units in the key names)."""
    smallest = states[0]
    mean_pressure_min = smallest.load_n / smallest.area_m2
    counts_per_sqrt_pa = settings.contact_counts / np.sqrt(mean_pressure_min)

    fluorescence_rng = instrument_rng(seed, sphere, "fluorescence")
    for state in states:
        path = out_dir / "fluorescence" / fluorescence_name(state.load_n * 1e3)
        write_fluorescence(path, state, pixel_m, counts_per_sqrt_pa, settings, fluorescence_rng)
        log.info("%s: %s (%d² px)", sphere, path, state.contact.shape[0])

    reflected = _matching(states, reflection_load_n)
    write_reflection(
        out_dir / REFLECTION_NAME,
        reflected,
        pixel_m,
        settings,
        instrument_rng(seed, sphere, "reflection"),
    )
    bead_centre = write_bead(
        out_dir / BEAD_NAME, pixel_m, settings, instrument_rng(seed, sphere, "bead")
    )
    density_per_um2, peak = write_absorbance(
        out_dir / ABSORBANCE_NAME, settings, instrument_rng(seed, sphere, "absorbance")
    )
    rheometer_rng = instrument_rng(seed, sphere, "rheometer")
    static, dynamic = [], []
    for state in states:
        static.append(shear_strength_pa * state.area_m2)
        dynamic.append(
            write_rheometer(
                out_dir / "rheometer" / rheometer_name(state.load_n * 1e3),
                state.load_n,
                static[-1],
                settings,
                rheometer_rng,
            )
        )
    flim_truth = None
    if flim_load_n is not None:
        window = write_flim(
            out_dir / FLIM_NAME,
            _matching(states, flim_load_n),
            pixel_m,
            settings,
            instrument_rng(seed, sphere, "flim"),
        )
        flim_truth = {
            "load_mn": flim_load_n * 1e3,
            "contact_ns": settings.flim_contact_ns,
            "outside_ns": settings.flim_outside_ns,
            "noise_ns": settings.flim_noise_ns,
            "contact_pixels": int(window.sum()),
            "field_px": int(window.shape[0]),
        }

    loads_mn = [s.load_n * 1e3 for s in states]
    return {
        "synthetic": True,
        "sphere": sphere,
        "seed": seed,
        "loads_mn": loads_mn,
        "area_um2": [s.area_m2 * 1e12 for s in states],
        "mean_pressure_mpa": [s.load_n / s.area_m2 * 1e-6 for s in states],
        "pixel_nm": pixel_m * 1e9,
        "image_side_px": int(smallest.contact.shape[0]),
        "psf_fwhm_nm": settings.psf_fwhm_m * 1e9,
        "background_counts": settings.background_counts,
        "local_intensity_pressure_exponent": 0.5,
        "confinement_floor_mpa": settings.confinement_floor_pa * 1e-6,
        "intensity_pressure_exponent": mean_intensity_exponent(states, pixel_m),
        "intensity_pressure_definition": "exponent of the true mean contact intensity "
        "(sum of the pixel-averaged emission sqrt(max(p, p_c)) over the true area) versus the "
        "true mean pressure F/A; the local law is I ~ p^0.5 above the confinement floor p_c, "
        "a rough contact's mean follows its own exponent",
        "bead_centre_nm": [c * 1e9 for c in bead_centre],
        "grafting_density_per_um2": density_per_um2,
        "absorbance_peak": peak,
        "absorbance_peak_nm": ABSORBANCE_PEAK_NM,
        "coated_faces": COATED_FACES,
        "reflection_load_mn": reflection_load_n * 1e3,
        "edge_gap_nm": reflected.edge_gap_m * 1e9,
        "edge_gap_definition": "gap just outside the true (mechanical) contact edge at the "
        "reflection load; the Otsu edge of the fluorescence lies slightly inside it",
        "first_ring_gap_nm": float(ring_gap(0, WAVELENGTH_M, N_FORMAMIDE)) * 1e9,
        "wavelength_nm": WAVELENGTH_M * 1e9,
        "refractive_index": N_FORMAMIDE,
        "shear_strength_mpa": shear_strength_pa * 1e-6,
        "static_friction_mn": [f * 1e3 for f in static],
        "dynamic_friction_mn": [f * 1e3 for f in dynamic],
        "rotation_radius_mm": settings.rotation_radius_m * 1e3,
        "sliding_speed_um_s": settings.sliding_speed_m_s * 1e6,
        "flim": flim_truth,
    }
