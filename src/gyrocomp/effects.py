"""The deterministic gyro effects as pure, vectorized functions.

The simulator adds these effects and the models fit and remove them, with the same code, so a
simulated truth and a fitted model mean the same thing by construction. Each function works on
whole arrays; the ones with memory (thermal lag, turning points) take and return a state so
that a stream cut into chunks gives exactly the result of one call.

References
----------
M. Ali, *Correction of temperature and acceleration effects on MEMS gyro output signals*,
MS thesis, METU, 2014: section 2.6 (hysteresis as a polynomial in |T - T_turn| after the
temperature slope reverses), section 2.7.1 (the 3x3 g-sensitivity matrix).
IEEE Std 1431-2004 (Coriolis vibratory gyros), Annex B: g-sensitive and g x g-sensitive bias.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numpy as np

from .errors import InputError
from .spilled_series import WindowSums, parts

HYSTERESIS_DIRECTIONS = ("descending", "ascending", "both")
#: order of the g x g terms: products of specific-force components [g^2]
G_SQUARED_TERMS = ("xx", "yy", "zz", "xy", "xz", "yz")


# -- thermal lag ------------------------------------------------------------------------------------

#: a first-order filter of at most this many samples runs in Python (about 0.1 us a sample) rather than import
#: scipy.signal (0.6 s) for it
PYTHON_FILTER_SAMPLES = 100_000
#: the samples filtered in Python in one process before scipy.signal is imported after all (about 0.2-0.3 s of
#: Python filtering, under half the import's cost): a command that filters little never imports it, one that
#: filters a lot (a fit's lag search on hours of blocks) pays at most that much before scipy's faster filter
PYTHON_FILTER_BUDGET = 2_000_000
#: samples filtered in Python so far in this process (a running total; a lost update between threads only moves
#: the switch to scipy a little)
_python_filtered = [0]


def lazy_lfilter(b, a, x, zi=None):
    """``scipy.signal.lfilter``, imported on first use: scipy.signal costs most of a second at start-up and
    most commands never filter. Until something else has imported it, or :data:`PYTHON_FILTER_BUDGET` samples
    have been filtered in Python, a first-order filter (``a = [1, a1]``) of a short input runs in Python with
    scipy's operations in scipy's order (its direct form II transposed: y = x b0 + z, z = x b1 - y a1), so the
    result is the same to the bit (tested); after that, scipy's is used, forty times faster on long inputs."""
    x = np.asarray(x, dtype=float)
    if (
        len(a) == 2
        and a[0] == 1.0
        and len(b) <= 2
        and x.ndim == 1
        and x.size <= PYTHON_FILTER_SAMPLES
        and _python_filtered[0] + x.size <= PYTHON_FILTER_BUDGET
        and "scipy.signal" not in sys.modules
    ):
        _python_filtered[0] += x.size
        return _first_order(b, a, x, zi)
    from scipy.signal import lfilter

    return lfilter(b, a, x) if zi is None else lfilter(b, a, x, zi=zi)


def _first_order(b, a, x: np.ndarray, zi):
    b0, b1, a1 = float(b[0]), float(b[1]) if len(b) > 1 else 0.0, float(a[1])
    z = 0.0 if zi is None else float(np.asarray(zi, dtype=float).reshape(-1)[0])
    out = np.empty(x.size)
    for i, value in enumerate(x.tolist()):
        y = value * b0 + z
        z = value * b1 - y * a1
        out[i] = y
    return out if zi is None else (out, np.array([z]))


def lag_coefficients(step_s: float, time_constant_s: float) -> tuple[float, float, float]:
    """Coefficients (a, b0, b1) of the exact first-order lag for an input linear between samples.

    The structure temperature T_s follows dT_s/dt = (T - T_s) / tau. If the reported
    temperature T is linear over a step of length h (first-order hold), the exact update is

        T_s[k] = a T_s[k-1] + b0 T[k] + b1 T[k-1],
        a = exp(-h/tau),  b0 = 1 - (1 - a) tau/h,  b1 = (1 - a) tau/h - a,

    so a steady ramp of r [degC/s] is followed with a lag of exactly r tau [degC].

    Parameters
    ----------
    step_s : float
        Time step h [s].
    time_constant_s : float
        Thermal time constant tau [s]; 0 means no lag (a = 0, b0 = 1, b1 = 0).
    """
    if time_constant_s <= 0:
        return 0.0, 1.0, 0.0
    h = step_s / time_constant_s
    a = math.exp(-h)
    g = -math.expm1(-h) / h  # (1 - a) / h, accurate for small h
    return a, 1.0 - g, g - a


