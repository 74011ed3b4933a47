"""What a recording is: :class:`~gyrocomp.recording.recording.Recording`, one power-on's samples in internal units [s,
deg/s, g, degC]."""

from __future__ import annotations

from .recording import (
    ACCEL_AXES,
    Gap,
    GAP_FACTOR,
    Gaps,
    GYRO_AXES,
    nominal_rate_hz,
    POSSIBLE,
    Recording,
    REFERENCE_RATE_AXES,
    TEMPERATURE_COLUMN,
)

__all__ = [
    "ACCEL_AXES",
    "GAP_FACTOR",
    "GYRO_AXES",
    "Gap",
    "Gaps",
    "POSSIBLE",
    "REFERENCE_RATE_AXES",
    "Recording",
    "TEMPERATURE_COLUMN",
    "nominal_rate_hz",
]
