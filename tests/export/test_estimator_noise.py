"""A noise model in each estimator's units: each export read back (round trip) against the continuous bound,
and each conversion checked against what the consumer's code does with the number (a per-step variance, or a
per-sample variance of simulated white noise)."""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest

from gyrocomp.allan import allan_deviation
from gyrocomp.errors import DataQualityWarning, InputError
from gyrocomp.export.estimator_noise import (
    NOISE_EXPORTS,
    continuous_noise,
    kalibr_yaml,
    openvins_yaml,
    ros_covariances,
    vins_values,
    vins_yaml,
)
from gyrocomp.measures.noise import analyse_noise
from gyrocomp.measures.noise_model import noise_model
from gyrocomp.simulation import simulate
from gyrocomp.units import STANDARD_GRAVITY_M_PER_S2

RATE_HZ = 100.0


def _values(text: str) -> dict[str, str]:
    """``key: value  # comment`` lines of a flat (or one-block) YAML file."""
    out = {}
    for line in text.splitlines():
        body = line.split("#", 1)[0].strip()
        if ":" in body and not body.endswith(":"):
            key, value = body.split(":", 1)
            out[key.strip()] = value.strip()
    return out


@pytest.fixture(scope="module")
def model():
    rec = simulate("mti10", profile="static", duration_s=1200, rate_hz=RATE_HZ, seed=3).recording
    return noise_model(analyse_noise(rec, with_accel=True))


def test_every_export_writes_and_reads_back_the_bound_in_si_units(model):
    c = continuous_noise(model)
    gyro_n = max(a.bound.white_noise_density for a in model.axes.values() if a.sensor == "gyro")
    accel_k = max(a.bound.random_walk for a in model.axes.values() if a.sensor == "accel")
    assert c.gyro_noise_density_rad_per_s_per_sqrt_hz == pytest.approx(math.radians(gyro_n), rel=1e-12)
    assert c.accel_random_walk_m_per_s3_per_sqrt_hz == pytest.approx(accel_k * STANDARD_GRAVITY_M_PER_S2, rel=1e-12)
    for text in (kalibr_yaml(model, "/imu"), openvins_yaml(model, "/imu")):
        v = _values(text)
        assert float(v["gyroscope_noise_density"]) == pytest.approx(c.gyro_noise_density_rad_per_s_per_sqrt_hz, 1e-6)
        assert float(v["gyroscope_random_walk"]) == pytest.approx(c.gyro_random_walk_rad_per_s2_per_sqrt_hz, 1e-6)
        assert float(v["accelerometer_noise_density"]) == pytest.approx(
            c.accel_noise_density_m_per_s2_per_sqrt_hz, 1e-6
        )
        assert float(v["update_rate"]) == RATE_HZ and json.loads(v["rostopic"]) == "/imu"
    assert openvins_yaml(model).startswith("%YAML:1.0") and "\nimu0:\n" in openvins_yaml(model)
    v = _values(vins_yaml(model))
    for key, value in vins_values(model).items():
        assert float(v[key]) == pytest.approx(value, rel=1e-6)
    back = json.loads(NOISE_EXPORTS["json"](model, "/imu0"))
    assert back["format"] == "gyrocomp-noise-model" and set(back["axes"]) == set(model.axes)
    assert (
        back["axes"]["gyro_x"]["bound"]["white_noise_density_u_per_sqrt_hz"]
        == model.axes["gyro_x"].bound.white_noise_density
    )
    log, written = model.axes["gyro_x"].logs[0], back["axes"]["gyro_x"]["logs"][0]["bound_with_markov"]
    assert [(t["sigma_u"], t["time_constant_s"]) for t in written["gauss_markov"]] == list(log.markov.markov)
    assert written["white_noise_density_u_per_sqrt_hz"] == log.markov.white_noise_density


def test_vins_numbers_give_its_mid_point_step_the_continuous_models_variance(model):
    """integration_base.h: the angle gets (0.5 dt)^2 GYR_N^2 from each of the step's two samples and the bias dt^2
    GYR_W^2; the continuous model gives N^2 dt and K^2 dt per step."""
    c, v, dt = continuous_noise(model), vins_values(model), 1.0 / RATE_HZ
    assert 2 * (0.5 * dt) ** 2 * v["gyr_n"] ** 2 == pytest.approx(c.gyro_noise_density_rad_per_s_per_sqrt_hz**2 * dt)
    assert dt**2 * v["gyr_w"] ** 2 == pytest.approx(c.gyro_random_walk_rad_per_s2_per_sqrt_hz**2 * dt)
    assert 2 * (0.5 * dt) ** 2 * v["acc_n"] ** 2 == pytest.approx(c.accel_noise_density_m_per_s2_per_sqrt_hz**2 * dt)


