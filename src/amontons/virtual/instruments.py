"""The virtual instruments: each function takes a contact state (or nothing of it) and writes
one file of the raw-data layout (amontons.io.layout), the way the real instrument would.
They never ask how the contact state was obtained.

Every instrument draws its noise from its own random stream (:func:`instrument_rng`: seed,
sphere id, instrument name), so adding or changing one instrument leaves the other files
byte-identical.
"""

from __future__ import annotations

import uuid
import zlib
from datetime import datetime
from pathlib import Path

import numpy as np

from amontons.io.absorbance import write_absorbance_csv
from amontons.io.confocal_writers import write_confocal
from amontons.io.heightmap import write_height_map
from amontons.io.layout import AFM_AFTER_NAME, AFM_BEFORE_NAME
from amontons.io.ptu import write_ptu_image
from amontons.io.rheometer_export_shapes import write_rheometer_export
from amontons.io.tiff import write_image
from amontons.physics.beer_lambert import EPSILON_M2_PER_MOL, surface_density_per_m2
from amontons.physics.roughness import flattening_depth, roughness_statistics
from amontons.simulate.grid import resample_points
from amontons.virtual.absorbance import absorbance_spectrum
from amontons.virtual.afm import MAX_APEX_OFFSET, AfmSettings, afm_to_microscope, scan_artefacts
from amontons.virtual.bead import render_bead
from amontons.virtual.flim import TcspcSettings, photon_histograms, render_flim
from amontons.virtual.fluorescence import render_fluorescence
from amontons.virtual.reflection import render_reflection
from amontons.virtual.rheometer import rheometer_trace, write_rheometer_trace
from amontons.virtual.rough_contact import RoughSphereSolution
from amontons.virtual.roughness import Roughness, synthesize
from amontons.virtual.settings import InstrumentSettings
from amontons.virtual.state import ContactState

# A 0.5 nm-step spectrophotometer scan across the band (the grafting-density tests use the same
# scan): 401 points, enough for LOWESS to average the monolayer's noise down.
ABSORBANCE_SCAN_NM = np.arange(400.0, 600.01, 0.5)
# The band maximum: the 488 nm excitation line, where the appendix reads 0.0016 (Fig. B.1).
ABSORBANCE_PEAK_NM = 488.0
# Both faces of the cover slip carry a monolayer and the beam crosses both (docs/models.md §1.1).
COATED_FACES = 2
# A virtual acquisition has no time: its PTU header says the Unix epoch, as reproducible builds
# do, so that the same seed writes the same bytes.
VIRTUAL_ACQUISITION_TIME = datetime(1970, 1, 1)
# Rheometer record: 20 s at 100 Hz (1 s rest, 4 s loading to the static peak, then sliding).
RHEOMETER_DURATION_S = 20.0
RHEOMETER_RATE_HZ = 100.0


def instrument_rng(seed: int, sphere: str, instrument: str) -> np.random.Generator:
    """Random stream of one instrument of one sphere: depends on seed, sphere and instrument
    only (not on job order or on which other instruments ran)."""
    return np.random.default_rng(
        [seed, zlib.crc32(sphere.encode()), zlib.crc32(instrument.encode())]
    )


def write_fluorescence(
    path: Path,
    state: ContactState,
    pixel_m: float,
    counts_per_sqrt_pa: float,
    settings: InstrumentSettings,
    rng: np.random.Generator,
    image_format: str = "tif",
) -> None:
    """Confocal image: local intensity ∝ the probe's emission (√max(p, p_c) in contact,
    appendix Fig. B.4), PSF, background, noise; in ``image_format`` (amontons.io.layout
    IMAGE_FORMATS)."""
    signal = counts_per_sqrt_pa * state.emission_sqrt_pa
    image = render_fluorescence(
        signal,
        pixel_m,
        psf_fwhm_m=settings.psf_fwhm_m,
        background_counts=settings.background_counts,
        rng=rng,
    )
    write_confocal(path, image, pixel_m, image_format)


