"""Write one sphere's virtual experiment: every instrument's raw file and the truth behind them.

Two halves, kept apart on purpose:

1. *The contact state* per load — a pressure map, a gap map and a contact mask on the
   fluorescence image grid (``ContactState``). For now it is a smooth Hertzian sphere
   (``hertz_contact_state``); the rough-sphere contact solver will provide the same object.
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
from amontons.rawdata import (
    ABSORBANCE_NAME,
    BEAD_NAME,
    FLIM_NAME,
    REFLECTION_NAME,
    fluorescence_name,
    rheometer_name,
)
from amontons.virtual.absorbance import absorbance_spectrum, write_absorbance_csv
from amontons.virtual.bead import render_bead
from amontons.virtual.flim import render_flim
from amontons.virtual.fluorescence import pixel_averaged, render_fluorescence
from amontons.virtual.reflection import (
    N_FORMAMIDE,
    WAVELENGTH_M,
    hertz_gap,
    radial_gap_map,
    render_reflection,
    ring_gap,
)
from amontons.virtual.rheometer import rheometer_trace, write_rheometer_trace

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
    field_of_view_factor: float
    reflection_counts: float
    reflection_contrast: float
    reflection_rings: int
    edge_gap_m: float
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
            field_of_view_factor=settings["field_of_view_factor"],
            reflection_counts=settings["reflection_counts"],
            reflection_contrast=settings["reflection_contrast"],
            reflection_rings=settings["reflection_rings"],
            edge_gap_m=settings["edge_gap_nm"] * 1e-9,
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
class ContactState:
    """One load's contact on the image grid (origin at the image centre, square pixels).

    ``pressure_pa``: pressure averaged over each pixel (Pa); ``gap_m``: gap at pixel centres
    (m, 0 in contact); ``contact``: pixels whose centre is in contact; ``area_m2``: the true
    contact area; ``edge_gap_m``: the gap just outside the contact edge (m), what the Newton
    rings extrapolate to.
    """

    load_n: float
    pressure_pa: np.ndarray
    gap_m: np.ndarray
    contact: np.ndarray
    area_m2: float
    edge_gap_m: float
    centre_px: tuple[float, float]


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


def hertz_ring_radius(gap_m: float, load_n: float, radius_m: float, e_star_pa: float) -> float:
    """Distance from the centre (m) at which the Hertz gap reaches ``gap_m`` (bisection; the
    exterior gap rises monotonically from 0 at the edge)."""
    lo = hertz.contact_radius(load_n, radius_m, e_star_pa)
    hi = 2 * lo
    while hertz_gap(np.array([hi]), load_n, radius_m, e_star_pa)[0] < gap_m:
        hi *= 2
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if hertz_gap(np.array([mid]), load_n, radius_m, e_star_pa)[0] < gap_m:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def reflection_field_px(
    rings: int, load_n: float, radius_m: float, e_star_pa: float, pixel_m: float
) -> int:
    """Image side (px, a multiple of 32) whose half-width holds ``rings`` bright rings plus half
    a ring spacing, so that every half-profile through the centre crosses that many rings."""
    gaps = ring_gap(np.arange(rings + 1), WAVELENGTH_M, N_FORMAMIDE)
    outer = 0.5 * (gaps[-2] + gaps[-1])  # half-way to the next ring
    reach_m = hertz_ring_radius(float(outer), load_n, radius_m, e_star_pa)
    return int(32 * np.ceil(2 * reach_m / pixel_m / 32))


def hertz_contact_state(
    load_n: float,
    radius_m: float,
    e_star_pa: float,
    shape: tuple[int, int],
    pixel_m: float,
    edge_gap_m: float = 0.0,
) -> ContactState:
    """Contact state of a smooth Hertz sphere (Johnson 1985 §4.2) at the image centre.

    ``edge_gap_m`` lifts the gap outside the contact by a constant: a stand-in for the average
    local gap that roughness leaves at the fluorescent edge (the appendix measures ≤ 9 nm),
    so that the Newton-ring measurement has a non-zero truth to recover.
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
    """Confocal image: local intensity ∝ √pressure (appendix Fig. B.4), PSF, background, noise."""
    signal = counts_per_sqrt_pa * np.sqrt(state.pressure_pa)
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


def generate_sphere(
    out_dir: str | Path,
    *,
    sphere: str,
    diameter_m: float,
    e_star_pa: float,
    loads_n: list[float],
    pixel_m: float,
    reflection_load_n: float,
    flim_load_n: float | None,
    shear_strength_pa: float,
    settings: InstrumentSettings,
    seed: int,
) -> dict:
    """Write every raw file of one sphere into ``out_dir`` and ``truth.json``; return the truth.

    ``contact_counts`` (settings) is the expected signal at the mean contact pressure of the
    smallest load; the signal scales as √p. Static friction is ``shear_strength_pa`` × the true
    contact area at each load (F_f = τ·A); dynamic friction is ``dynamic_fraction`` of it.
    """
    out_dir = Path(out_dir)
    radius_m = diameter_m / 2
    if not any(np.isclose(reflection_load_n, f, rtol=1e-9) for f in loads_n):
        raise ValueError(
            f"{sphere}: reflection load {reflection_load_n * 1e3:g} mN is not one of the loads "
            f"{[f * 1e3 for f in loads_n]} mN"
        )
    if flim_load_n is not None and not any(np.isclose(flim_load_n, f) for f in loads_n):
        raise ValueError(
            f"{sphere}: FLIM load {flim_load_n * 1e3:g} mN is not one of the loads "
            f"{[f * 1e3 for f in loads_n]} mN"
        )
    radii = [hertz.contact_radius(f, radius_m, e_star_pa) for f in loads_n]
    side = max(
        field_of_view_px(max(radii), pixel_m, settings.field_of_view_factor),
        reflection_field_px(
            settings.reflection_rings, reflection_load_n, radius_m, e_star_pa, pixel_m
        ),
    )
    states = [
        hertz_contact_state(f, radius_m, e_star_pa, (side, side), pixel_m, settings.edge_gap_m)
        for f in loads_n
    ]
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
    truth.update(
        {
            "forward_model": "hertz (smooth sphere)",
            "contact_radius_um": [a * 1e6 for a in radii],
            "area_exponent": 2 / 3,
            "diameter_mm": diameter_m * 1e3,
            "e_star_gpa": e_star_pa * 1e-9,
        }
    )
    with atomic_path(out_dir / "truth.json") as tmp:
        tmp.write_text(json.dumps(truth, indent=2))
    return truth


def _matching(states: list[ContactState], load_n: float) -> ContactState:
    return next(s for s in states if np.isclose(s.load_n, load_n, rtol=1e-9))


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
        "intensity_pressure_exponent": 0.5,
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
