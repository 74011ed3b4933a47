"""Fitted models, one module per effect, and the pipelines that combine them.

- :mod:`.temperature`: the bias polynomial in temperature, order by cross-validation;
- :mod:`.mlp`: the thesis's small back-propagation network (Levenberg-Marquardt);
- :mod:`.hysteresis`: the turning-point hysteresis curve;
- :mod:`.acceleration`: g-sensitivity (the 3x3 matrix G, the acceleration network);
- :mod:`.thermal`: the joint fit of polynomial, thermal lag, hysteresis and G, chosen by the data;
- :mod:`.pipelines`: ``fit_calibration`` / ``fit_pipeline`` / ``fit_channels``, recordings in, a
  :class:`gyrocomp.calibration.Calibration` out.
"""

from .polynomial_fit import PolynomialTemperatureModel
from .temperature import PolynomialBias

__all__ = ["PolynomialBias", "PolynomialTemperatureModel"]