def write_reflection(
    path: Path,
    state: ContactState,
    pixel_m: float,
    settings: InstrumentSettings,
    rng: np.random.Generator,
    image_format: str = "tif",
) -> None:
    """Reflection image of the gap map: Newton rings (eq. B.1), on the fluorescence grid; in
    ``image_format``."""
    image = render_reflection(
        state.gap_m,
        pixel_m,
        wavelength_m=settings.wavelength_m,
        n_medium=settings.refractive_index,
        background=settings.reflection_counts,
        contrast=settings.reflection_contrast,
        psf_fwhm_m=settings.psf_fwhm_m,
        rng=rng,
    )
    write_confocal(path, image, pixel_m, image_format)


def write_bead(
    path: Path,
    pixel_m: float,
    settings: InstrumentSettings,
    rng: np.random.Generator,
    image_format: str = "tif",
) -> tuple[float, float]:
    """Image of a 100 nm bead (the PSF) near the field centre, in ``image_format``; returns
    its centre (x, y) in m."""
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
    write_confocal(path, image, pixel_m, image_format)
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
    density_per_m2 = surface_density_per_m2(
        settings.absorbance_peak, EPSILON_M2_PER_MOL, COATED_FACES
    )
    return density_per_m2 * 1e-12, settings.absorbance_peak


def write_rheometer(
    path: Path,
    load_n: float,
    static_friction_n: float,
    settings: InstrumentSettings,
    rng: np.random.Generator,
    shape: str = "csv",
) -> float:
    """One load's friction test (torque, angle, normal force), as our CSV (``shape`` 'csv') or
    as a program's export (a key of amontons.io.rheometer_export_shapes.EXPORT_SHAPES); returns the
    true dynamic friction (N). The trace, and so its noise, is the same in every shape."""
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
    if shape == "csv":
        write_rheometer_trace(path, trace)
    else:
        write_rheometer_export(path, trace, shape)
    return dynamic


def flim_window(state: ContactState, field_px: int) -> np.ndarray:
    """The true contact mask of the FLIM microscope's window: ``field_px`` square, centred on
    the contact's right-hand edge (appendix Fig. B.3)."""
    half = field_px // 2
    row = round(state.centre_px[0])
    inside_cols = np.nonzero(state.contact[row])[0]
    edge_col = int(inside_cols.max()) if inside_cols.size else round(state.centre_px[1])
    # Pad with 'no contact' so a window reaching past the image is still defined.
    padded = np.pad(state.contact, half, constant_values=False)
    return padded[row : row + 2 * half, edge_col : edge_col + 2 * half]


def write_flim(
    path: Path,
    state: ContactState,
    pixel_m: float,
    settings: InstrumentSettings,
    rng: np.random.Generator,
) -> np.ndarray:
    """Mean photon arrival time map (ns) of a window centred on the contact's right-hand edge
    (appendix Fig. B.3); returns the window's true contact mask."""
    window = flim_window(state, settings.flim_field_px)
    arrival = render_flim(
        window,
        settings.flim_contact_ns,
        settings.flim_outside_ns,
        settings.flim_noise_ns,
        rng=rng,
    )
    write_image(path, arrival, pixel_m)
    return window


def write_flim_ptu(
    path: Path,
    state: ContactState,
    pixel_m: float,
    settings: InstrumentSettings,
    tcspc: TcspcSettings,
    rng: np.random.Generator,
) -> np.ndarray:
    """The time-tagged photons of the same window as :func:`write_flim` (a T3 image-mode PTU,
    written by ptufile): each pixel a mono-exponential decay of the contact's or the free
    molecules' lifetime through a Gaussian instrument response, Poisson photons; returns the
    window's true contact mask."""
    window = flim_window(state, settings.flim_field_px)
    lifetime_s = np.where(window, settings.flim_contact_ns, settings.flim_outside_ns) * 1e-9
    histograms = photon_histograms(lifetime_s, tcspc, rng=rng)
    write_ptu_image(
        path,
        histograms,
        bin_s=tcspc.bin_s,
        sync_period_s=tcspc.sync_period_s,
        pixel_m=pixel_m,
        comment="amontons virtual experiment (synthetic data)",
        guid=uuid.UUID(bytes=rng.bytes(16), version=4),
        created=VIRTUAL_ACQUISITION_TIME,
    )
    return window


