"""Fitted models: temperature (and, in later releases, hysteresis, acceleration) and pipelines.

``gyrocomp.models.pipelines.fit_calibration`` turns recordings into a Calibration.
"""

from .temperature import PolynomialBias, PolynomialTemperatureModel, parse_temperature_option

__all__ = ["PolynomialBias", "PolynomialTemperatureModel", "parse_temperature_option"]
