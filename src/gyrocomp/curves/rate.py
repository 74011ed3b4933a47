"""A bias in the temperature's rate of change: the thermal gradient across a part while its temperature moves.

    offset = k r,   r = (T_m - T_f) / s,   dT_f/dt = (T_m - T_f) / s

with T_m the model temperature (reported, or through the thermal lag), s the smoothing time constant [s] and k the
axis's sensitivity to the rate [the axis's unit per degC/s]. On a steady ramp of rho degC/s the offset settles to
k rho; at a hold it fades as exp(-t / s). Unlike a lag of the temperature curve (whose offset on a ramp is the
curve's slope times rho times the lag, so it vanishes where the curve is flat and changes sign with the slope), the
offset is the same at every temperature: a gradient between the die and the package, not a delay of the die.
The rate is :func:`gyrocomp.effects.temperature_rate`; this module holds the fitted term and its fit column.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ..c_literals import c_number
from ..effects import temperature_rate
from ..errors import InputError


@dataclass(frozen=True)
class TemperatureRateTerm:
    """A fitted temperature-rate term of one axis.

    Attributes
    ----------
    coefficient_per_degc_per_s : float
        k [the axis's unit per degC/s: deg/s per degC/s, or g per degC/s].
    smoothing_s : float
        s [s], positive.
    """

    kind: ClassVar[str] = "temperature-rate"
    #: what the term models, in words (exports say which they cannot carry)
    title: ClassVar[str] = "temperature-rate term"

    coefficient_per_degc_per_s: float
    smoothing_s: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.coefficient_per_degc_per_s) and math.isfinite(self.smoothing_s)):
            raise InputError("temperature_rate: coefficient_per_degc_per_s and smoothing_s must be finite numbers")
        if not self.smoothing_s > 0:
            raise InputError(f"temperature_rate: smoothing_s must be positive [s], got {self.smoothing_s}")

    def offset(self, rate_degc_per_s: np.ndarray) -> np.ndarray:
        """k r [the axis's unit] at the smoothed rate ``rate_degc_per_s`` [degC/s]."""
        return self.coefficient_per_degc_per_s * np.asarray(rate_degc_per_s, dtype=float)

    def describe(self, unit: str = "deg/s") -> str:
        """In words for tables: ``temperature rate 0.012 deg/s per degC/min (smoothed over 300 s)``."""
        per_min = self.coefficient_per_degc_per_s / 60.0
        return f"temperature rate {per_min:.3g} {unit} per degC/min (smoothed over {self.smoothing_s:.3g} s)"

    def to_dict(self) -> dict[str, Any]:
        return {
            "type": self.kind,
            "coefficient_per_degc_per_s": self.coefficient_per_degc_per_s,
            "smoothing_s": self.smoothing_s,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "TemperatureRateTerm":
        if not isinstance(d, dict) or d.get("type") != cls.kind:
            raise InputError(f"temperature_rate: expected an entry of type {cls.kind!r}")
        try:
            return cls(float(d["coefficient_per_degc_per_s"]), float(d["smoothing_s"]))
        except (KeyError, TypeError, ValueError):
            raise InputError("temperature_rate: needs the numbers coefficient_per_degc_per_s and smoothing_s") from None

    def c_code(self, slot: int) -> tuple[str, ...]:
        """The statements that add the offset to ``shape`` in ``gyrocomp_step`` from ``tm`` and the smoothing
        filter ``s->rate[slot]`` (updated by them), as :func:`gyrocomp.effects.temperature_rate` computes it."""
        s = c_number(self.smoothing_s)
        return (
            f"{{   double smoothed = lag_update(&s->rate[{slot}], step, tm, {s});",
            f"    shape += {c_number(self.coefficient_per_degc_per_s)} * (tm - smoothed) / {s}; }}",
        )


def rate_columns(
    time_s: np.ndarray, temperature_degc: np.ndarray, smoothings_s: tuple[float, ...], period_s: float
) -> np.ndarray:
    """The fit columns of :class:`TemperatureRateTerm`: its offset is the column of its smoothing times k.

    Parameters
    ----------
    time_s : array (n,)
        Times [s] of the model temperature's samples (block means, in a fit).
    temperature_degc : array (n,)
        Model temperature [degC].
    smoothings_s : tuple of float
        One column per smoothing time constant [s].
    period_s : float
        Nominal period of the samples [s].

    Returns
    -------
    array (n, len(smoothings_s))
        The smoothed rate [degC/s] at each smoothing.
    """
    cols = [temperature_rate(time_s, temperature_degc, s, period_s=period_s)[0] for s in smoothings_s]
    return np.column_stack(cols) if cols else np.zeros((np.size(temperature_degc), 0))


__all__ = ["TemperatureRateTerm", "rate_columns"]
