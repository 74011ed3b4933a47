"""Calibrations and noise figures out, in the formats other tools read."""

from .autopilot import (
    ardupilot_parameters,
    ardupilot_params_file,
    installed_calibration,
    px4_parameters,
    px4_params_file,
)
from .formats import EXPORTERS, ExportOptions, Exported, Exporter, export_to, format_of, register
from .kalibr import KalibrImu, kalibr_imu, kalibr_imu_yaml

__all__ = [
    "EXPORTERS",
    "ExportOptions",
    "Exported",
    "Exporter",
    "KalibrImu",
    "ardupilot_parameters",
    "ardupilot_params_file",
    "export_to",
    "format_of",
    "installed_calibration",
    "kalibr_imu",
    "kalibr_imu_yaml",
    "px4_parameters",
    "px4_params_file",
    "register",
]
