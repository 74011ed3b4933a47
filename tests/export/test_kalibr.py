"""Kalibr imu.yaml: values, units and warnings."""

import json
import math

import numpy as np
import pytest

from gyrocomp.errors import DataQualityWarning, InputError
from gyrocomp.export.kalibr import kalibr_imu, kalibr_imu_yaml
from gyrocomp.measures.noise import analyse_noise

from ..conftest import static_recording


def parse(text):
    values = {}
    for line in text.splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            key, value = (part.strip() for part in line.split(":", 1))
            values[key] = value
    return values


def test_values_are_the_continuous_time_densities_in_si_units():
    rec = static_recording()
    analysis = analyse_noise(rec, ["gyro_x", "gyro_z", "accel_x", "accel_y", "accel_z"])
    with pytest.warns(DataQualityWarning) as caught:
        imu = kalibr_imu(analysis, rostopic="/imu/data")
    said = " | ".join(str(w.message) for w in caught)
    assert "no gyroscope random walk is visible" in said and "no accelerometer random walk is visible" in said
    gyro_n = max(analysis.axes[a].noise.noise_density_dps_per_sqrt_hz for a in ("gyro_x", "gyro_z"))
    assert imu.gyroscope_noise_density_rad_per_s_per_sqrt_hz == pytest.approx(gyro_n * math.pi / 180)
    accel_n = max(analysis.axes[a].noise.noise_density_g_per_sqrt_hz for a in ("accel_x", "accel_y", "accel_z"))
    assert imu.accelerometer_noise_density_m_per_s2_per_sqrt_hz == pytest.approx(accel_n * 9.80665)
    values = parse(kalibr_imu_yaml(imu))
    assert set(values) == {
        "accelerometer_noise_density",
        "accelerometer_random_walk",
        "gyroscope_noise_density",
        "gyroscope_random_walk",
        "rostopic",
        "update_rate",
    }
    assert float(values["gyroscope_noise_density"]) == pytest.approx(0.01 * math.pi / 180, rel=0.03)
    assert float(values["update_rate"]) == 50.0 and json.loads(values["rostopic"]) == "/imu/data"


def test_random_walk_reaches_the_file():
    rate_hz = 10.0
    rec = static_recording(n=200_000, rate_hz=rate_hz)
    k = 1e-4  # [deg/s/sqrt(s)]
    walk = np.cumsum(np.random.default_rng(2).standard_normal(rec.n_samples)) * k / math.sqrt(rate_hz)
    rec = rec.with_gyro(rec.gyro_dps + walk[:, None])
    analysis = analyse_noise(rec, ["gyro_z", "accel_z"])
    with pytest.warns(DataQualityWarning, match=r"no accelerometer random walk"):
        imu = kalibr_imu(analysis)
    assert imu.gyroscope_random_walk_rad_per_s2_per_sqrt_hz == pytest.approx(k * math.pi / 180, rel=0.3)


def test_gyro_only_logs_say_what_is_missing():
    analysis = analyse_noise(static_recording(), ["gyro_z"])
    with pytest.warns(DataQualityWarning) as caught:
        text = kalibr_imu_yaml(kalibr_imu(analysis))
    said = " | ".join(str(w.message) for w in caught)
    assert "no accelerometer axes, so imu.yaml has gyroscope values only" in said
    assert "no gyroscope random walk is visible" in said
    assert "accelerometer_noise_density:" not in text and "no accelerometer columns in the log" in text
    with pytest.raises(InputError, match=r"kalibr: needs at least one gyro axis"):
        kalibr_imu(analyse_noise(static_recording(), ["accel_z"]))
