"""A zoo of thermal memories written from the physics, none of them one of gyrocomp's model forms.

Every part has the same body: a chamber steps through set points at a ramp rate; the die follows the chamber
through a first-order thermal lag of 25 s; each axis's bias is a smooth, saturating curve of the die's temperature
(a tanh plus a gentle bow, not a polynomial), a power-on constant, white noise and a slow random walk; the
temperature is reported in steps of 1/16 degC with its own noise. On top of that body, each part carries one
memory effect (per axis, of other sizes and signs on the three axes, so that no one lag shared by the axes can
stand in for it):

``play``
    A backlash (play) operator on the die temperature: the strain follows the temperature only once it has moved
    more than the play's half-width from where it stopped, so the bias runs on two parallel lines with a straight
    crossover after each turn (package stress held by friction).
``play bank``
    A sum of plays of widths spread from 1 to 30 degC (a Prandtl-Ishlinskii, or discrete Preisach, model): a loop
    whose width grows with the excursion.
``bump after turns``
    After each turn, a bump in the distance travelled from it, of one shape after a maximum (a gamma-shaped rise
    and fall) and another after a minimum (a saturating step that relaxes back): relaxation of the die attach.
``thermal gradient``
    A second thermal node: the bias follows the difference between the die's temperature and that of the package
    core behind a 300 s lag, that is, the temperature gradient, which on a ramp is the ramp rate times the lag
    (a bias in dT/dt).
``fading in time``
    After each turn, an offset of the turn's sign that fades with the time since the turn (a 15-minute
    relaxation), not with temperature.
``slow second lag``
    A second, slow thermal path (a board or housing behind 40 minutes) whose temperature adds a term of its own.
``adxrs450-like bump``
    The thesis's part: a 30 s lag, and after each maximum a smooth bump in temperature (a Gaussian centred 15 degC
    below the turn), not a polynomial in the distance from the turn.

:func:`zoo_run` gives a run of a part through a chamber profile, with the true rate (0: the part is still) and
the noise alone (the white noise and the random walk: what perfect compensation leaves).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gyrocomp.recording import GYRO_AXES, Recording

#: the die's thermal lag behind the chamber [s] (the ADXRS450-like part: 30 s)
DIE_LAG_S = 25.0
#: per axis: tanh gain [deg/s], bow [deg/s per degC^2], the memory effect's size and sign
_BODY = np.array([[0.06, 4e-6], [-0.04, -3e-6], [0.09, 2e-6]])
_SIZE = np.array([1.0, -0.6, 0.8])


def _first_order(x: np.ndarray, tau_s: float, dt_s: float) -> np.ndarray:
    """x through a first-order lag of ``tau_s`` [s] (exact for a piecewise-constant input)."""
    a = math.exp(-dt_s / tau_s)
    out = np.empty_like(x)
    out[0] = x[0]
    for k in range(1, x.size):
        out[k] = a * out[k - 1] + (1.0 - a) * x[k]
    return out


def _play(x: np.ndarray, half_width: float) -> np.ndarray:
    """The play (backlash) operator of half-width ``half_width`` [degC], starting centred on x[0]."""
    out = np.empty_like(x)
    y = x[0]
    for k, v in enumerate(x):
        y = min(max(y, v - half_width), v + half_width)
        out[k] = y
    return out


def _turns(x: np.ndarray, threshold: float = 0.5):
    """Per sample: the temperature of the last confirmed turn, its kind (+1 after a maximum, -1 after a minimum,
    0 before any), and the sample it was confirmed at; a turn is confirmed ``threshold`` degC past the extreme."""
    turn_at = np.full(x.size, np.nan)
    kind = np.zeros(x.size)
    since = np.full(x.size, -1)
    direction = 0  # 0 until the temperature has moved ``threshold`` from where it started
    low = high = x[0]
    low_k = high_k = 0
    last, last_kind, last_k = math.nan, 0.0, -1
    for k, v in enumerate(x):
        if v > high:
            high, high_k = v, k
        if v < low:
            low, low_k = v, k
        if direction >= 0 and v < high - threshold:  # falling: a maximum, confirmed if it ended a rise
            if direction > 0:
                last, last_kind, last_k = high, 1.0, high_k
            direction, low, low_k = -1, v, k
        elif direction <= 0 and v > low + threshold:  # rising: a minimum, confirmed if it ended a fall
            if direction < 0:
                last, last_kind, last_k = low, -1.0, low_k
            direction, high, high_k = 1, v, k
        turn_at[k], kind[k], since[k] = last, last_kind, last_k
    return turn_at, kind, since


def _memory(name: str, die: np.ndarray, t: np.ndarray, dt_s: float) -> np.ndarray:
    """The memory effect ``name`` of a unit size [deg/s] along the die temperature ``die`` [degC]."""
    if name == "play":
        return 0.004 * (_play(die, 4.0) - die)
    if name == "play bank":
        widths = np.geomspace(1.0, 30.0, 8)
        return sum(0.0015 * (_play(die, w) - die) for w in widths) / 2.0
    turn_at, kind, since = _turns(die)
    after = kind != 0
    distance = np.where(after, np.abs(die - np.nan_to_num(turn_at)), 0.0)
    if name == "bump after turns":
        rise = (distance / 8.0) * np.exp(1.0 - distance / 8.0)  # after a maximum: up and back down
        step = (1.0 - np.exp(-distance / 4.0)) * np.exp(-distance / 40.0)  # after a minimum: a relaxing step
        return np.where(kind > 0, 0.03 * rise, np.where(kind < 0, -0.02 * step, 0.0))
    if name == "thermal gradient":
        core = _first_order(die, 300.0, dt_s)
        return 0.004 * (die - core)
    if name == "fading in time":
        age_s = np.where(after, t - t[np.maximum(since, 0)], 0.0)
        return np.where(after, 0.02 * kind * np.exp(-age_s / 900.0), 0.0)
    if name == "slow second lag":
        housing = _first_order(die, 2400.0, dt_s)
        return 0.0004 * (housing - 25.0) + 3e-6 * (housing - 25.0) ** 2
    if name == "adxrs450-like bump":
        centre = np.nan_to_num(turn_at) - 15.0
        return np.where(kind > 0, 0.05 * np.exp(-0.5 * ((die - centre) / 6.0) ** 2), 0.0)
    raise KeyError(name)


#: the memory forms of the zoo
FORMS = (
    "play",
    "play bank",
    "bump after turns",
    "thermal gradient",
    "fading in time",
    "slow second lag",
    "adxrs450-like bump",
)


@dataclass(frozen=True)
class ZooRun:
    """A run of a zoo part: the recording, the true rate [deg/s] (n, 3) and the noise alone [deg/s] (n, 3)."""

    recording: Recording
    true_rate_dps: np.ndarray
    noise_dps: np.ndarray


def chamber_profile(set_points_degc, ramp_degc_per_min: float, hold_s: float, rate_hz: float):
    """(time [s], chamber temperature [degC]) through ``set_points_degc`` at ``ramp_degc_per_min``, holding ``hold_s``
    at each."""
    knots_t, knots_v = [0.0], [float(set_points_degc[0])]
    for target in set_points_degc[1:]:
        knots_t += [knots_t[-1] + hold_s, knots_t[-1] + hold_s + abs(target - knots_v[-1]) / ramp_degc_per_min * 60]
        knots_v += [knots_v[-1], float(target)]
    knots_t.append(knots_t[-1] + hold_s)
    knots_v.append(knots_v[-1])
    t = np.arange(0.0, knots_t[-1], 1.0 / rate_hz)
    return t, np.interp(t, knots_t, knots_v)


def zoo_run(
    form: str,
    set_points_degc,
    ramp_degc_per_min: float = 1.0,
    *,
    hold_s: float = 600.0,
    rate_hz: float = 2.0,
    noise_dps_per_sqrt_hz: float = 0.005,
    seed: int = 0,
) -> ZooRun:
    """A run of the zoo part ``form`` (one of :data:`FORMS`) through the chamber's ``set_points_degc`` [degC]."""
    rng = np.random.default_rng(seed)
    t, chamber = chamber_profile(set_points_degc, ramp_degc_per_min, hold_s, rate_hz)
    dt = 1.0 / rate_hz
    die = _first_order(chamber, 30.0 if form == "adxrs450-like bump" else DIE_LAG_S, dt)
    body = np.column_stack([g * np.tanh((die - 25.0) / 30.0) + b * (die - 25.0) ** 2 for g, b in _BODY])
    memory = _memory(form, die, t, dt)[:, None] * _SIZE
    turn_on = rng.normal(0.0, 0.02, 3)
    white = rng.standard_normal((t.size, 3)) * noise_dps_per_sqrt_hz * math.sqrt(rate_hz)
    walk = np.cumsum(rng.standard_normal((t.size, 3)), axis=0) * (noise_dps_per_sqrt_hz / 500.0) * math.sqrt(dt)
    noise = white + walk
    reported = np.round((die + rng.normal(0.0, 0.03, t.size)) * 16.0) / 16.0
    recording = Recording(
        time_s=t,
        gyro_dps=body + memory + turn_on + noise,
        gyro_axes=GYRO_AXES,
        temperature_degc=reported,
        source=f"zoo {form} {seed}",
    )
    return ZooRun(recording, np.zeros((t.size, 3)), noise)
