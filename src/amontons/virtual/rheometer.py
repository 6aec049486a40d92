"""Forward model of a rheometer friction test at one normal load (appendix B.1.2).

The record, sampled at ``sample_rate_hz``:
- rest: no tangential force;
- loading: the tangential force F rises linearly to the static friction F_s; the sphere
  stays stuck and the plate turns only by the elastic compliance of sphere, glue and contact,
  θ = F/(k·R_rot);
- sliding: the sphere slides at ``sliding_speed_m_s`` (θ ramps at v/R_rot) and the force
  relaxes exponentially from F_s to the dynamic friction F_d.
Torque = F·R_rot; normal force = load; each channel gets white Gaussian noise.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from amontons.io.rheometer import RheometerTrace, write_rheometer_csv


def tangential_force(
    time_s: np.ndarray,
    rest_s: float,
    loading_s: float,
    friction_static_n: float,
    friction_dynamic_n: float,
    relaxation_s: float,
) -> np.ndarray:
    """Noise-free tangential force (N): 0, a linear rise to F_s, relaxation to F_d."""
    peak_s = rest_s + loading_s
    rising = friction_static_n * np.clip((time_s - rest_s) / loading_s, 0, 1)
    since_peak = np.clip(time_s - peak_s, 0, None)
    relaxing = friction_dynamic_n + (friction_static_n - friction_dynamic_n) * np.exp(
        -since_peak / relaxation_s
    )
    return np.where(time_s <= peak_s, rising, relaxing)


def rheometer_trace(
    load_n: float,
    friction_static_n: float,
    friction_dynamic_n: float,
    rotation_radius_m: float,
    sliding_speed_m_s: float,
    duration_s: float = 20.0,
    sample_rate_hz: float = 100.0,
    *,
    stiffness_n_per_m: float = 1e4,
    rest_s: float = 1.0,
    loading_s: float = 4.0,
    relaxation_s: float = 0.3,
    normal_noise_n: float = 2e-4,
    torque_noise_n_m: float = 5e-7,
    angle_noise_rad: float = 1e-6,
    rng: np.random.Generator,
) -> RheometerTrace:
    """Simulated record of one friction test; the true static peak is at t = rest + loading.

    ``stiffness_n_per_m`` is the tangential stiffness of the stuck contact (sets the angle
    before sliding); the noise arguments are standard deviations of each channel.
    """
    if not 0 < friction_dynamic_n <= friction_static_n:
        raise ValueError(
            f"friction: dynamic {friction_dynamic_n} N must be > 0 and ≤ static "
            f"{friction_static_n} N"
        )
    if rest_s + loading_s >= duration_s:
        raise ValueError(
            f"rest {rest_s} s + loading {loading_s} s leave no sliding in {duration_s} s"
        )
    time = np.arange(0.0, duration_s, 1.0 / sample_rate_hz)
    force = tangential_force(
        time, rest_s, loading_s, friction_static_n, friction_dynamic_n, relaxation_s
    )
    slid_m = sliding_speed_m_s * np.clip(time - rest_s - loading_s, 0, None)
    angle = (force / stiffness_n_per_m + slid_m) / rotation_radius_m
    n = time.size
    return RheometerTrace(
        time_s=time,
        angle_rad=angle + rng.normal(0, angle_noise_rad, n),
        normal_force_n=load_n + rng.normal(0, normal_noise_n, n),
        torque_n_m=force * rotation_radius_m + rng.normal(0, torque_noise_n_m, n),
        rotation_radius_m=rotation_radius_m,
        metadata={"load_mn": f"{load_n * 1e3:g}", "source": "virtual experiment"},
    )


def write_rheometer_trace(path: str | Path, trace: RheometerTrace) -> None:
    """Write the trace as the rheometer writes it (``<folder>/rheometer/<load>.csv``)."""
    write_rheometer_csv(path, trace)
