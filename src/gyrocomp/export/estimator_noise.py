"""A noise model (:mod:`gyrocomp.measures.noise_model`) in each estimator's own units, from the bound that carries
white noise and random walk only (the form these estimators take).

Each conversion follows the consumer's code (docs/noise.md has the table with the source lines):

- Kalibr ``imu.yaml`` and OpenVINS ``kalibr_imu_chain.yaml``: the continuous-time densities N [rad/s/sqrt(Hz)]
  and K [rad/s^2/sqrt(Hz)] (OpenVINS ``ov_msckf/src/state/Propagator.cpp`` builds its discrete noise as
  ``sigma_w^2 / dt``, ``sigma_wb^2 / dt``, "continuous time noises to discrete").
- VINS-Fusion ``gyr_n``, ``gyr_w``, ``acc_n``, ``acc_w``: standard deviations per IMU sample
  (``vins_estimator/src/factor/integration_base.h``: the mid-point step adds ``(0.5 dt)^2`` times ``GYR_N^2`` for
  each of its two samples to the angle and ``dt^2 GYR_W^2`` to the bias), so for the same variance per step as the
  continuous model, ``gyr_n = N sqrt(2 / dt)`` and ``gyr_w = K / sqrt(dt)``; likewise for the accelerometer.
- ROS ``sensor_msgs/Imu``: ``angular_velocity_covariance`` and ``linear_acceleration_covariance`` are the
  variance of one sample about the true value [rad^2/s^2, m^2/s^4]: N^2 times the sample rate (the white part a
  sample carries; the bias is the estimator's state).
- PX4 EKF2 (``EKF2_GYR_NOISE``, ``EKF2_GYR_B_NOISE``, ``EKF2_ACC_NOISE``, ``EKF2_ACC_B_NOISE``) and ArduPilot EK3
  (``EK3_GYRO_P_NSE``, ``EK3_GBIAS_P_NSE``, ``EK3_ACC_P_NSE``, ``EK3_ABIAS_P_NSE``): each prediction step of the
  filter period dt adds ``(dt sigma)^2`` to the angle (velocity) variance and ``(dt sigma_b)^2`` to the rate
  (acceleration) bias variance (PX4 ``src/modules/ekf2/EKF/covariance.cpp``, ``predictCovariance``; ArduPilot
  ``libraries/AP_NavEKF3/AP_NavEKF3_core.cpp``, ``CovariancePrediction``, whose delta-angle bias gets
  ``(dt^2 sigma_b)^2``), so sigma = N / sqrt(dt) and sigma_b = K / sqrt(dt) at the filter's period (PX4
  ``EKF2_PREDICT_US``, default 10 ms; ArduPilot ``EKF_TARGET_DT``, 12 ms), clamped to the range each parameter
  accepts (their parameter definitions), with a warning naming what was clamped.
- JSON: the whole model (both bounds, the IEEE Std 952 fit, each log's bound) in the data's units.

With several axes of one sensor, the largest value is written: the conservative choice for a filter that takes
one number for all three.
"""

from __future__ import annotations

import json
import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass

from ..errors import DataQualityWarning, InputError, user_stacklevel
from ..measures.noise_model import NoiseModel, per_sample_covariance
from ..units import STANDARD_GRAVITY_M_PER_S2
from .encode import line_comment
from .kalibr import KalibrImu, kalibr_imu_yaml, warn_zero_walks

DEG_TO_RAD = math.pi / 180.0


@dataclass(frozen=True)
class ContinuousNoise:
    """The bound's white-noise densities and random walks in SI units, the largest over each sensor's axes.

    Attributes
    ----------
    gyro_noise_density_rad_per_s_per_sqrt_hz, gyro_random_walk_rad_per_s2_per_sqrt_hz : float or None
        N and K of the gyro axes (None without one).
    accel_noise_density_m_per_s2_per_sqrt_hz, accel_random_walk_m_per_s3_per_sqrt_hz : float or None
        N and K of the accelerometer axes (None without one).
    rate_hz : float
        The sample rate the logs were taken at [Hz].
    """

    gyro_noise_density_rad_per_s_per_sqrt_hz: float | None
    gyro_random_walk_rad_per_s2_per_sqrt_hz: float | None
    accel_noise_density_m_per_s2_per_sqrt_hz: float | None
    accel_random_walk_m_per_s3_per_sqrt_hz: float | None
    rate_hz: float


