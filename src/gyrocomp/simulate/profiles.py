"""Temperature profiles of calibration tests."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError


@dataclass(frozen=True)
class SetPointProfile:
    """Temperature that dwells at each set point in turn, with linear ramps between them.

    Parameters
    ----------
    set_points_degc : tuple of float
        Temperatures visited, in order [degC].
    dwell_fraction : float
        Share of the duration spent dwelling, split equally between set points; the rest is
        split equally between the ramps.
    """

    name: str
    set_points_degc: tuple[float, ...]
    dwell_fraction: float = 0.2

    def temperature_degc(self, time_s: np.ndarray) -> np.ndarray:
        """Temperature [degC] at ``time_s`` [s] (measured from the first sample) over the full duration."""
        t = np.asarray(time_s, dtype=float) - time_s[0]
        duration = float(t[-1]) if t.size > 1 else 1.0
        points = self.set_points_degc
        if len(points) == 1:
            return np.full(t.shape, float(points[0]))
        dwell = self.dwell_fraction * duration / len(points)
        ramp = (1.0 - self.dwell_fraction) * duration / (len(points) - 1)
        knots_t, knots_T = [0.0], [points[0]]
        for k, temp in enumerate(points):
            start = k * (dwell + ramp)
            if k:
                knots_t.append(start)
                knots_T.append(temp)
            knots_t.append(start + dwell)
            knots_T.append(temp)
        return np.interp(t, knots_t, knots_T)

    def ramp_rate_degc_per_s(self, duration_s: float) -> float:
        """Magnitude of the temperature rate on the first ramp [degC/s]."""
        if len(self.set_points_degc) < 2:
            return 0.0
        ramp = (1.0 - self.dwell_fraction) * duration_s / (len(self.set_points_degc) - 1)
        return abs(self.set_points_degc[1] - self.set_points_degc[0]) / ramp


PROFILES = {
    "chamber": SetPointProfile("chamber", (-20.0, 70.0)),
    "cycle": SetPointProfile("cycle", (-20.0, 70.0, -20.0)),
    "static": SetPointProfile("static", (25.0,)),
}


def get_profile(name: str) -> SetPointProfile:
    try:
        return PROFILES[name]
    except KeyError:
        raise InputError(f"--profile: unknown profile {name!r}; use one of {', '.join(PROFILES)}") from None
