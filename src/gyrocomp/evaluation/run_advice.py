"""Which calibration run to record next, and when more chamber time stops paying: each candidate run scored by
the drift the model would leave on the use profile after it (:mod:`gyrocomp.evaluation.drift_forecast`), per hour
of chamber time.

The candidates are new power-ons built from the calibration runs' own range and ramp rate: the same cycle again,
the range widened at either end (or both, to cover the use profile), a slower and a faster ramp, dwells at the
ends and the middle, one heating and one cooling leg. Each adds its information (its own turn-on constant
projected out) to the runs', under the same residual drift model, and the forecast is made again; what a run
resolves is read from what it changes: the extrapolation past the calibrated range, the lag's standard error,
the coefficients' share.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..calibration.calibration import Calibration
from ..recording import Recording
from .choice_alternatives import choice_alternatives
from .drift_forecast import (
    DEFAULT_WINDOW_S,
    AxisForecast,
    AxisInformation,
    axis_information,
    DriftForecast,
    UseProfile,
    close_candidates,
    set_point_profile,
)

#: the hold at each end of a candidate cycle, and a dwell's [s]
HOLD_S = 600.0
DWELL_S = 1800.0
#: a candidate's gain below this share of the drift: more chamber time buys little
WORTHWHILE_GAIN = 0.10
#: the chi-square (one degree of freedom) at which a run tells an alternative from the chosen model: 3 sigma
SEPARATION_CHI2 = 9.0
#: a widened range goes at least this share of the calibrated span past the end it widens
WIDEN_SHARE = 0.25


@dataclass(frozen=True)
class CandidateRun:
    """A run not yet recorded: its name, what it is, and its temperatures (reported [degC] at 1 Hz)."""

    name: str
    description: str
    profile: UseProfile

    @property
    def hours(self) -> float:
        """Its chamber time [h]."""
        return float(self.profile.time_s[-1] - self.profile.time_s[0]) / 3600.0


@dataclass(frozen=True)
class RunAdvice:
    """A candidate run's predicted effect: each axis's forecast after it, and on the worst axis the gain per hour.

    Attributes
    ----------
    run : CandidateRun
        The run.
    after : DriftForecast
        The forecast with the run added.
    gain_dps_per_h : float
        The worst axis's expected drift now less after, per hour of the run [deg/s/h].
    resolves : str
        What it changes most, in words with its numbers.
    """

    run: CandidateRun
    after: DriftForecast
    gain_dps_per_h: float
    resolves: str


@dataclass(frozen=True)
class CalibrationPlan:
    """The forecast now and every candidate run's, best gain per hour first.

    Attributes
    ----------
    now : DriftForecast
        The drift the model should leave on the use profile as it is [deg/s].
    advice : tuple of RunAdvice
        Candidate runs, the best gain per hour first.
    enough : bool
        Whether no candidate lowers the worst axis's expected drift by :data:`WORTHWHILE_GAIN` or more.
    ramp_degc_per_min : float
        The calibration runs' ramp rate the candidates are built from [degC/min].
    range_degc : (float, float)
        The calibrated range of the model temperature [degC].
    """

    now: DriftForecast
    advice: tuple[RunAdvice, ...]
    enough: bool
    ramp_degc_per_min: float
    range_degc: tuple[float, float]

    def to_dict(self) -> dict:
        return {
            "now": self.now.to_dict(),
            "enough": self.enough,
            "ramp_degc_per_min": self.ramp_degc_per_min,
            "range_degc": list(self.range_degc),
            "advice": [
                {
                    "run": a.run.name,
                    "description": a.run.description,
                    "hours": a.run.hours,
                    "gain_dps_per_h": a.gain_dps_per_h,
                    "resolves": a.resolves,
                    "after": a.after.to_dict(),
                }
                for a in self.advice
            ],
        }


def ramp_rate_degc_per_min(recordings: Sequence[Recording]) -> float:
    """The runs' typical ramp rate [degC/min]: the median rate of the minutes whose temperature changes at more than
    a fifth of the fastest minutes' (the 95th percentile) rate."""
    rates = []
    for rec in recordings:
        if rec.temperature_degc is None:
            continue
        temps = rec.temperature_degc if rec.temperature_degc.ndim == 1 else rec.temperature_degc.mean(axis=1)
        grid = np.arange(rec.time_s[0], rec.time_s[-1], 60.0)
        if grid.size > 1:
            rates.append(np.abs(np.diff(np.interp(grid, rec.time_s, temps))))
    rates = np.concatenate(rates) if rates else np.zeros(0)
    moving = rates[rates > 0.2 * np.percentile(rates, 95)] if rates.size and np.percentile(rates, 95) > 0 else rates
    return float(np.median(moving)) if moving.size and np.median(moving) > 0 else 1.0


