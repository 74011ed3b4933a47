"""When to stop a calibration run: a log that grows, fitted again at each look, its forecast drift
(:mod:`gyrocomp.evaluation.drift_forecast`) and what one more hour of the leg under way would buy.

At each look the log is read whole, fitted by default (with any earlier runs), and the worst axis's drift on the
use profile forecast; the leg under way is continued for an hour at its last ten minutes' rate (a hold when that
is under :data:`HOLD_RATE_DEGC_PER_MIN`) and added as a candidate run: the drift now less the drift after, per
hour, is what the leg still pays.
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..models.fit import fit
from ..measures.ramp_rate import ramp_rate_degc_per_min
from ..recording import Recording
from .choice_alternatives import close_candidates
from .drift_forecast import DEFAULT_WINDOW_S, AxisForecast, UseProfile, axis_information, calibration_cycle

#: the stretch of the log whose rate the leg under way is continued at [s], and for how long [s]
TREND_S = 600.0
CONTINUED_S = 3600.0
#: a leg slower than this is continued as a hold [degC/min]
HOLD_RATE_DEGC_PER_MIN = 0.05


@dataclass(frozen=True)
class LogLook:
    """One look at a growing log.

    Attributes
    ----------
    rows : int
        The log's rows at this look.
    duration_s : float
        Its length [s].
    range_degc : (float, float)
        Its reported temperature's range [degC].
    worst : AxisForecast or None
        The worst axis's forecast on the use profile (None: no forecast yet; ``waiting`` says why).
    leg_gain_dps_per_h : float or None
        What one more hour of the leg under way would lower the worst axis's expected drift by [deg/s/h].
    reached : bool
        Whether the worst axis's expected drift is at or under the target.
    waiting : str
        Why there is no forecast yet (the fit's or the forecast's refusal), else empty.
    """

    rows: int
    duration_s: float
    range_degc: tuple[float, float]
    worst: AxisForecast | None
    leg_gain_dps_per_h: float | None
    reached: bool
    waiting: str = ""


def continued_leg(recording: Recording) -> UseProfile:
    """The leg under way continued for :data:`CONTINUED_S` at its last :data:`TREND_S`'s rate (a hold below
    :data:`HOLD_RATE_DEGC_PER_MIN`), from its last temperature, at 1 Hz.

    Parameters
    ----------
    recording : Recording
        The log so far.
    """
    temps = recording.die_temperature_degc
    t = recording.time_s
    recent = t >= t[-1] - TREND_S
    slope_per_s = float(np.polyfit(t[recent] - t[-1], temps[recent], 1)[0]) if np.count_nonzero(recent) > 2 else 0.0
    if abs(slope_per_s) * 60 < HOLD_RATE_DEGC_PER_MIN:
        slope_per_s = 0.0
    ahead = np.arange(0.0, CONTINUED_S + 0.5, 1.0)
    return UseProfile(ahead, float(temps[-1]) + slope_per_s * ahead, "the leg under way, continued")


def look(
    recording: Recording,
    earlier: Sequence[Recording] = (),
    use: UseProfile | None = None,
    window_s: float = DEFAULT_WINDOW_S,
    target_drift_dps: float | None = None,
) -> LogLook:
    """One look at a log that grows: fit, forecast, and the gain of one more hour of its leg under way.

    Parameters
    ----------
    recording : Recording
        The log so far.
    earlier : sequence of Recording
        Calibration runs recorded before it, fitted with it.
    use : UseProfile, optional
        The temperatures the gyro will see; default one cycle over the range so far at the runs' ramp rate.
    window_s : float
        Moving-average window of the drift [s].
    target_drift_dps : float, optional
        The drift to reach [deg/s]: :attr:`LogLook.reached` says whether the worst axis's expected drift is at or
        under it.

    Returns
    -------
    LogLook
        What the log gives so far.
    """
    temps = recording.temperature_degc
    span = (float(np.min(temps)), float(np.max(temps))) if temps is not None else (math.nan, math.nan)
    base = dict(rows=recording.n_samples, duration_s=recording.duration_s, range_degc=span)
    runs = [*earlier, recording]
    try:
        with warnings.catch_warnings():  # a short log's warnings would repeat at every look
            warnings.simplefilter("ignore")
            calibration = fit(runs)
        infos = axis_information(calibration, runs, window_s, extrapolation=use is not None)
    except InputError as exc:
        return LogLook(**base, worst=None, leg_gain_dps_per_h=None, reached=False, waiting=str(exc))
    if use is None:
        use = calibration_cycle(infos, ramp_rate_degc_per_min(runs))
    now = {a: i.forecast(use, window_s, close=close_candidates(calibration, a)) for a, i in infos.items()}
    worst = max(now.values(), key=lambda f: f.drift_dps)
    leg = continued_leg(recording)
    info = infos[worst.axis]
    after = info.forecast(use, window_s, [info.with_run(leg.time_s, leg.temperature_degc, leg.name)])
    gain = (worst.drift_dps - after.drift_dps) / (CONTINUED_S / 3600.0)
    reached = target_drift_dps is not None and worst.drift_dps <= target_drift_dps
    return LogLook(**base, worst=worst, leg_gain_dps_per_h=gain, reached=reached)


def watch_log(
    read: Callable[[], Recording],
    every_s: float,
    earlier: Sequence[Recording] = (),
    use: UseProfile | None = None,
    window_s: float = DEFAULT_WINDOW_S,
    target_drift_dps: float | None = None,
    looks: int | None = None,
    sleep: Callable[[float], None] = time.sleep,
) -> Iterator[LogLook]:
    """Look at a growing log every ``every_s`` [s] until the target is reached or ``looks`` looks are done.

    Parameters
    ----------
    read : callable
        Reads the log as it is now.
    every_s : float
        Time between looks [s].
    earlier, use, window_s, target_drift_dps
        As for :func:`look` (``window_s`` [s], ``target_drift_dps`` [deg/s]).
    looks : int, optional
        The most looks (default: until the target is reached).
    sleep : callable
        Waits a number of seconds (a test's stand-in for the clock).

    Yields
    ------
    LogLook
        Each look, the last one the target's when it is reached.
    """
    if not (math.isfinite(every_s) and every_s >= 0):
        raise InputError(f"every_s: {every_s!r}; give the seconds between looks")
    count, before = 0, None
    while looks is None or count < looks:
        if count:
            sleep(every_s)
        recording = read()
        before = _still_growing(before, recording)
        seen = look(recording, earlier, use, window_s, target_drift_dps)
        count += 1
        yield seen
        if seen.reached:
            return


#: the rows whose values must not change from one look to the next
FINGERPRINT_ROWS = 1000


def _still_growing(before: tuple | None, recording: Recording) -> tuple:
    """The log's rows and its first rows' times and rates, refusing a log that lost rows or whose first rows changed
    since the look before (``before``): a run under way only grows."""
    n = min(FINGERPRINT_ROWS, recording.n_samples)
    now = (recording.n_samples, recording.time_s[:n].copy(), recording.gyro_dps[:n].copy())
    if before is not None:
        rows, times, rates = before
        if recording.n_samples < rows:
            raise InputError(
                f"{recording.source}: {recording.n_samples} rows, {rows} at the look before: the log was truncated "
                "or replaced; a run under way only grows (start the watch again on the new log)"
            )
        k = min(times.size, n)
        if not (np.array_equal(times[:k], now[1][:k]) and np.array_equal(rates[:k], now[2][:k])):
            raise InputError(
                f"{recording.source}: its first rows changed since the look before: the log was rewritten; a run "
                "under way only grows (start the watch again on the new log)"
            )
    return now


__all__ = ["LogLook", "continued_leg", "look", "watch_log"]
