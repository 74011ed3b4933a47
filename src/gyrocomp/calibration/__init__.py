"""The frozen, versioned calibration (:mod:`.calibration`: the model file), its schema, triads and fit report, and its
application (:mod:`.compensate`)."""

from __future__ import annotations

from .calibration import AxisCalibration, AxisSummary, Calibration, FORMAT_NAME, SCHEMA_VERSION

__all__ = ["AxisCalibration", "AxisSummary", "Calibration", "FORMAT_NAME", "SCHEMA_VERSION"]