def candidate_runs(lo_degc: float, hi_degc: float, ramp: float, use: UseProfile) -> list[CandidateRun]:
    """The candidate runs of a calibration over [lo, hi] degC at ``ramp`` [degC/min], for the use profile ``use``."""
    span = hi_degc - lo_degc
    need_lo = min(float(use.temperature_degc.min()), lo_degc - WIDEN_SHARE * span)
    need_hi = max(float(use.temperature_degc.max()), hi_degc + WIDEN_SHARE * span)
    mid = (lo_degc + hi_degc) / 2
    made = [
        (
            "repeat",
            f"the same cycle again, {lo_degc:.0f}..{hi_degc:.0f} degC at {ramp:.2g} degC/min",
            [lo_degc, hi_degc, lo_degc],
            ramp,
            HOLD_S,
        ),
        (
            "colder",
            f"a cycle down to {need_lo:.0f} degC ({need_lo:.0f}..{hi_degc:.0f} at {ramp:.2g} degC/min)",
            [need_lo, hi_degc, need_lo],
            ramp,
            HOLD_S,
        ),
        (
            "hotter",
            f"a cycle up to {need_hi:.0f} degC ({lo_degc:.0f}..{need_hi:.0f} at {ramp:.2g} degC/min)",
            [lo_degc, need_hi, lo_degc],
            ramp,
            HOLD_S,
        ),
        (
            "wider",
            f"a cycle over {need_lo:.0f}..{need_hi:.0f} degC at {ramp:.2g} degC/min",
            [need_lo, need_hi, need_lo],
            ramp,
            HOLD_S,
        ),
        (
            "slower",
            f"a cycle over {lo_degc:.0f}..{hi_degc:.0f} degC at {ramp / 2:.2g} degC/min",
            [lo_degc, hi_degc, lo_degc],
            ramp / 2,
            HOLD_S,
        ),
        (
            "faster",
            f"a cycle over {lo_degc:.0f}..{hi_degc:.0f} degC at {ramp * 2:.2g} degC/min",
            [lo_degc, hi_degc, lo_degc],
            ramp * 2,
            HOLD_S,
        ),
        (
            "dwells",
            f"{DWELL_S / 60:.0f} min dwells at {lo_degc:.0f}, {mid:.0f} and {hi_degc:.0f} degC",
            [lo_degc, mid, hi_degc, mid, lo_degc],
            ramp,
            DWELL_S,
        ),
        (
            "heating leg",
            f"one heating leg {lo_degc:.0f} -> {hi_degc:.0f} degC at {ramp:.2g} degC/min",
            [lo_degc, hi_degc],
            ramp,
            HOLD_S,
        ),
        (
            "cooling leg",
            f"one cooling leg {hi_degc:.0f} -> {lo_degc:.0f} degC at {ramp:.2g} degC/min",
            [hi_degc, lo_degc],
            ramp,
            HOLD_S,
        ),
    ]
    return [CandidateRun(name, text, set_point_profile(points, r, hold, name)) for name, text, points, r, hold in made]


def _told_apart(info: AxisInformation, run, alternatives) -> dict:
    """The alternatives on ``info``'s axis a run would tell from the chosen model, with their chi-square."""
    found = {}
    for alt in alternatives:
        if info.axis in alt.axes:
            statistic = info.separation(run, alt)
            if statistic >= SEPARATION_CHI2:
                found[alt] = statistic
    return found


