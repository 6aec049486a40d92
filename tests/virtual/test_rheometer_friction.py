"""Static and dynamic friction from rheometer traces (appendix B.1.2), against known truth."""

import dataclasses

import numpy as np
import pandas as pd
import pytest

from amontons.io.rheometer import RheometerError, read_rheometer_csv
from amontons.measure.friction import amontons_deviation, static_friction
from amontons.virtual.rheometer import rheometer_trace, write_rheometer_trace

LOAD, F_STATIC, F_DYNAMIC = 0.025, 0.010, 0.008  # N
RADIUS = 5e-3  # rotation radius, m
SPEED = 1e-5  # m/s
DURATION, PEAK_TIME = 20.0, 5.0  # s: 1 s rest + 4 s loading, then sliding to the end
# Torque noise 5e-7 N·m is 1 % of the 5e-5 N·m static peak; normal-force noise 0.2 mN.


def trace(seed: int, **changes):
    rng = np.random.default_rng(seed)
    return rheometer_trace(
        LOAD, F_STATIC, F_DYNAMIC, RADIUS, SPEED, DURATION, 100.0, rng=rng, **changes
    )


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_friction_speed_and_distance_within_2_percent(seed):
    # Over 50 seeds the static peak scatters by 0.5 % (bias −0.2 %), so 2 % is a ~4 σ bound;
    # speed and distance are good to 0.3 % (the distance includes the elastic recovery
    # (F_s − F_d)/k = 0.2 µm of 150 µm).
    result = static_friction(trace(seed))
    assert result.static_friction_n == pytest.approx(F_STATIC, rel=0.02)
    assert result.dynamic_friction_n == pytest.approx(F_DYNAMIC, rel=0.02)
    assert result.sliding_speed_m_s == pytest.approx(SPEED, rel=0.02)
    assert result.sliding_distance_m == pytest.approx(
        SPEED * (DURATION - 0.01 - PEAK_TIME), rel=0.02
    )
    assert result.normal_force_n == pytest.approx(LOAD, rel=0.002)
    assert result.peak_time_s == pytest.approx(PEAK_TIME, abs=0.1)
    assert result.static_coefficient == pytest.approx(F_STATIC / LOAD, rel=0.02)


def test_single_sample_spikes_do_not_make_the_peak():
    # Three +50 % spikes during loading: a plain maximum would report 1.5 × the truth; the
    # moving median ignores isolated samples.
    spiky = trace(3)
    torque = spiky.torque_n_m.copy()
    torque[[200, 300, 450]] += 0.5 * F_STATIC * RADIUS
    spiky = dataclasses.replace(spiky, torque_n_m=torque)
    assert torque.max() / RADIUS > 1.3 * F_STATIC
    assert static_friction(spiky).static_friction_n == pytest.approx(F_STATIC, rel=0.02)


def test_csv_round_trip_keeps_radius_and_values(tmp_path):
    original = trace(4)
    path = tmp_path / "rheometer" / "25.csv"
    write_rheometer_trace(path, original)
    assert path.read_text().startswith("# ")
    read = read_rheometer_csv(path)
    assert read.rotation_radius_m == pytest.approx(RADIUS, rel=1e-9)
    assert read.metadata["load_mn"] == "25"
    np.testing.assert_allclose(read.torque_n_m, original.torque_n_m, rtol=1e-8)
    assert static_friction(read).static_friction_n == pytest.approx(
        static_friction(original).static_friction_n, rel=1e-6
    )


def test_monotonically_rising_torque_has_no_peak():
    # A torque ramping up to the end of the record (with 1 % noise) never drops.
    base = trace(5)
    ramp = F_STATIC * RADIUS * base.time_s / DURATION
    noise = np.random.default_rng(5).normal(0, 5e-7, ramp.size)
    rising = dataclasses.replace(base, torque_n_m=ramp + noise)
    with pytest.raises(RheometerError, match="no static friction peak"):
        static_friction(rising, RADIUS)


def test_missing_column_names_file_and_column(tmp_path):
    path = tmp_path / "25.csv"
    rows = "".join(f"{i * 0.01},0,0.025\n" for i in range(20))
    path.write_text("# rotation_radius_mm: 5\ntime_s,angle_rad,normal_force_N\n" + rows)
    with pytest.raises(RheometerError, match=r"25\.csv: no column 'torque_N_m'"):
        read_rheometer_csv(path)


def test_missing_radius_metadata_is_refused(tmp_path):
    path = tmp_path / "25.csv"
    rows = "".join(f"{i * 0.01},0,0.025,0\n" for i in range(20))
    path.write_text("# load_mn: 25\ntime_s,angle_rad,normal_force_N,torque_N_m\n" + rows)
    with pytest.raises(RheometerError, match=r"25\.csv: no '# rotation_radius_mm"):
        read_rheometer_csv(path)


def test_amontons_deviation_table():
    # A ∝ F^(2/3) and F_f = τ·A with constant τ: μ/μ_ref = (F/25 mN)^(−1/3) exactly.
    force = np.array([0.1, 0.025, 0.05, 0.2])
    area = 1e-10 * (force / 0.025) ** (2 / 3)
    friction = 5e6 * area
    table = amontons_deviation(force, area, friction)
    assert isinstance(table, pd.DataFrame)
    assert list(table["normal_force_n"]) == sorted(force)
    np.testing.assert_allclose(
        table["mu_over_mu_ref"], (table["normal_force_n"] / 0.025) ** (-1 / 3)
    )
    np.testing.assert_allclose(table["shear_strength_over_ref"], 1.0)
    np.testing.assert_allclose(table["area_per_load_over_ref"], table["mu_over_mu_ref"])
    with pytest.raises(ValueError, match="no load within 10% of the reference 0.025 N"):
        amontons_deviation(force[[0, 2, 3]], area[[0, 2, 3]], friction[[0, 2, 3]])