def continuous_noise(model: NoiseModel) -> ContinuousNoise:
    """The two-term bound of ``model`` in SI units (deg/s to rad/s, g to m/s^2), the largest over each sensor's
    axes.

    Parameters
    ----------
    model : NoiseModel
        The noise model of static logs.
    """

    def largest(sensor: str, attribute: str, factor: float) -> float | None:
        values = [getattr(a.bound, attribute) for a in model.axes.values() if a.sensor == sensor]
        return max(values) * factor if values else None

    g = STANDARD_GRAVITY_M_PER_S2
    return ContinuousNoise(
        largest("gyro", "white_noise_density", DEG_TO_RAD),
        largest("gyro", "random_walk", DEG_TO_RAD),
        largest("accel", "white_noise_density", g),
        largest("accel", "random_walk", g),
        model.rate_hz,
    )


def _need(value: float | None, what: str, target: str) -> float:
    if value is None:
        raise InputError(
            f"export {target}: the logs have no {what} axes; it needs them (name the columns with "
            "columns=, and analyse the accelerometer too)"
        )
    return value


def _warn_zero_walk(c: ContinuousNoise, consumer: str) -> None:
    """Kalibr and OpenVINS refuse a random walk of 0 (:func:`gyrocomp.export.kalibr.warn_zero_walks`)."""
    warn_zero_walks(
        f"export {consumer.lower()}",
        c.gyro_random_walk_rad_per_s2_per_sqrt_hz,
        c.accel_random_walk_m_per_s3_per_sqrt_hz,
        consumer,
    )


def kalibr_yaml(model: NoiseModel, rostopic: str = "/imu0") -> str:
    """Kalibr's ``imu.yaml`` (:func:`gyrocomp.export.kalibr.kalibr_imu_yaml`'s layout): continuous-time densities
    [rad/s/sqrt(Hz), m/s^2/sqrt(Hz)] and random walks of the bound."""
    c = continuous_noise(model)
    _warn_zero_walk(c, "Kalibr")
    imu = KalibrImu(
        _need(c.gyro_noise_density_rad_per_s_per_sqrt_hz, "gyro", "kalibr"),
        c.gyro_random_walk_rad_per_s2_per_sqrt_hz,
        c.accel_noise_density_m_per_s2_per_sqrt_hz,
        c.accel_random_walk_m_per_s3_per_sqrt_hz,
        c.rate_hz,
        rostopic,
    )
    return kalibr_imu_yaml(
        imu,
        "the white-noise + random-walk bound of the measured Allan deviation (at or above "
        "the upper end of its 95 % interval at every averaging time); continuous-time values",
    )


def openvins_yaml(model: NoiseModel, rostopic: str = "/imu0") -> str:
    """OpenVINS's ``kalibr_imu_chain.yaml`` (``%YAML:1.0``, an ``imu0`` block): the same continuous values."""
    c = continuous_noise(model)
    _warn_zero_walk(c, "OpenVINS")
    gyro_n = _need(c.gyro_noise_density_rad_per_s_per_sqrt_hz, "gyro", "openvins")
    accel_n = _need(c.accel_noise_density_m_per_s2_per_sqrt_hz, "accelerometer", "openvins")
    return (
        "\n".join(
            [
                "%YAML:1.0 # written by gyrocomp: the white-noise + random-walk bound of the measured Allan deviation",
                "",
                "imu0:",
                "  T_i_b:",
                *(f"    - [{', '.join('1.0' if i == j else '0.0' for j in range(4))}]" for i in range(4)),
                f"  accelerometer_noise_density: {accel_n:.6e}  # [m/s^2/sqrt(Hz)]",
                f"  accelerometer_random_walk: {c.accel_random_walk_m_per_s3_per_sqrt_hz:.6e}  # [m/s^3/sqrt(Hz)]",
                f"  gyroscope_noise_density: {gyro_n:.6e}  # [rad/s/sqrt(Hz)]",
                f"  gyroscope_random_walk: {c.gyro_random_walk_rad_per_s2_per_sqrt_hz:.6e}  # [rad/s^2/sqrt(Hz)]",
                f"  rostopic: {json.dumps(rostopic)}",
                "  time_offset: 0.0",
                f"  update_rate: {c.rate_hz:.6g}",
                '  model: "kalibr"',
            ]
        )
        + "\n"
    )