@dataclass(frozen=True)
class LagState:
    """Where a thermal-lag filter stands after a chunk: the last input [degC] and output [degC], and its time [s]."""

    last_input_degc: float
    last_output_degc: float
    last_time_s: float


def thermal_lag(
    time_s: np.ndarray,
    temperature_degc: np.ndarray,
    time_constant_s: float,
    *,
    period_s: float | None = None,
    state: LagState | None = None,
) -> tuple[np.ndarray, LagState]:
    """Temperature of the sensing structure, lagging the reported temperature (first-order) [degC].

    Parameters
    ----------
    time_s : array (n,)
        Sample times [s], increasing.
    temperature_degc : array (n,)
        Reported temperature [degC].
    time_constant_s : float
        Thermal time constant tau [s] (>= 0).
    period_s : float, optional
        Nominal sample period [s]. Steps within 1.5 periods are taken as exactly one period (real
        logs jitter); longer steps (gaps) are bridged exactly, assuming the temperature linear
        across the gap. Default: the median step.
    state : LagState, optional
        Where the previous chunk ended; without it the structure starts in equilibrium
        (T_s = T at the first sample).

    Returns
    -------
    structure_degc : array (n,)
    state : LagState
        Pass it with the next chunk to continue the stream exactly.
    """
    t = np.asarray(time_s, dtype=float)
    u = np.asarray(temperature_degc, dtype=float)
    if time_constant_s < 0:
        raise InputError(f"thermal time constant: must not be negative, got {time_constant_s}")
    if u.size == 0:
        return u.copy(), state
    if time_constant_s == 0:
        return u.copy(), LagState(float(u[-1]), float(u[-1]), float(t[-1]))
    if period_s is None:
        period_s = float(np.median(np.diff(t))) if t.size > 1 else (t[0] - state.last_time_s if state else 1.0)
    if state is None:
        prev_u, prev_y, prev_t = float(u[0]), float(u[0]), float(t[0])
        start = 1
        out = np.empty_like(u)
        out[0] = u[0]
    else:
        prev_u, prev_y, prev_t = state.last_input_degc, state.last_output_degc, state.last_time_s
        start = 0
        out = np.empty_like(u)
    _lag_stretches(t, u, out, start, (prev_u, prev_y, prev_t), period_s, time_constant_s)
    return out, LagState(float(u[-1]), float(out[-1]), float(t[-1]))


def _lag_stretches(
    t: np.ndarray,
    u: np.ndarray,
    out: np.ndarray,
    start: int,
    previous: tuple[float, float, float],
    period_s: float,
    time_constant_s: float,
) -> None:
    """Fill ``out[start:]`` with the lagged temperature [degC]: each uniform stretch by one IIR filter, each gap
    (a step over 1.5 periods) bridged exactly; ``previous`` is (input, output, time) before ``start``."""
    prev_u, prev_y, prev_t = previous
    steps = np.diff(np.concatenate([[prev_t], t]))
    long_steps = np.flatnonzero(steps[start:] > 1.5 * period_s) + start
    a, b0, b1 = lag_coefficients(period_s, time_constant_s)
    i = start
    for stop in list(long_steps) + [u.size]:
        if i < stop:
            # uniform stretch [i, stop): y[k] = a y[k-1] + b0 u[k] + b1 u[k-1]
            seg = u[i:stop]
            zi = np.array([a * prev_y + b1 * prev_u])
            out[i:stop], _ = lazy_lfilter([b0, b1], [1.0, -a], seg, zi=zi)
            prev_u, prev_y = float(seg[-1]), float(out[stop - 1])
        if stop < u.size:  # bridge the gap before sample `stop` exactly
            ga, gb0, gb1 = lag_coefficients(float(steps[stop]), time_constant_s)
            out[stop] = ga * prev_y + gb0 * u[stop] + gb1 * prev_u
            prev_u, prev_y = float(u[stop]), float(out[stop])
            i = stop + 1


