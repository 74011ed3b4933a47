"""Calibrations and noise figures out, in the formats other tools read."""

from .kalibr import KalibrImu, kalibr_imu, kalibr_imu_yaml

__all__ = ["KalibrImu", "kalibr_imu", "kalibr_imu_yaml"]