def write_afm_scans(
    out_dir: Path,
    solution: RoughSphereSolution,
    radius_m: float,
    roughness: Roughness,
    afm: AfmSettings,
    scan_pixel_m: float,
    rng: np.random.Generator,
) -> dict:
    """Write ``afm_before.tif`` and ``afm_after.tif`` (the sphere near its apex before the
    load series and after it, ``scan_pixel_m`` pixels); return their truth. The scan is
    mirrored and rotated against the microscope frame (:func:`afm_to_microscope`), and its
    centre is off the apex by up to ``MAX_APEX_OFFSET`` of its side, as a real scan is.

    After: where the solve made the surface flow (h_pl < 0 on the solver grid, nearest
    pixel), the scan sees the deformed surface h + h_pl of the solver where it lies below the
    scan's own surface: asperity tops cut flat (appendix Fig. B.9), the finer roughness the
    solver grid does not carry kept below the cut.
    """
    side = afm.side_px
    centre = rng.uniform(-MAX_APEX_OFFSET, MAX_APEX_OFFSET, size=2) * side * scan_pixel_m
    axis = (np.arange(side) - (side - 1) / 2) * scan_pixel_m
    rows, cols = afm_to_microscope(axis[:, None], axis[None, :], afm, centre)
    dx = solution.spacing_m
    fine = synthesize((side, side), scan_pixel_m, roughness, rng, above_m=dx)
    coarse = resample_points(solution.roughness, dx, rows, cols, order=3)
    cap = -(rows**2 + cols**2) / (2 * radius_m)
    before = cap + coarse + fine
    plastic = solution.results[-1].plastic_displacement
    deformed = cap + resample_points(solution.roughness + plastic, dx, rows, cols, order=3)
    flowed = resample_points((plastic < 0).astype(float), dx, rows, cols, order=0) > 0.5
    after = np.where(flowed, np.minimum(before, deformed), before)
    before_scan = before + scan_artefacts(before.shape, afm, rng)
    after_scan = after + scan_artefacts(before.shape, afm, rng)
    write_height_map(out_dir / AFM_BEFORE_NAME, before_scan, scan_pixel_m)
    write_height_map(out_dir / AFM_AFTER_NAME, after_scan, scan_pixel_m)
    rough = coarse + fine
    stats = roughness_statistics(rough - rough.mean(), scan_pixel_m)
    return {
        "pixel_nm": scan_pixel_m * 1e9,
        "side_px": side,
        "frame": {
            "definition": "microscope position (row, col about the apex) = rotate(mirror("
            "AFM position about the scan centre)) + scan centre; mirror flips the column "
            "axis, rotation is counter-clockwise as displayed",
            "mirrored": afm.mirrored,
            "rotation_deg": afm.rotation_deg,
            "scan_centre_um": [float(c * 1e6) for c in centre],
        },
        "noise_nm": afm.noise_m * 1e9,
        "line_offsets": afm.line_offsets,
        "line_offset_nm": afm.line_offset_m * 1e9,
        "roughness_rms_nm": stats.h_rms_m * 1e9,
        "slope_rms": stats.slope_rms,
        "curvature_rms_per_um": stats.curvature_rms_per_m * 1e-6,
        "max_plastic_depth_nm": float((before - after).max() * 1e9),
        # the measurement's depth statistic on the noise-free scans (docs/models.md §1.8),
        # at its smoothing (physics.roughness.FLATTENING_SMOOTHING_PX)
        "flattening_depth_nm": _depth_nm(before - after),
        "flattened_fraction": float(np.mean(after < before)),
    }


def _depth_nm(drop_m: np.ndarray) -> float | None:
    depth, _ = flattening_depth(drop_m)
    return None if depth is None else depth * 1e9