def temperature_rate(
    time_s: np.ndarray,
    temperature_degc: np.ndarray,
    smoothing_s: float,
    *,
    period_s: float | None = None,
    state: LagState | None = None,
) -> tuple[np.ndarray, LagState]:
    """Smoothed rate of change of a temperature [degC/s], causal, so a stream in chunks gives the batch result.

        r = (T - T_f) / s,   dT_f/dt = (T - T_f) / s

    T_f is T through a first-order lag of time constant s (:func:`thermal_lag`). On a steady ramp of rho
    [degC/s], r settles to rho within a few s; at a hold it decays as exp(-t / s). (T - T_f) is also the gradient
    between a surface at T and a core behind the lag s: a bias linear in r is the bias of a thermal gradient
    across the part, which a lag of the bias's own temperature curve cannot follow where the curve is flat.

    Parameters
    ----------
    time_s : array (n,)
        Sample times [s], increasing.
    temperature_degc : array (n,)
        The temperature [degC] (the model's: reported, or through the thermal lag).
    smoothing_s : float
        Smoothing time constant s [s], positive.
    period_s : float, optional
        Nominal sample period [s] (see :func:`thermal_lag`).
    state : LagState, optional
        The smoothing filter's state where the previous chunk ended.

    Returns
    -------
    rate_degc_per_s : array (n,)
    state : LagState
    """
    if not smoothing_s > 0:
        raise InputError(f"temperature-rate smoothing: must be positive [s], got {smoothing_s}")
    smoothed, state = thermal_lag(time_s, temperature_degc, smoothing_s, period_s=period_s, state=state)
    return (np.asarray(temperature_degc, dtype=float) - smoothed) / smoothing_s, state


# -- turning points and hysteresis ------------------------------------------------------------------
@dataclass(frozen=True)
class TurnState:
    """Where a turning-point detector stands: the direction of travel (+1 rising, -1 falling,
    0 not yet known), the running extreme of the current branch [degC], the last turn [degC]
    (NaN before the first), and, while the direction is not known, the lowest and highest
    temperature seen [degC]."""

    direction: int
    extreme_degc: float
    turn_degc: float
    low_degc: float
    high_degc: float


@dataclass(frozen=True)
class Turns:
    """Per-sample hysteresis state of a temperature series.

    Attributes
    ----------
    direction : array (n,) of int
        +1 on a rising branch, -1 on a falling branch, 0 before the direction is known.
    turn_degc : array (n,)
        Temperature of the last confirmed turning point [degC], NaN before the first.
    turn_index : array (m,) of int
        Sample index at which each reversal was confirmed.
    state : TurnState
        Pass it with the next chunk to continue the stream exactly.
    """

    direction: np.ndarray
    turn_degc: np.ndarray
    turn_index: np.ndarray
    state: TurnState


def _first_true(mask: np.ndarray) -> int:
    hit = np.flatnonzero(mask)
    return int(hit[0]) if hit.size else -1


#: first block a branch is searched in [samples]; each further block doubles
_TURN_BLOCK = 256


def _leave_band(
    x: np.ndarray, start: int, low: float, high: float, threshold: float
) -> tuple[int, int, float, float, float]:
    """Where the series x [degC] leaves the band of its running extremes (from ``low``, ``high`` [degC]) by more
    than ``threshold`` [degC] while the direction is unknown: (index or -1, direction, extreme there, low,
    high), scanning blocks from ``start``; low and high are the extremes up to that index (where the first
    branch started: low when it rises, high when it falls)."""
    block, pos = _TURN_BLOCK, start
    while pos < x.size:
        seg = x[pos : pos + block]
        lo = np.minimum.accumulate(np.minimum(seg, low))
        hi = np.maximum.accumulate(np.maximum(seg, high))
        up = _first_true(seg - lo > threshold)
        down = _first_true(hi - seg > threshold)
        if up >= 0 or down >= 0:
            k, d = (up, 1) if down < 0 or (0 <= up < down) else (down, -1)
            return pos + k, d, float(hi[k]) if d == 1 else float(lo[k]), float(lo[k]), float(hi[k])
        low, high = float(lo[-1]), float(hi[-1])
        pos += seg.size
        block *= 2
    return -1, 0, math.nan, low, high


