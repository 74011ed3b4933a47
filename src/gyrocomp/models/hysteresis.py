"""The thesis's hysteresis (section 2.6): after the temperature turns, the bias follows another path,
an offset polynomial in |T - T_turn| on each branch.

This module holds the fitted curve and the turning-point threshold; the curve is fitted jointly with
the temperature polynomial, thermal lag and g-sensitivity by :class:`gyrocomp.models.thermal.ThermalHysteresisModel`,
and the turning points themselves are found by :func:`gyrocomp.effects.find_turns`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..effects import find_turns, hysteresis_offset
from ..errors import InputError
from ..recording import Recording


def turn_threshold_degc(temperature_degc: np.ndarray) -> float:
    """Turning-point threshold for a measured temperature series [degC].

    Ten times the sample noise (robust, from the median absolute second difference, which a ramp
    does not inflate: the running extreme of a long dwell wanders several sigma), 1.5 times the
    quantization step when the values sit on a grid, and at least 0.1 degC.
    """
    t = np.asarray(temperature_degc, dtype=float)
    second = np.diff(t, 2)
    noise = 1.4826 * float(np.median(np.abs(second))) / math.sqrt(6.0) if second.size else 0.0
    steps = np.abs(np.diff(t))
    steps = steps[steps > 0]
    lsb = 0.0
    if steps.size:
        smallest = float(steps.min())
        if np.allclose(steps / smallest, np.round(steps / smallest), atol=1e-6):
            lsb = smallest
    return max(10.0 * noise, 1.5 * lsb, 0.1)


def heats_and_cools(recordings: list[Recording], axis: str) -> bool:
    """Whether the runs together contain both a rising and a falling temperature branch."""
    up = down = False
    for rec in recordings:
        t = rec.temperature_for(axis)
        d = find_turns(t, turn_threshold_degc(t)).direction
        up |= bool(np.any(d == 1))
        down |= bool(np.any(d == -1))
    return up and down


@dataclass(frozen=True)
class HysteresisCurve:
    """Fitted hysteresis of one axis: offset after a reversal of the model temperature.

    offset = sum_j h_j |T - T_turn|^j, h from ``descending_dps`` on cooling branches and
    ``ascending_dps`` on heating branches [deg/s/degC^j], zero outside ``band_degc`` if given.
    Reversals are confirmed ``threshold_degc`` past the extreme (see :func:`gyrocomp.effects.find_turns`).
    """

    descending_dps: tuple[float, ...]
    ascending_dps: tuple[float, ...]
    threshold_degc: float
    band_degc: tuple[float, float] | None = None

    @property
    def order(self) -> int:
        return len(self.descending_dps)

    def offset_dps(self, temperature_degc: np.ndarray, turns) -> np.ndarray:
        down = hysteresis_offset(temperature_degc, turns, self.descending_dps, direction="descending",
                                 band_degc=self.band_degc)
        up = hysteresis_offset(temperature_degc, turns, self.ascending_dps, direction="ascending",
                               band_degc=self.band_degc)
        return down + up

    def to_dict(self) -> dict[str, Any]:
        return {"type": "turning-point", "descending_dps": list(self.descending_dps),
                "ascending_dps": list(self.ascending_dps), "threshold_degc": self.threshold_degc,
                "band_degc": None if self.band_degc is None else list(self.band_degc)}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "HysteresisCurve":
        if d.get("type") != "turning-point":
            raise InputError(f"unknown hysteresis model type {d.get('type')!r}")
        band = d.get("band_degc")
        return cls(tuple(float(v) for v in d["descending_dps"]), tuple(float(v) for v in d["ascending_dps"]),
                   float(d["threshold_degc"]), None if band is None else (float(band[0]), float(band[1])))


__all__ = ["HysteresisCurve", "heats_and_cools", "turn_threshold_degc"]
