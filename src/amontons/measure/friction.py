"""Friction from rheometer torque traces (appendix B.1.2) and the friction-versus-load table.

The rheometer measures the torque M on the plate to which the sphere is glued, off-centre at
the rotation radius R_rot (measured by microscopy to ~1 %). The tangential force on the
contact is M/R_rot; the same radius turns the plate angle θ into sliding distance R_rot·Δθ
and the angular rate into sliding speed R_rot·dθ/dt.

The records are read by amontons.io.rheometer (one CSV per normal load).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.ndimage import median_filter

from amontons.io.export_map import ExportMap
from amontons.io.layout import RawDataError
from amontons.io.rawdata import read_rheometer_traces
from amontons.io.rheometer import RheometerError, RheometerTrace


@dataclass(frozen=True)
class FrictionMeasurement:
    """Friction of one load: forces in N, speed in m/s, distance in m, times in s."""

    static_friction_n: float
    dynamic_friction_n: float
    dynamic_friction_se_n: float
    normal_force_n: float
    static_coefficient: float
    dynamic_coefficient: float
    sliding_speed_m_s: float
    sliding_distance_m: float
    peak_time_s: float
    rotation_radius_m: float


# --- the measurement ---------------------------------------------------------------------------


def _check_trace(trace: RheometerTrace, median_window_s: float) -> None:
    """Refuse a trace that cannot give a friction force: ragged columns, non-finite samples,
    time not increasing, or a dropout (a time step longer than both the median window and
    twice the median step, s: samples missing from the record)."""
    columns = {
        "time_s": trace.time_s,
        "angle_rad": trace.angle_rad,
        "normal_force_N": trace.normal_force_n,
        "torque_N_m": trace.torque_n_m,
    }
    sizes = {np.asarray(a).size for a in columns.values()}
    if len(sizes) != 1:
        raise RheometerError(f"{trace.source}: columns have different lengths {sorted(sizes)}")
    for name, values in columns.items():
        bad = ~np.isfinite(np.asarray(values, dtype=float))
        if bad.any():
            first = int(np.argmax(bad))
            raise RheometerError(
                f"{trace.source}: {int(bad.sum())} non-finite {name} samples (dropouts; the "
                f"first is sample {first}); expected a finite value in every sample"
            )
    steps = np.diff(trace.time_s)
    if np.any(steps <= 0):
        raise RheometerError(f"{trace.source}: time_s is not strictly increasing")
    longest = int(np.argmax(steps))
    # a gap as long as the median window can hide the peak the window is meant to find
    if steps[longest] > max(median_window_s, 2 * float(np.median(steps))):
        raise RheometerError(
            f"{trace.source}: {steps[longest]:.3g} s without samples after t = "
            f"{trace.time_s[longest]:.6g} s (a dropout longer than the {median_window_s:g} s "
            "median window); expected an evenly sampled record"
        )


def _median_value(values: np.ndarray, index: int, half: int) -> float:
    lo, hi = max(index - half, 0), min(index + half + 1, values.size)
    return float(np.median(values[lo:hi]))


def static_friction(
    trace: RheometerTrace,
    rotation_radius_m: float | None = None,
    *,
    median_window_s: float = 0.05,
    plateau_fraction: float = 0.5,
    min_peak_snr: float = 10.0,
) -> FrictionMeasurement:
    """Static and dynamic friction (N), sliding speed and distance from one torque trace.

    Static friction is the peak of the torque's moving median over ``median_window_s``,
    divided by the rotation radius. A median ignores single-sample spikes and, unlike a plain
    maximum, does not ride on the noise; the window is kept short against the torque's rise
    and drop so that it does not shave the peak off (a median of w samples around a sharp peak
    sits a few samples down its flanks). Dynamic friction is the mean torque over the last
    ``plateau_fraction`` of the sliding part (after the peak) divided by the radius. Sliding
    speed is the slope of a straight line through angle vs time after the peak, times the
    radius; sliding distance is the angle change from the peak to the end (each end a median
    over the window) times the radius. The normal force is the mean over the record.

    ``rotation_radius_m`` defaults to the trace's metadata. Raises RheometerError when the
    torque has no peak preceded by a rise and followed by sliding (largest at the start or
    the end of the record: constant, falling or still rising), when the peak does not stand
    ``min_peak_snr`` noise standard deviations above zero, when no radius is known, or for a
    record with dropouts (non-finite samples, or a gap longer than the median window).
    """
    _check_trace(trace, median_window_s)
    radius = rotation_radius_m if rotation_radius_m is not None else trace.rotation_radius_m
    if radius is None or not radius > 0:
        raise RheometerError(
            f"{trace.source}: rotation radius {radius}; expected a positive radius in m, "
            "from the file's metadata or the caller"
        )
    time, angle, torque = trace.time_s, trace.angle_rad, trace.torque_n_m
    dt = float(np.median(np.diff(time)))
    window = max(1, round(median_window_s / dt)) | 1  # odd, so the median is centred
    half = window // 2
    smoothed = median_filter(torque, size=window, mode="nearest")
    peak = int(np.argmax(smoothed))
    if peak < 2 * window:
        # a constant or falling torque: no loading ramp ends in this maximum
        raise RheometerError(
            f"{trace.source}: no static friction peak — the torque is largest at the start of "
            f"the record (t = {time[peak]:.3g} s of {time[-1]:.3g} s); expected it to rise "
            "to a peak followed by sliding"
        )
    if peak >= torque.size - 2 * window:
        raise RheometerError(
            f"{trace.source}: no static friction peak — the torque is largest at the end of the "
            f"record (t = {time[peak]:.3g} s of {time[-1]:.3g} s); expected a peak followed by "
            "sliding"
        )
    noise_sd = 1.4826 * float(np.median(np.abs(np.diff(torque)))) / np.sqrt(2)
    if smoothed[peak] <= min_peak_snr * noise_sd:
        raise RheometerError(
            f"{trace.source}: torque peak {smoothed[peak]:.3g} N·m is not above "
            f"{min_peak_snr:g} × the noise ({noise_sd:.3g} N·m); expected a friction signal"
        )
    sliding = slice(peak, torque.size)
    n_sliding = torque.size - peak
    plateau = slice(torque.size - max(2, int(plateau_fraction * n_sliding)), torque.size)
    plateau_torque = torque[plateau]
    speed_rad_s = np.polyfit(time[sliding], angle[sliding], 1)[0]
    swept_rad = _median_value(angle, angle.size - 1 - half, half) - _median_value(angle, peak, half)
    normal_force = float(np.mean(trace.normal_force_n))
    static = float(smoothed[peak] / radius)
    dynamic = float(plateau_torque.mean() / radius)
    return FrictionMeasurement(
        static_friction_n=static,
        dynamic_friction_n=dynamic,
        dynamic_friction_se_n=float(plateau_torque.std(ddof=1) / np.sqrt(plateau_torque.size))
        / radius,
        normal_force_n=normal_force,
        static_coefficient=static / normal_force,
        dynamic_coefficient=dynamic / normal_force,
        sliding_speed_m_s=float(speed_rad_s * radius),
        sliding_distance_m=float(swept_rad * radius),
        peak_time_s=float(time[peak]),
        rotation_radius_m=float(radius),
    )


# --- friction versus load ----------------------------------------------------------------------


def amontons_deviation(
    normal_force_n: np.ndarray,
    area_m2: np.ndarray,
    friction_n: np.ndarray,
    reference_load_n: float = 0.025,
    *,
    reference_tolerance: float = 0.1,
) -> pd.DataFrame:
    """Friction, area and their ratios to the values at the reference load (Fig. 5).

    Amontons' law says μ = F_f/F_N is constant; with F_f = τ·A and a sublinear A(F_N) it falls.
    Columns (units in the names): normal_force_N, area_m2, static_friction_n,
    friction_coefficient, mean_pressure_pa (F_N/A), shear_strength_pa (F_f/A), and the ratios
    mu_over_mu_ref, area_over_area_ref, shear_strength_over_ref and
    area_per_load_over_ref ((A/F_N)/(A/F_N)_ref, which is μ/μ_ref if τ is constant).
    The reference row is the load nearest ``reference_load_n``; it must lie within
    ``reference_tolerance`` (relative), else ValueError.
    """
    force = np.asarray(normal_force_n, dtype=float)
    area = np.asarray(area_m2, dtype=float)
    friction = np.asarray(friction_n, dtype=float)
    if not (force.shape == area.shape == friction.shape) or force.ndim != 1 or force.size == 0:
        raise ValueError(
            f"normal force, area and friction must be 1-D of equal length; got shapes "
            f"{force.shape}, {area.shape}, {friction.shape}"
        )
    for name, values in (("normal force", force), ("area", area), ("friction", friction)):
        if not np.all(np.isfinite(values)) or np.any(values <= 0):
            raise ValueError(f"{name} values {values} must be finite and > 0")
    reference = int(np.argmin(np.abs(force - reference_load_n)))
    if abs(force[reference] - reference_load_n) > reference_tolerance * reference_load_n:
        raise ValueError(
            f"no load within {reference_tolerance:.0%} of the reference {reference_load_n:g} N; "
            f"nearest is {force[reference]:g} N"
        )
    table = pd.DataFrame(
        {
            "normal_force_n": force,
            "area_m2": area,
            "static_friction_n": friction,
            "friction_coefficient": friction / force,
            "mean_pressure_pa": force / area,
            "shear_strength_pa": friction / area,
        }
    )
    ref = table.iloc[reference]
    table["mu_over_mu_ref"] = table["friction_coefficient"] / ref["friction_coefficient"]
    table["area_over_area_ref"] = table["area_m2"] / ref["area_m2"]
    table["shear_strength_over_ref"] = table["shear_strength_pa"] / ref["shear_strength_pa"]
    table["area_per_load_over_ref"] = (table["area_m2"] / table["normal_force_n"]) / (
        ref["area_m2"] / ref["normal_force_n"]
    )
    return table.sort_values("normal_force_n", ignore_index=True)


def measure_friction(
    rheometer_paths: Sequence[str | Path],
    loads_mn: Sequence[float],
    *,
    median_window_s: float,
    plateau_fraction: float,
    maps: Mapping[str, ExportMap] | None = None,
) -> pd.DataFrame:
    """Friction per load from the rheometer records ``rheometer_paths`` (one per load of
    ``loads_mn``; each our CSV, or a program's export read through the first of ``maps``,
    name → column map, that names its columns); units in the column names."""
    rows = []
    traces = read_rheometer_traces(rheometer_paths, loads_mn, maps)
    for load, trace in zip(loads_mn, traces, strict=True):
        try:
            result = static_friction(
                trace, median_window_s=median_window_s, plateau_fraction=plateau_fraction
            )
        except RheometerError as error:
            raise RawDataError(str(error)) from error
        rows.append(
            {
                "load_mn": load,
                "normal_force_mn": result.normal_force_n * 1e3,
                "static_friction_mn": result.static_friction_n * 1e3,
                "dynamic_friction_mn": result.dynamic_friction_n * 1e3,
                "dynamic_friction_se_mn": result.dynamic_friction_se_n * 1e3,
                "static_coefficient": result.static_coefficient,
                "dynamic_coefficient": result.dynamic_coefficient,
                "sliding_speed_um_s": result.sliding_speed_m_s * 1e6,
                "sliding_distance_um": result.sliding_distance_m * 1e6,
                "peak_time_s": result.peak_time_s,
                "rotation_radius_mm": result.rotation_radius_m * 1e3,
                "file": trace.source,
            }
        )
    return pd.DataFrame(rows)


def amontons_table(
    spheres: Sequence[str],
    area_tables: Sequence[pd.DataFrame],
    friction_tables: Sequence[pd.DataFrame],
    reference_load_mn: float,
) -> pd.DataFrame:
    """Area and static friction per load and sphere, normalised at ``reference_load_mn``
    (appendix Fig. B.13), from each sphere's contact_area.csv and friction.csv tables.

    Loads whose area is ill-determined (Otsu) are left out. The normal force is the
    rheometer's measured one.
    """
    frames = []
    for sphere, areas, friction in zip(spheres, area_tables, friction_tables, strict=True):
        merged = areas[areas["contact_found"]].merge(friction, on="load_mn", how="inner")
        deviation = amontons_deviation(
            merged["normal_force_mn"].to_numpy() * 1e-3,
            merged["area_um2"].to_numpy() * 1e-12,
            merged["static_friction_mn"].to_numpy() * 1e-3,
            reference_load_n=reference_load_mn * 1e-3,
        )
        # The same reference row as amontons_deviation: the load nearest the reference.
        reference = int(np.argmin(np.abs(deviation["normal_force_n"] - reference_load_mn * 1e-3)))
        frames.append(
            pd.DataFrame(
                {
                    "sphere": sphere,
                    "load_mn": merged.sort_values("normal_force_mn")["load_mn"].to_numpy(),
                    "normal_force_mn": deviation["normal_force_n"] * 1e3,
                    "area_um2": deviation["area_m2"] * 1e12,
                    "static_friction_mn": deviation["static_friction_n"] * 1e3,
                    "friction_coefficient": deviation["friction_coefficient"],
                    "shear_strength_mpa": deviation["shear_strength_pa"] * 1e-6,
                    "area_over_area_ref": deviation["area_over_area_ref"],
                    "friction_over_friction_ref": deviation["static_friction_n"]
                    / deviation["static_friction_n"].iloc[reference],
                    "mu_over_mu_ref": deviation["mu_over_mu_ref"],
                }
            )
        )
    return pd.concat(frames, ignore_index=True)