def _reversal(x: np.ndarray, start: int, d: int, extreme: float, threshold: float) -> tuple[int, float]:
    """Where the branch of direction d (+1 rising, -1 falling) of x [degC] reverses (its running extreme, from
    ``extreme``, left by more than ``threshold`` [degC]), scanning blocks from ``start``: (index or -1, the
    running extreme there or at the end [degC])."""
    block, pos = _TURN_BLOCK, start
    while pos < x.size:
        seg = x[pos : pos + block]
        running = (
            np.maximum.accumulate(np.maximum(seg, extreme))
            if d == 1
            else np.minimum.accumulate(np.minimum(seg, extreme))
        )
        back = (running - seg) if d == 1 else (seg - running)
        k = _first_true(back > threshold)
        if k >= 0:
            return pos + k, float(running[k])
        extreme = float(running[-1])
        pos += seg.size
        block *= 2
    return -1, extreme


def _turn_arrays(n: int, changes: list, turns: list[int], state: TurnState) -> tuple[np.ndarray, np.ndarray]:
    """Per-sample direction and turning temperature [degC] from the changes (index, direction, turn temperature
    or None) found in a chunk of n samples, the chunk's start continuing ``state``."""
    direction = np.zeros(n, dtype=np.int8)
    turn = np.full(n, np.nan)
    for (k, dk, _), stop in zip(changes, [c[0] for c in changes[1:]] + [n]):
        direction[k:stop] = dk
    values = [tk for _, _, tk in changes if tk is not None]
    for k, tk, stop in zip(turns, values, turns[1:] + [n]):
        turn[k:stop] = tk
    first = turns[0] if turns else n
    if state.direction != 0:
        direction[:first] = state.direction
    if not math.isnan(state.turn_degc):
        turn[:first] = state.turn_degc
    return direction, turn


def find_turns(temperature_degc: np.ndarray, threshold_degc: float = 0.0, *, state: TurnState | None = None) -> Turns:
    """Turning points of a temperature series, robust to noise and to whole-degree steps.

    A reversal is confirmed when the temperature has come back from the running extreme of the
    current branch by more than ``threshold_degc``; its turning temperature T_turn is that extreme.
    Noise and quantization steps smaller than the threshold never make a reversal. The detector is
    causal, so a stream processed in chunks (passing ``state``) gives exactly the batch result.
    Each branch is searched in blocks that double from 256 samples, so the work is linear in the length
    of the series (it was quadratic in the number of branches), vectorized per block, not per sample.

    Parameters
    ----------
    temperature_degc : array (n,)
        Temperature [degC].
    threshold_degc : float
        Hysteresis of the detector [degC]: 0 for clean data, a few times the noise or the
        quantization step of the temperature sensor for measured data.
    state : TurnState, optional
        Where the previous chunk ended.
    """
    x = np.asarray(temperature_degc, dtype=float)
    n = x.size
    if threshold_degc < 0:
        raise InputError(f"turning-point threshold: must not be negative, got {threshold_degc}")
    if state is None:
        state = TurnState(0, math.nan, math.nan, math.inf, -math.inf)
    d, extreme, last_turn = state.direction, state.extreme_degc, state.turn_degc
    low, high = state.low_degc, state.high_degc
    changes = []  # (index, direction, turn temperature or None when only the direction became known)
    turns = []
    i = 0
    while i < n:
        if d == 0:
            k, d, extreme, low, high = _leave_band(x, i, low, high, threshold_degc)
            if k < 0:
                break
            changes.append((k, d, None))
            i = k + 1
            continue
        k, running = _reversal(x, i, d, extreme, threshold_degc)
        if k < 0:
            extreme = running
            break
        last_turn = running
        d = -d
        changes.append((k, d, last_turn))
        turns.append(k)
        extreme = float(x[k])
        i = k + 1
    direction, turn = _turn_arrays(n, changes, turns, state)
    return Turns(direction, turn, np.asarray(turns, dtype=np.int64), TurnState(int(d), extreme, last_turn, low, high))


