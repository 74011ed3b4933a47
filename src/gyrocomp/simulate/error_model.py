"""Deterministic and random gyro errors, with their truth.

Noise terms follow IEEE Std 952-1997 Annex C. For rate samples taken every dt = 1/rate_hz:

- angle random walk N [deg/s/sqrt(Hz)]: white noise of standard deviation N sqrt(rate_hz);
  Allan variance N^2 / tau;
- bias instability B [deg/h]: flicker noise with one-sided PSD B^2 / (pi f), built as a bank of
  first-order Gauss-Markov processes with log-spaced correlation times T_i = T_0 r^i, each of
  variance (B^2 / pi) ln r, whose PSDs add up to 1/f between the bank's corner frequencies;
  Allan floor (2 ln 2 / pi)^(1/2) B = 0.664 B;
- rate random walk K [deg/s/sqrt(s)]: integrated white noise, Allan variance K^2 tau / 3.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np
from scipy.signal import lfilter

from ..errors import InputError
from ..units import DEG_PER_S_TO_DEG_PER_H

GM_RATIO = 3.0  # spacing of the Gauss-Markov correlation times


@dataclass(frozen=True)
class GyroErrorModel:
    """Error parameters of a gyro, per axis.

    Parameters
    ----------
    axes : tuple of str
        Gyro axes simulated, e.g. ``("gyro_z",)``.
    temperature_coefficients : tuple of tuples
        Per axis, coefficients of (T - t_ref_degc)^k for k = 1, 2, ... [deg/s/degC^k].
    t_ref_degc : float
        Reference temperature of the polynomial [degC].
    turn_on_bias_sigma_dps : float
        Standard deviation of the random constant bias of each power-on [deg/s].
    noise_density_dps_per_sqrt_hz : float
        Angle random walk N [deg/s/sqrt(Hz)].
    bias_instability_deg_per_h : float
        Bias instability B [deg/h].
    rate_random_walk_dps_per_sqrt_s : float
        Rate random walk K [deg/s/sqrt(s)].
    accel_g : tuple of 3 floats, optional
        Constant specific force written as accelerometer columns [g], or None for no accelerometer.
    """

    axes: tuple[str, ...] = ("gyro_x", "gyro_y", "gyro_z")
    temperature_coefficients: tuple[tuple[float, ...], ...] = ((4e-4, 6e-6, -8e-8), (-3e-4, 4e-6, 5e-8), (5e-4, -5e-6, 6e-8))
    t_ref_degc: float = 25.0
    turn_on_bias_sigma_dps: float = 0.02
    noise_density_dps_per_sqrt_hz: float = 0.01
    bias_instability_deg_per_h: float = 10.0
    rate_random_walk_dps_per_sqrt_s: float = 0.0
    accel_g: tuple[float, float, float] | None = (0.0, 0.0, 1.0)

    def __post_init__(self) -> None:
        if len(self.temperature_coefficients) != len(self.axes):
            raise InputError(
                f"temperature_coefficients: {len(self.temperature_coefficients)} sets for {len(self.axes)} axes"
            )
        for name in ("turn_on_bias_sigma_dps", "noise_density_dps_per_sqrt_hz", "bias_instability_deg_per_h",
                     "rate_random_walk_dps_per_sqrt_s"):
            if getattr(self, name) < 0:
                raise InputError(f"{name}: must not be negative")

    def temperature_error_dps(self, temperature_degc: np.ndarray) -> np.ndarray:
        """Deterministic bias (n, k) [deg/s] at ``temperature_degc`` (without the turn-on constant)."""
        d = np.asarray(temperature_degc, dtype=float) - self.t_ref_degc
        cols = []
        for coefs in self.temperature_coefficients:
            out = np.zeros_like(d)
            for c in reversed(coefs):
                out = (out + c) * d
            cols.append(out)
        return np.column_stack(cols)

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class NoiseTruth:
    """The noise that was added, per axis (n, k) [deg/s], and its parts' parameters."""

    white_dps: np.ndarray = field(repr=False)
    flicker_dps: np.ndarray = field(repr=False)
    random_walk_dps: np.ndarray = field(repr=False)

    @property
    def total_dps(self) -> np.ndarray:
        return self.white_dps + self.flicker_dps + self.random_walk_dps


def flicker_bank(n: int, rate_hz: float, bias_instability_deg_per_h: float, rng: np.random.Generator,
                 shortest_s: float | None = None, longest_s: float | None = None) -> np.ndarray:
    """Flicker (bias instability) noise [deg/s] from a bank of Gauss-Markov processes (see module doc)."""
    if bias_instability_deg_per_h == 0 or n == 0:
        return np.zeros(n)
    dt = 1.0 / rate_hz
    b_dps = bias_instability_deg_per_h / DEG_PER_S_TO_DEG_PER_H
    shortest = shortest_s or 2.0 * dt
    longest = longest_s or max(n * dt, shortest * GM_RATIO)
    count = int(math.ceil(math.log(longest / shortest) / math.log(GM_RATIO))) + 1
    variance = b_dps**2 / math.pi * math.log(GM_RATIO)
    out = np.zeros(n)
    for i in range(count):
        tc = shortest * GM_RATIO**i
        phi = math.exp(-dt / tc)
        drive = rng.standard_normal(n) * math.sqrt(variance * -math.expm1(-2.0 * dt / tc))
        drive[0] = rng.standard_normal() * math.sqrt(variance)  # start in the stationary distribution
        out += lfilter([1.0], [1.0, -phi], drive)
    return out


def simulate_noise(n: int, rate_hz: float, model: GyroErrorModel, rng: np.random.Generator) -> NoiseTruth:
    """Draw the random errors of every axis."""
    k = len(model.axes)
    white = rng.standard_normal((n, k)) * model.noise_density_dps_per_sqrt_hz * math.sqrt(rate_hz)
    flicker = np.column_stack([flicker_bank(n, rate_hz, model.bias_instability_deg_per_h, rng) for _ in range(k)])
    steps = rng.standard_normal((n, k)) * model.rate_random_walk_dps_per_sqrt_s * math.sqrt(1.0 / rate_hz)
    walk = np.cumsum(steps, axis=0)
    return NoiseTruth(white, flicker, walk)
