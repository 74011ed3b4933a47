"""The pipelines: how the models of each effect are combined and fitted, recordings in, a frozen
:class:`gyrocomp.calibration.Calibration` out.

- :mod:`.fit`: :func:`gyrocomp.fit`, the one way to fit (typed options, the channel explicit);
- :mod:`.options`: the typed options of a fit (:class:`FitOptions`, :class:`Polynomial`, :class:`Network`);
- :mod:`.pipelines`: the cascade and the one-network pipeline, per channel;
- :mod:`.field`: calibration without a chamber, from the still moments of everyday logs.

The curves a calibration holds are in :mod:`gyrocomp.curves`, their estimators in :mod:`gyrocomp.fitting`.
"""

from ..curves.polynomial import PolynomialCurve
from ..fitting.polynomial_model import PolynomialTemperatureModel

__all__ = ["PolynomialCurve", "PolynomialTemperatureModel"]