def _resolves(now: AxisForecast, after: AxisForecast, told: dict) -> str:
    """What a run changes most on an axis, in words with its numbers."""
    changes = [
        (
            now.model_choice_dps - after.model_choice_dps,
            "the model choice (it tells "
            + ", ".join(f"{alt.form} apart at {math.sqrt(x):.1f} sigma" for alt, x in told.items())
            + f"; their parting {now.model_choice_dps:.2g} -> {after.model_choice_dps:.2g} deg/s)",
        ),
        (
            now.extrapolation_dps - after.extrapolation_dps,
            f"the range (extrapolation {now.extrapolation_dps:.2g} -> {after.extrapolation_dps:.2g} deg/s)",
        ),
        (
            now.coefficients_dps - after.coefficients_dps,
            f"the curve (coefficients' share {now.coefficients_dps:.2g} -> {after.coefficients_dps:.2g} deg/s)",
        ),
    ]
    if now.lag_standard_error_s and after.lag_standard_error_s is not None:
        share = now.coefficients_dps * (1 - after.lag_standard_error_s / now.lag_standard_error_s)
        changes.append(
            (
                share,
                f"the lag ({now.lag_s:.0f} s +- {now.lag_standard_error_s:.2g} -> +- {after.lag_standard_error_s:.2g} s)",
            )
        )
    largest = max(change for change, _ in changes)
    return " and ".join(text for change, text in sorted(changes, key=lambda c: -c[0]) if change >= 0.5 * largest)


def plan_calibration(
    calibration: Calibration,
    recordings: Sequence[Recording],
    use: UseProfile | None = None,
    window_s: float = DEFAULT_WINDOW_S,
    model_choice: bool = True,
) -> CalibrationPlan:
    """The drift ``calibration`` should leave on ``use``, and which run to record next.

    Parameters
    ----------
    calibration : Calibration
        The fitted model.
    recordings : sequence of Recording
        The static calibration runs it was fitted on.
    use : UseProfile, optional
        The temperatures the gyro will see; default one heat-cool cycle over the calibrated range at the runs'
        ramp rate.
    window_s : float
        Moving-average window of the drift [s].
    model_choice : bool
        Fit the nearest forms the model choice could not tell apart, count how far they part on ``use``, and say
        which candidate run tells them apart (a fit of the runs each).

    Returns
    -------
    CalibrationPlan
        The forecast now, each candidate run's gain per hour (best first), and whether more runs pay.
    """
    infos = axis_information(calibration, recordings, window_s)
    axes = list(infos)
    lo = min(i.lo_degc for i in infos.values())
    hi = max(i.hi_degc for i in infos.values())
    ramp = ramp_rate_degc_per_min(recordings)
    if use is None:
        use = UseProfile.cycle(
            lo, hi, ramp, name=f"one cycle {lo:.0f}..{hi:.0f} degC at {ramp:.2g} degC/min (the calibration's)"
        )
    close = {a: close_candidates(calibration, a) for a in axes}
    alternatives = choice_alternatives(calibration, recordings) if model_choice else ()
    now = DriftForecast(
        use.name, window_s, {a: i.forecast(use, window_s, (), close[a], alternatives) for a, i in infos.items()}
    )
    worst_now = now.worst.drift_dps
    advice = []
    for run in candidate_runs(lo, hi, ramp, use):
        extra = {a: i.with_run(run.profile.time_s, run.profile.temperature_degc, run.name) for a, i in infos.items()}
        told = {a: _told_apart(i, extra[a], alternatives) for a, i in infos.items()}
        after = DriftForecast(
            use.name,
            window_s,
            {
                a: i.forecast(use, window_s, [extra[a]], close[a], [alt for alt in alternatives if alt not in told[a]])
                for a, i in infos.items()
            },
        )
        worst = now.worst.axis
        advice.append(
            RunAdvice(
                run,
                after,
                (worst_now - after.worst.drift_dps) / run.hours,
                _resolves(now.axes[worst], after.axes[worst], told[worst]),
            )
        )
    advice.sort(key=lambda a: -a.gain_dps_per_h)
    best_after = min((a.after.worst.drift_dps for a in advice), default=worst_now)
    enough = not math.isfinite(best_after) or worst_now - best_after < WORTHWHILE_GAIN * worst_now
    return CalibrationPlan(now, tuple(advice), enough, ramp, (lo, hi))


__all__ = [
    "CalibrationPlan",
    "CandidateRun",
    "RunAdvice",
    "candidate_runs",
    "plan_calibration",
    "ramp_rate_degc_per_min",
]
