"""Kalibr's ``imu.yaml`` from a noise analysis.

Kalibr (ethz-asl/kalibr, wiki "IMU Noise Model") takes the continuous-time white-noise densities and
bias random walks: gyroscope_noise_density [rad/s/sqrt(Hz)] = N, gyroscope_random_walk
[rad/s^2/sqrt(Hz)] = K, accelerometer_noise_density [m/s^2/sqrt(Hz)], accelerometer_random_walk
[m/s^3/sqrt(Hz)], plus update_rate [Hz] and rostopic. They are the N and K of the Allan analysis;
Kalibr derives the discrete-time values itself (noise density times sqrt(update_rate), random walk
divided by it). With several axes, the largest value is written, which is the conservative choice.
"""

from __future__ import annotations

import json
import math
import warnings
from dataclasses import dataclass

from ..errors import DataQualityWarning, InputError, user_stacklevel
from ..measures.noise import NoiseAnalysis
from ..units import STANDARD_GRAVITY_M_PER_S2

DEG_TO_RAD = math.pi / 180.0


@dataclass(frozen=True)
class KalibrImu:
    """The values of a Kalibr ``imu.yaml``; accelerometer values are None when there are no accelerometer axes."""

    gyroscope_noise_density_rad_per_s_per_sqrt_hz: float
    gyroscope_random_walk_rad_per_s2_per_sqrt_hz: float
    accelerometer_noise_density_m_per_s2_per_sqrt_hz: float | None
    accelerometer_random_walk_m_per_s3_per_sqrt_hz: float | None
    update_rate_hz: float
    rostopic: str


def warn_zero_walks(source: str, gyro_walk: float | None, accel_walk: float | None, consumer: str = "Kalibr") -> None:
    """Kalibr (and OpenVINS, which reads its file) refuse a random walk of 0: say so for each sensor whose random
    walk [any unit] is 0 (None: no such sensor)."""
    for label, walk in (("gyroscope", gyro_walk), ("accelerometer", accel_walk)):
        if walk is not None and walk == 0.0:
            warnings.warn(
                f"{source}: no {label} random walk is visible in this log (K = 0); {consumer} needs a "
                "non-zero value: record a longer static log (hours)",
                DataQualityWarning,
                stacklevel=user_stacklevel(),
            )


def kalibr_imu(analysis: NoiseAnalysis, rostopic: str = "/imu0") -> KalibrImu:
    """Kalibr values from the gyro (and accelerometer) axes of ``analysis``; warns when a random walk is zero."""
    gyros = [a.noise for a in analysis.axes.values() if a.sensor == "gyro"]
    accels = [a.noise for a in analysis.axes.values() if a.sensor == "accel"]
    if not gyros:
        raise InputError("kalibr: needs at least one gyro axis; add one to axes=")
    gyro_walk = max(g.rrw_dps_sqrt_hz for g in gyros) * DEG_TO_RAD
    accel_walk = max(a.random_walk_m_per_s3_per_sqrt_hz for a in accels) if accels else None
    if not accels:
        warnings.warn(
            f"{analysis.source}: no accelerometer axes, so imu.yaml has gyroscope values only; "
            "Kalibr needs both (name the accelerometer columns with columns=)",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
    warn_zero_walks(analysis.source, gyro_walk, accel_walk)
    return KalibrImu(
        gyroscope_noise_density_rad_per_s_per_sqrt_hz=max(g.noise_density_dps_per_sqrt_hz for g in gyros) * DEG_TO_RAD,
        gyroscope_random_walk_rad_per_s2_per_sqrt_hz=gyro_walk,
        accelerometer_noise_density_m_per_s2_per_sqrt_hz=(
            max(a.noise_density_g_per_sqrt_hz for a in accels) * STANDARD_GRAVITY_M_PER_S2 if accels else None
        ),
        accelerometer_random_walk_m_per_s3_per_sqrt_hz=accel_walk,
        update_rate_hz=analysis.rate_hz,
        rostopic=rostopic,
    )


#: what the values of gyrocomp's Kalibr file are, by default: the IEEE Std 952 fit's
ALLAN_FIT = "continuous-time noise densities and bias random walks (Allan analysis)"


def kalibr_imu_yaml(imu: KalibrImu, source: str = ALLAN_FIT) -> str:
    """The YAML text, laid out like Kalibr's own example ``imu.yaml``; ``source`` says what the values are (a
    comment line), and the topic is written as a quoted string."""
    lines = [f"# written by gyrocomp: {source}"]
    if imu.accelerometer_noise_density_m_per_s2_per_sqrt_hz is not None:
        lines += [
            "#Accelerometers",
            f"accelerometer_noise_density: {imu.accelerometer_noise_density_m_per_s2_per_sqrt_hz:.6e}  "
            "#Noise density (continuous-time) [m/s^2/sqrt(Hz)]",
            f"accelerometer_random_walk:   {imu.accelerometer_random_walk_m_per_s3_per_sqrt_hz:.6e}  "
            "#Bias random walk [m/s^3/sqrt(Hz)]",
        ]
    else:
        lines.append(
            "# no accelerometer columns in the log: add accelerometer_noise_density and "
            "accelerometer_random_walk before running Kalibr"
        )
    lines += [
        "#Gyroscopes",
        f"gyroscope_noise_density:     {imu.gyroscope_noise_density_rad_per_s_per_sqrt_hz:.6e}  "
        "#Noise density (continuous-time) [rad/s/sqrt(Hz)]",
        f"gyroscope_random_walk:       {imu.gyroscope_random_walk_rad_per_s2_per_sqrt_hz:.6e}  "
        "#Bias random walk [rad/s^2/sqrt(Hz)]",
        f"rostopic:                    {json.dumps(imu.rostopic)}  #the IMU ROS topic",
        f"update_rate:                 {imu.update_rate_hz:.6g}  #Hz (for discretization of the values above)",
    ]
    return "\n".join(lines) + "\n"
