"""Friction from rheometer torque traces (appendix B.1.2) and the friction-versus-load table.

The rheometer measures the torque M on the plate to which the sphere is glued, off-centre at
the rotation radius R_rot (measured by microscopy to ~1 %). The tangential force on the
contact is M/R_rot; the same radius turns the plate angle θ into sliding distance R_rot·Δθ
and the angular rate into sliding speed R_rot·dθ/dt.

One CSV per normal load (``<folder>/rheometer/<load in mN>.csv``): leading comment lines
``# key: value`` with at least ``# rotation_radius_mm: <value>``, then the columns
time_s, angle_rad, normal_force_N, torque_N_m.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.ndimage import median_filter

from amontons.images import atomic_path

COLUMNS = ("time_s", "angle_rad", "normal_force_N", "torque_N_m")
RADIUS_KEY = "rotation_radius_mm"


class RheometerError(ValueError):
    """A rheometer file or trace from which no friction force can be read."""


@dataclass(frozen=True)
class RheometerTrace:
    """One load's record: time (s), plate angle (rad), normal force (N), torque (N·m)."""

    time_s: np.ndarray
    angle_rad: np.ndarray
    normal_force_n: np.ndarray
    torque_n_m: np.ndarray
    rotation_radius_m: float | None = None
    metadata: dict[str, str] = field(default_factory=dict)
    source: str = "<memory>"


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


# --- reading and writing -----------------------------------------------------------------------


def _metadata(lines: list[str]) -> dict[str, str]:
    metadata = {}
    for line in lines:
        body = line.lstrip("#").strip()
        if ":" in body:
            key, value = body.split(":", 1)
            metadata[key.strip()] = value.strip()
    return metadata


def read_rheometer_csv(path: str | Path) -> RheometerTrace:
    """Read one load's rheometer CSV with its '# key: value' header.

    Raises RheometerError naming the file for a missing column, missing or invalid
    rotation-radius metadata, non-numeric values, or fewer than 10 rows.
    """
    path = Path(path)
    if not path.is_file():
        raise RheometerError(f"{path}: no such rheometer file")
    with path.open(encoding="utf-8") as handle:
        header = []
        for line in handle:
            if not line.startswith("#"):
                break
            header.append(line)
    metadata = _metadata(header)
    radius_m = _radius_from_metadata(path, metadata)
    table = pd.read_csv(path, comment="#")
    columns = {}
    for column in COLUMNS:
        if column not in table.columns:
            raise RheometerError(
                f"{path}: no column '{column}'; found {list(table.columns)}, expected "
                f"{list(COLUMNS)}"
            )
        values = pd.to_numeric(table[column], errors="coerce").to_numpy(dtype=float)
        if not np.all(np.isfinite(values)):
            bad = int(np.count_nonzero(~np.isfinite(values)))
            raise RheometerError(f"{path}: {bad} non-numeric or missing values in '{column}'")
        columns[column] = values
    if len(table) < 10:
        raise RheometerError(f"{path}: {len(table)} rows; a friction trace needs at least 10")
    return RheometerTrace(
        time_s=columns["time_s"],
        angle_rad=columns["angle_rad"],
        normal_force_n=columns["normal_force_N"],
        torque_n_m=columns["torque_N_m"],
        rotation_radius_m=radius_m,
        metadata=metadata,
        source=str(path),
    )


def _radius_from_metadata(path: Path, metadata: dict[str, str]) -> float:
    if RADIUS_KEY not in metadata:
        raise RheometerError(
            f"{path}: no '# {RADIUS_KEY}: <value>' line in the header; the rotation radius "
            "is needed to turn torque into force"
        )
    try:
        radius_mm = float(metadata[RADIUS_KEY])
    except ValueError:
        radius_mm = float("nan")
    if not np.isfinite(radius_mm) or radius_mm <= 0:
        raise RheometerError(
            f"{path}: {RADIUS_KEY} = '{metadata[RADIUS_KEY]}'; expected a positive number of mm"
        )
    return radius_mm * 1e-3


def write_rheometer_csv(path: str | Path, trace: RheometerTrace) -> None:
    """Write a trace in the rheometer CSV layout, radius and metadata in the header, atomically."""
    if trace.rotation_radius_m is None:
        raise RheometerError(f"{path}: trace has no rotation radius to write")
    metadata = {**trace.metadata, RADIUS_KEY: f"{trace.rotation_radius_m * 1e3:.6g}"}
    table = pd.DataFrame(
        {
            "time_s": trace.time_s,
            "angle_rad": trace.angle_rad,
            "normal_force_N": trace.normal_force_n,
            "torque_N_m": trace.torque_n_m,
        }
    )
    with atomic_path(path) as tmp, tmp.open("w", encoding="utf-8") as handle:
        for key, value in metadata.items():
            handle.write(f"# {key}: {value}\n")
        table.to_csv(handle, index=False, float_format="%.9g")


# --- the measurement ---------------------------------------------------------------------------


def _check_trace(trace: RheometerTrace) -> None:
    arrays = (trace.time_s, trace.angle_rad, trace.normal_force_n, trace.torque_n_m)
    sizes = {np.asarray(a).size for a in arrays}
    if len(sizes) != 1:
        raise RheometerError(f"{trace.source}: columns have different lengths {sorted(sizes)}")
    if np.any(np.diff(trace.time_s) <= 0):
        raise RheometerError(f"{trace.source}: time_s is not strictly increasing")


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
    torque has no peak followed by sliding (still rising at the end of the record), when the
    peak does not stand ``min_peak_snr`` noise standard deviations above zero, or when no
    radius is known.
    """
    _check_trace(trace)
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
    Columns (units in the names): normal_force_N, area_m2, static_friction_N,
    friction_coefficient, mean_pressure_Pa (F_N/A), shear_strength_Pa (F_f/A), and the ratios
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
            "normal_force_N": force,
            "area_m2": area,
            "static_friction_N": friction,
            "friction_coefficient": friction / force,
            "mean_pressure_Pa": force / area,
            "shear_strength_Pa": friction / area,
        }
    )
    ref = table.iloc[reference]
    table["mu_over_mu_ref"] = table["friction_coefficient"] / ref["friction_coefficient"]
    table["area_over_area_ref"] = table["area_m2"] / ref["area_m2"]
    table["shear_strength_over_ref"] = table["shear_strength_Pa"] / ref["shear_strength_Pa"]
    table["area_per_load_over_ref"] = (table["area_m2"] / table["normal_force_N"]) / (
        ref["area_m2"] / ref["normal_force_N"]
    )
    return table.sort_values("normal_force_N", ignore_index=True)
