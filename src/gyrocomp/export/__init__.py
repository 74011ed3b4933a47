"""Calibrations and noise figures out, in the formats other tools read."""

from .autopilot import (ardupilot_parameters, ardupilot_params_file, installed_calibration, px4_parameters,
                        px4_params_file)
from .formats import EXPORTERS, ExportOptions, Exported, Exporter, export_to, register
from .kalibr import KalibrImu, kalibr_imu, kalibr_imu_yaml

__all__ = ["EXPORTERS", "ExportOptions", "Exported", "Exporter", "KalibrImu", "export_to", "register", "ardupilot_parameters", "ardupilot_params_file", "installed_calibration", "kalibr_imu", "kalibr_imu_yaml",
           "px4_parameters", "px4_params_file"]
