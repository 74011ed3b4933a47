"""Parts written from the physics for the memory curves' tests: a chamber, a die behind it, and a bias whose memory
is given as a function of the die's temperature path (none of it one of gyrocomp's model forms)."""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable

import numpy as np

from gyrocomp import apply
from gyrocomp.measures.merit import smoothed_residual_rms
from gyrocomp.recording import GYRO_AXES, Recording

#: each axis's share of the memory (other sizes and signs, so that no one term of the three axes stands in for it)
MEMORY_SHARE = np.array([1.0, -0.6, 0.8])


def die_path(set_points_degc, ramp_degc_per_min: float, rate_hz: float = 1.0, lag_s: float = 30.0):
    """(time [s], die temperature [degC]): a chamber through ``set_points_degc`` at ``ramp_degc_per_min`` with
    15-minute holds, and the die behind it through a first-order lag of ``lag_s``, stepped sample by sample."""
    knots_t, knots_v = [0.0], [float(set_points_degc[0])]
    for target in set_points_degc[1:]:
        knots_t += [knots_t[-1] + 900.0, knots_t[-1] + 900.0 + abs(target - knots_v[-1]) / ramp_degc_per_min * 60]
        knots_v += [knots_v[-1], float(target)]
    knots_t.append(knots_t[-1] + 900.0)
    knots_v.append(knots_v[-1])
    t = np.arange(0.0, knots_t[-1], 1.0 / rate_hz)
    chamber = np.interp(t, knots_t, knots_v)
    a = math.exp(-1.0 / (lag_s * rate_hz))
    die = np.empty_like(chamber)
    die[0] = chamber[0]
    for k in range(1, t.size):
        die[k] = a * die[k - 1] + (1 - a) * chamber[k]
    return t, die


def part_run(
    set_points_degc,
    ramp_degc_per_min: float,
    seed: int,
    memory: Callable[[np.ndarray], np.ndarray],
    rate_hz: float = 1.0,
) -> tuple[Recording, np.ndarray]:
    """A run of a part whose gyro axes read a smooth curve of the die temperature (a tanh), a turn-on constant,
    ``memory(die)`` [deg/s] times :data:`MEMORY_SHARE` and white noise of 0.005 deg/s/sqrt(Hz); the temperature
    reported in 1/16 degC with its own noise. Returns (recording, the noise alone [deg/s])."""
    rng = np.random.default_rng(seed)
    t, die = die_path(set_points_degc, ramp_degc_per_min, rate_hz)
    body = np.column_stack([g * np.tanh((die - 25.0) / 30.0) for g in (0.06, -0.04, 0.09)])
    noise = rng.standard_normal((t.size, 3)) * 0.005 * math.sqrt(rate_hz)
    gyro = body + memory(die)[:, None] * MEMORY_SHARE + rng.normal(0.0, 0.02, 3) + noise
    reported = np.round((die + rng.normal(0.0, 0.03, t.size)) * 16.0) / 16.0
    return Recording(t, gyro, GYRO_AXES, reported, source=f"part {seed}"), noise


def runs_at_two_rates(memory: Callable[[np.ndarray], np.ndarray]):
    """Two heat-cool runs at 1 degC/min (-20..70 and -10..60 degC) of a part with ``memory``, and a third at 3
    degC/min (-15..70) with its noise alone: ``(fit runs, (held-out run, noise [deg/s]))``."""
    fit_runs = [part_run(sp, 1.0, s, memory)[0] for s, sp in ((0, (-20.0, 70.0, -20.0)), (1, (-10.0, 60.0, -10.0)))]
    return fit_runs, part_run((-15.0, 70.0, -15.0), 3.0, 9, memory)


def drift_over_noise(calibration, held: Recording, noise_dps: np.ndarray) -> list[float]:
    """Per axis, the 60 s drift the calibration leaves on ``held`` (still: the true rate 0) over the noise's own."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = apply(calibration, held).gyro_dps
    return [smoothed_residual_rms(out[:, j], 60) / smoothed_residual_rms(noise_dps[:, j], 60) for j in range(3)]