def vins_values(model: NoiseModel) -> dict[str, float]:
    """VINS-Fusion's ``acc_n``, ``gyr_n``, ``acc_w``, ``gyr_w``: per-sample standard deviations at the logs' rate
    (see the module): n = N sqrt(2 rate), w = K sqrt(rate).

    Parameters
    ----------
    model : NoiseModel
        The noise model of static logs (gyro and accelerometer axes).
    """
    c = continuous_noise(model)
    gyro_n = _need(c.gyro_noise_density_rad_per_s_per_sqrt_hz, "gyro", "vins")
    accel_n = _need(c.accel_noise_density_m_per_s2_per_sqrt_hz, "accelerometer", "vins")
    return {
        "acc_n": accel_n * math.sqrt(2.0 * c.rate_hz),
        "gyr_n": gyro_n * math.sqrt(2.0 * c.rate_hz),
        "acc_w": c.accel_random_walk_m_per_s3_per_sqrt_hz * math.sqrt(c.rate_hz),
        "gyr_w": c.gyro_random_walk_rad_per_s2_per_sqrt_hz * math.sqrt(c.rate_hz),
    }


def vins_yaml(model: NoiseModel, rostopic: str = "/imu0") -> str:
    """The IMU lines of a VINS-Fusion configuration file."""
    v = vins_values(model)
    return (
        "\n".join(
            [
                "# "
                + line_comment(
                    f"written by gyrocomp: per-sample standard deviations at {model.rate_hz:g} Hz "
                    "(integration_base.h's discretization), from the white-noise + random-walk bound"
                ),
                f"imu_topic: {json.dumps(rostopic)}",
                f"acc_n: {v['acc_n']:.6e}  # accelerometer measurement noise [m/s^2]",
                f"gyr_n: {v['gyr_n']:.6e}  # gyroscope measurement noise [rad/s]",
                f"acc_w: {v['acc_w']:.6e}  # accelerometer bias random walk [m/s^3]",
                f"gyr_w: {v['gyr_w']:.6e}  # gyroscope bias random walk [rad/s^2]",
            ]
        )
        + "\n"
    )


def ros_covariances(model: NoiseModel, rate_hz: float | None = None) -> dict[str, list[float]]:
    """``sensor_msgs/Imu``'s ``angular_velocity_covariance`` [rad^2/s^2] and ``linear_acceleration_covariance``
    [m^2/s^4] (row-major 3x3, diagonal), per sample at ``rate_hz`` [Hz] (default the logs' rate): N^2 rate."""
    c = continuous_noise(model)
    rate = model.rate_hz if rate_hz is None else rate_hz
    out = {}
    for key, density in (
        ("angular_velocity_covariance", c.gyro_noise_density_rad_per_s_per_sqrt_hz),
        ("linear_acceleration_covariance", c.accel_noise_density_m_per_s2_per_sqrt_hz),
    ):
        if density is not None:
            out[key] = per_sample_covariance(density, rate)
    return out


def ros_yaml(model: NoiseModel, rostopic: str = "/imu0") -> str:
    """The covariances as YAML parameters of an IMU driver node."""
    lines = [
        f"# written by gyrocomp: per-sample variances at {model.rate_hz:g} Hz (N^2 rate) for {line_comment(rostopic)}"
    ]
    for key, values in ros_covariances(model).items():
        lines.append(f"{key}: [{', '.join(f'{v:.6e}' for v in values)}]")
    return "\n".join(lines) + "\n"


def model_json(model: NoiseModel, rostopic: str = "/imu0") -> str:
    """The whole model as JSON (the data's units; each term's name says it)."""
    return json.dumps(model.to_dict(), indent=1) + "\n"


#: PX4 EKF2's prediction period by default (``EKF2_PREDICT_US`` = 10000 us) [s]
PX4_PREDICT_PERIOD_S = 0.01
#: ArduPilot EK3's update period (``EKF_TARGET_DT``) [s]
ARDUPILOT_FILTER_PERIOD_S = 0.012
#: the range each EKF noise parameter accepts (PX4 ``src/modules/ekf2/module.yaml``, ``params_gyro_bias.yaml``,
#: ``params_accel_bias.yaml``; ArduPilot ``libraries/AP_NavEKF3/AP_NavEKF3.cpp`` ``@Range``)
NOISE_PARAMETER_RANGES = {
    "EKF2_GYR_NOISE": (0.0001, 0.1),
    "EKF2_GYR_B_NOISE": (0.0, 0.01),
    "EKF2_ACC_NOISE": (0.01, 1.0),
    "EKF2_ACC_B_NOISE": (0.0, 0.01),
    "EK3_GYRO_P_NSE": (0.0001, 0.1),
    "EK3_GBIAS_P_NSE": (0.00001, 0.001),
    "EK3_ACC_P_NSE": (0.01, 1.0),
    "EK3_ABIAS_P_NSE": (0.00001, 0.02),
}
_AUTOPILOT_NAMES = {
    "px4": ("EKF2_GYR_NOISE", "EKF2_GYR_B_NOISE", "EKF2_ACC_NOISE", "EKF2_ACC_B_NOISE"),
    "ardupilot": ("EK3_GYRO_P_NSE", "EK3_GBIAS_P_NSE", "EK3_ACC_P_NSE", "EK3_ABIAS_P_NSE"),
}