def hysteresis_offset(
    temperature_degc: np.ndarray,
    turns: Turns,
    coefficients_dps: tuple[float, ...] | np.ndarray,
    *,
    direction: str = "descending",
    band_degc: tuple[float, float] | None = None,
    max_distance_degc: float | None = None,
) -> np.ndarray:
    """Bias offset on the branch after a temperature reversal [deg/s] (thesis section 2.6).

        offset = sum_j h_j d^j,   d = |T - T_turn|,   j = 1..p

    on branches of the given direction after the first confirmed reversal, zero elsewhere
    (the first branch is the reference path), and, with ``band_degc``, only where
    lo <= T <= hi (the ADXRS450 shows it only between 55 and 80 degC on cooling).

    Parameters
    ----------
    temperature_degc : array (n,)
        Temperature the effect depends on [degC].
    turns : Turns
        From :func:`find_turns` on the same series.
    coefficients_dps : sequence of float
        h_1..h_p [deg/s/degC^j].
    direction : {"descending", "ascending", "both"}
        Branches that carry the offset.
    band_degc : (lo, hi), optional
        Temperature band [degC] outside which the offset is zero.
    max_distance_degc : float, optional
        Largest d the offset follows [degC]; beyond it the offset is held at its value there (a fitted
        polynomial in d is not extrapolated past the distances it was fitted on).
    """
    if direction not in HYSTERESIS_DIRECTIONS:
        raise InputError(f"hysteresis direction: {direction!r}; use one of {', '.join(HYSTERESIS_DIRECTIONS)}")
    t = np.asarray(temperature_degc, dtype=float)
    active = ~np.isnan(turns.turn_degc)
    if direction == "descending":
        active &= turns.direction == -1
    elif direction == "ascending":
        active &= turns.direction == 1
    if band_degc is not None:
        lo, hi = band_degc
        active &= (t >= lo) & (t <= hi)
    d = np.where(active, np.abs(t - np.where(active, turns.turn_degc, 0.0)), 0.0)
    if max_distance_degc is not None:
        d = np.minimum(d, max_distance_degc)
    out = np.zeros_like(t)
    for h in reversed(tuple(coefficients_dps)):
        out = (out + h) * d
    return np.where(active, out, 0.0)


def branch_position(temperature_degc: np.ndarray, turns: Turns, transition_degc: float) -> np.ndarray:
    """Where the bias stands between the heating and the cooling curve, from -1 (cooling) to +1 (heating).

        s = 0                                   while the direction is not yet known
        s = D (1 - exp(-|T - T_0| / w))         on the first branch, of direction D, before the first confirmed
                                                turn: from midway (the history before the recording is not
                                                known) to this branch's curve; T_0 where the branch started
                                                (the lowest temperature before it when it rises, the highest
                                                when it falls)
        s = D (1 - 2 exp(-|T - T_turn| / w))    after a turn at T_turn: from the last branch's curve at the turn
                                                to this branch's, over a transition of about w degrees

    The general form of the thesis's turning-point correction (section 2.6): a part that follows one curve while
    heating and another while cooling, and crosses over after each turning point.

    Parameters
    ----------
    temperature_degc : array (n,)
        Temperature the effect depends on [degC].
    turns : Turns
        From :func:`find_turns` on the same series (direction D: +1 rising, -1 falling).
    transition_degc : float
        Transition width w [degC], positive.
    """
    t = np.asarray(temperature_degc, dtype=float)
    d = turns.direction.astype(float)
    after = ~np.isnan(turns.turn_degc)
    start = np.where(d > 0, turns.state.low_degc, turns.state.high_degc)  # where the first branch started
    first = np.where(~after & (d != 0), np.abs(t - start), 0.0)
    distance = np.abs(t - np.where(after, turns.turn_degc, t))
    return np.where(
        after, d * (1.0 - 2.0 * np.exp(-distance / transition_degc)), d * (1.0 - np.exp(-first / transition_degc))
    )


# -- acceleration -----------------------------------------------------------------------------------
def g_squared_products(accel_g: np.ndarray) -> np.ndarray:
    """Products of specific-force components in the order of ``G_SQUARED_TERMS`` (n, 6) [g^2]."""
    a = np.asarray(accel_g, dtype=float)
    x, y, z = a[:, 0], a[:, 1], a[:, 2]
    return np.column_stack([x * x, y * y, z * z, x * y, x * z, y * z])