def test_the_ros_covariance_is_the_variance_of_one_sample_of_white_noise_of_that_density(model):
    cov = ros_covariances(model)
    density = continuous_noise(model).gyro_noise_density_rad_per_s_per_sqrt_hz
    white = np.random.default_rng(0).normal(size=200_000) * density * math.sqrt(RATE_HZ)  # as the simulator draws
    # its Allan deviation at one sample is the density's N / sqrt(tau): the same white noise
    r = allan_deviation(white, RATE_HZ, taus=np.array([1.0 / RATE_HZ]))
    assert r.deviation[0] == pytest.approx(density * math.sqrt(RATE_HZ), rel=0.01)
    assert cov["angular_velocity_covariance"][0] == pytest.approx(np.var(white), rel=0.02)
    assert (
        cov["angular_velocity_covariance"][1] == 0.0
        and cov["angular_velocity_covariance"][4] == cov["angular_velocity_covariance"][8]
    )
    slower = ros_covariances(model, rate_hz=RATE_HZ / 2)
    assert slower["angular_velocity_covariance"][0] == pytest.approx(cov["angular_velocity_covariance"][0] / 2)
    from gyrocomp.export.estimator_noise import ros_yaml

    written = ros_yaml(model, "/imu\nangular_velocity_covariance: [0]")  # a topic cannot add a key
    assert [line.split(":")[0] for line in written.splitlines() if not line.startswith("#")] == [
        "angular_velocity_covariance",
        "linear_acceleration_covariance",
    ]
    with pytest.raises(InputError, match=r"rate_hz: a positive number of Hz, got -1"):
        ros_covariances(model, rate_hz=-1)


def test_a_consumer_that_needs_the_accelerometer_says_so():
    rec = simulate("mti10", profile="static", duration_s=600, rate_hz=RATE_HZ, seed=3).recording
    gyro_only = noise_model(analyse_noise(rec))
    assert "no accelerometer columns in the log" in kalibr_yaml(gyro_only)
    with pytest.raises(InputError, match=r"export vins: the logs have no accelerometer axes; it needs them"):
        vins_yaml(gyro_only)


def test_the_autopilot_parameters_give_each_prediction_step_the_continuous_variance(model):
    """PX4 and ArduPilot add (dt sigma)^2 to the angle and (dt sigma_b)^2 to the rate bias per step: at their
    filter period that is N^2 dt and K^2 dt; the files read back to the values."""
    from gyrocomp.export.estimator_noise import (
        ARDUPILOT_FILTER_PERIOD_S,
        PX4_PREDICT_PERIOD_S,
        autopilot_noise_parameters,
    )

    c = continuous_noise(model)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a clamped accelerometer value is said; checked below
        px4 = autopilot_noise_parameters(model, "px4")
        ardupilot = autopilot_noise_parameters(model, "ardupilot")
        px4_text = NOISE_EXPORTS["px4"](model, "/imu0")
        ardupilot_text = NOISE_EXPORTS["ardupilot"](model, "/imu0")
    for values, dt, gyro, bias in (
        (px4, PX4_PREDICT_PERIOD_S, "EKF2_GYR_NOISE", "EKF2_GYR_B_NOISE"),
        (ardupilot, ARDUPILOT_FILTER_PERIOD_S, "EK3_GYRO_P_NSE", "EK3_GBIAS_P_NSE"),
    ):
        assert (dt * values[gyro]) ** 2 == pytest.approx(c.gyro_noise_density_rad_per_s_per_sqrt_hz**2 * dt)
        assert (dt * values[bias]) ** 2 == pytest.approx(c.gyro_random_walk_rad_per_s2_per_sqrt_hz**2 * dt)
    rows = [line.split("\t") for line in px4_text.splitlines() if not line.startswith("#")]
    assert {name: float(value) for _, _, name, value, _ in rows} == pytest.approx(px4, rel=1e-5)
    pairs = [line.split() for line in ardupilot_text.splitlines() if not line.startswith("#")]
    assert {name: float(value) for name, value in pairs} == pytest.approx(ardupilot, rel=1e-5)


def test_a_value_outside_what_the_autopilot_accepts_is_clamped_and_said(model):
    from gyrocomp.export.estimator_noise import NOISE_PARAMETER_RANGES, autopilot_noise_parameters

    with pytest.warns(
        DataQualityWarning,
        match=r"export px4: EKF2_GYR_NOISE would be [0-9.e-]+, outside the "
        r"0.0001..0.1 the autopilot accepts; written as 0.1",
    ):
        values = autopilot_noise_parameters(model, "px4", filter_period_s=1e-9)
    assert values["EKF2_GYR_NOISE"] == NOISE_PARAMETER_RANGES["EKF2_GYR_NOISE"][1]
    with pytest.raises(InputError, match=r"target: 'inav'; use px4 or ardupilot"):
        autopilot_noise_parameters(model, "inav")