def autopilot_noise_parameters(
    model: NoiseModel, target: str, filter_period_s: float | None = None
) -> dict[str, float]:
    """An autopilot EKF's IMU noise parameters: N / sqrt(dt) and K / sqrt(dt) at its filter period dt [s]
    (see the module), clamped to each parameter's range with a warning.

    Parameters
    ----------
    model : NoiseModel
        The noise model of static logs.
    target : {"px4", "ardupilot"}
        The autopilot.
    filter_period_s : float, optional
        The EKF's prediction period [s] (default PX4's 0.01 s, ArduPilot's 0.012 s).
    """
    if target not in _AUTOPILOT_NAMES:
        raise InputError(f"target: {target!r}; use px4 or ardupilot")
    dt = (
        (PX4_PREDICT_PERIOD_S if target == "px4" else ARDUPILOT_FILTER_PERIOD_S)
        if filter_period_s is None
        else filter_period_s
    )
    if not (isinstance(dt, (int, float)) and 0 < dt < 1):
        raise InputError(f"filter_period_s: a period under 1 s, got {dt!r}")
    c = continuous_noise(model)
    values = (
        c.gyro_noise_density_rad_per_s_per_sqrt_hz,
        c.gyro_random_walk_rad_per_s2_per_sqrt_hz,
        c.accel_noise_density_m_per_s2_per_sqrt_hz,
        c.accel_random_walk_m_per_s3_per_sqrt_hz,
    )
    out = {}
    for name, density in zip(_AUTOPILOT_NAMES[target], values):
        if density is None:
            continue
        value = density / math.sqrt(dt)
        low, high = NOISE_PARAMETER_RANGES[name]
        if not low <= value <= high:
            clamped = min(max(value, low), high)
            warnings.warn(
                f"export {target}: {name} would be {value:.6g}, outside the {low:g}..{high:g} the autopilot "
                f"accepts; written as {clamped:g}",
                DataQualityWarning,
                stacklevel=user_stacklevel(),
            )
            value = clamped
        out[name] = value
    return out


def px4_noise_params(model: NoiseModel, rostopic: str = "/imu0") -> str:
    """PX4's EKF2 noise parameters as a QGroundControl parameter file (vehicle 1, component 1, float32)."""
    values = autopilot_noise_parameters(model, "px4")
    lines = [
        f"# PX4 EKF2 IMU noise written by gyrocomp from the white-noise + random-walk bound, at the "
        f"{PX4_PREDICT_PERIOD_S * 1e6:.0f} us prediction period (EKF2_PREDICT_US)",
        "# Vehicle-Id Component-Id Name Value Type",
    ]
    lines += [f"1\t1\t{name}\t{value:.6g}\t9" for name, value in values.items()]
    return "\n".join(lines) + "\n"


def ardupilot_noise_params(model: NoiseModel, rostopic: str = "/imu0") -> str:
    """ArduPilot's EK3 noise parameters (``NAME VALUE`` per line)."""
    values = autopilot_noise_parameters(model, "ardupilot")
    lines = [
        f"# ArduPilot EK3 IMU noise written by gyrocomp from the white-noise + random-walk bound, at the "
        f"{ARDUPILOT_FILTER_PERIOD_S * 1e3:g} ms filter period (EKF_TARGET_DT)"
    ]
    lines += [f"{name} {value:.6g}" for name, value in values.items()]
    return "\n".join(lines) + "\n"


#: the noise exports, by the name ``gyrocomp noise --export`` takes: text of (model, rostopic)
NOISE_EXPORTS: dict[str, Callable[[NoiseModel, str], str]] = {
    "kalibr": kalibr_yaml,
    "openvins": openvins_yaml,
    "vins": vins_yaml,
    "ros": ros_yaml,
    "px4": px4_noise_params,
    "ardupilot": ardupilot_noise_params,
    "json": model_json,
}


__all__ = [
    "ARDUPILOT_FILTER_PERIOD_S",
    "ContinuousNoise",
    "NOISE_EXPORTS",
    "NOISE_PARAMETER_RANGES",
    "PX4_PREDICT_PERIOD_S",
    "ardupilot_noise_params",
    "autopilot_noise_parameters",
    "continuous_noise",
    "kalibr_yaml",
    "model_json",
    "openvins_yaml",
    "px4_noise_params",
    "ros_covariances",
    "ros_yaml",
    "vins_values",
    "vins_yaml",
]