def g_sensitivity_offset(
    accel_g: np.ndarray, matrix_dps_per_g: np.ndarray, squared_dps_per_g2: np.ndarray | None = None
) -> np.ndarray:
    """Gyro bias caused by specific force (n, k) [deg/s]: G a (+ the g x g terms).

        offset_i = sum_j G_ij a_j + sum_m Q_im p_m(a)

    Parameters
    ----------
    accel_g : array (n, 3)
        Specific force along the body x, y, z axes [g].
    matrix_dps_per_g : array (k, 3)
        g-sensitivity G: row i is gyro axis i's sensitivity to each accelerometer axis [deg/s/g].
    squared_dps_per_g2 : array (k, 6), optional
        g x g sensitivity to the products in ``G_SQUARED_TERMS`` [deg/s/g^2].
    """
    a = np.asarray(accel_g, dtype=float)
    out = a @ np.asarray(matrix_dps_per_g, dtype=float).T
    if squared_dps_per_g2 is not None:
        out = out + g_squared_products(a) @ np.asarray(squared_dps_per_g2, dtype=float).T
    return out


def quantize(x: np.ndarray, lsb: float) -> np.ndarray:
    """Round to whole multiples of ``lsb`` (unit of x); ``lsb = 0`` leaves x as it is."""
    if lsb <= 0:
        return np.asarray(x, dtype=float)
    return np.round(np.asarray(x, dtype=float) / lsb) * lsb


def _checked_window(x: np.ndarray, window_samples: int) -> tuple[np.ndarray, int]:
    """(x as floats, the window [samples]), the window at least one sample and no longer than the data."""
    x = np.asarray(x, dtype=float)
    w = int(window_samples)
    if w < 1:
        raise InputError(f"window: must be at least one sample, got {w}")
    if w > x.size:
        raise InputError(f"window: {w} samples is longer than the data ({x.size} samples)")
    return x, w


def _window_sums(x: np.ndarray, window_samples: int) -> tuple[np.ndarray, np.ndarray, int]:
    """(x as floats, its running sum about its first value with a leading 0, the window [samples]), the window
    checked: in place, no temporary of the data's size."""
    x, w = _checked_window(x, window_samples)
    c = np.empty(x.size + 1)
    c[0] = 0.0
    np.subtract(x, x[0], out=c[1:])
    np.cumsum(c[1:], out=c[1:])
    return x, c, w


def moving_average(x: np.ndarray, window_samples: int) -> np.ndarray:
    """Moving average over ``window_samples`` samples, only where the window is full (n - w + 1 values)."""
    x, c, w = _window_sums(x, window_samples)
    out = c[w:] - c[:-w]
    out /= w
    out += x[0]
    return out


def moving_average_range(x: np.ndarray, window_samples: int, rows: int | None = None) -> float:
    """Peak-to-peak of :func:`moving_average` [unit of x], the same values, found a part of ``rows`` samples at a
    time (default :data:`gyrocomp.spilled_series.PART_ROWS`): the running sum is carried from part to part in the
    same order of additions, so no array of the data's length is made (``x`` may be a memory-mapped file)."""
    x, w = _checked_window(x, window_samples)
    first = x[0]
    sums = WindowSums(w)  # of the values about the first one, as moving_average sums them
    low, high = math.inf, -math.inf
    for start, stop in parts(x.size, rows=rows):
        out = sums.add(x[start:stop] - first)
        if out.size:
            out /= w
            out += first
            low, high = min(low, float(out.min())), max(high, float(out.max()))
    return high - low


def estimate_turn_on_bias(residual_dps: np.ndarray, time_s: np.ndarray, window_s: float) -> float:
    """Mean of ``residual_dps`` over the first ``window_s`` seconds of a run [deg/s]: the turn-on constant a run
    starts with."""
    head = time_s - time_s[0] < window_s
    return float(residual_dps[head].mean())


__all__ = [
    "G_SQUARED_TERMS",
    "HYSTERESIS_DIRECTIONS",
    "LagState",
    "TurnState",
    "Turns",
    "branch_position",
    "estimate_turn_on_bias",
    "find_turns",
    "g_sensitivity_offset",
    "g_squared_products",
    "hysteresis_offset",
    "lag_coefficients",
    "lazy_lfilter",
    "moving_average",
    "moving_average_range",
    "quantize",
    "temperature_rate",
    "thermal_lag",
]
