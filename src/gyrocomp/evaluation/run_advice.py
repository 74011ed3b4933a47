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

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field


from ..calibration.calibration import Calibration
from ..errors import InputError
from ..measures.ramp_rate import ramp_rate_degc_per_min
from ..recording import Recording
from ..threads import single_threaded_blas
from .choice_alternatives import choice_alternatives, close_candidates
from .drift_forecast import (
    DEFAULT_WINDOW_S,
    AxisForecast,
    AxisInformation,
    axis_information,
    calibrated_range,
    calibration_cycle,
    DriftForecast,
    UseProfile,
    set_point_profile,
    warn_faster_use,
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
    """A run not yet recorded, as a chamber is programmed.

    Attributes
    ----------
    name : str
        Its short name (``wider``, ``faster`` ...).
    what : str
        What it is, in words.
    set_points_degc : tuple of float
        The chamber's set points in turn [degC].
    ramp_degc_per_min : float
        The ramp rate between them [degC/min].
    hold_s : float
        The hold at each set point [s].
    """

    name: str
    what: str
    set_points_degc: tuple[float, ...]
    ramp_degc_per_min: float
    hold_s: float

    @functools.cached_property
    def profile(self) -> UseProfile:
        """Its temperatures (reported [degC] at 1 Hz)."""
        return set_point_profile(self.set_points_degc, self.ramp_degc_per_min, self.hold_s, self.name)

    @property
    def hours(self) -> float:
        """Its chamber time [h]."""
        return float(self.profile.time_s[-1] - self.profile.time_s[0]) / 3600.0

    @property
    def description(self) -> str:
        """What it is and how to program it."""
        points = " -> ".join(f"{p:.0f}" for p in self.set_points_degc)
        return f"{self.what}: {points} degC at {self.ramp_degc_per_min:.2g} degC/min, {self.hold_s / 60:.0f} min holds"


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
    sequence : tuple of RunAdvice
        Within ``budget_h``: the runs to record one after another, each the best gain per hour after those before
        it (each one's ``after`` with all before it added).
    budget_h : float or None
        The chamber time the sequence was planned for [h].
    target_drift_dps : float or None
        The drift it was planned to reach [deg/s].
    """

    now: DriftForecast
    advice: tuple[RunAdvice, ...]
    enough: bool
    ramp_degc_per_min: float
    range_degc: tuple[float, float]
    sequence: tuple[RunAdvice, ...] = ()
    budget_h: float | None = None
    target_drift_dps: float | None = None

    @property
    def reaches_target(self) -> bool | None:
        """Whether the sequence reaches the target (None: no target)."""
        if self.target_drift_dps is None:
            return None
        last = self.sequence[-1].after if self.sequence else self.now
        return last.worst.drift_dps <= self.target_drift_dps

    def to_dict(self) -> dict:
        def advice(a: RunAdvice) -> dict:
            return {
                "run": a.run.name,
                "description": a.run.description,
                "set_points_degc": list(a.run.set_points_degc),
                "ramp_degc_per_min": a.run.ramp_degc_per_min,
                "hold_s": a.run.hold_s,
                "hours": a.run.hours,
                "gain_dps_per_h": a.gain_dps_per_h,
                "resolves": a.resolves,
                "after": a.after.to_dict(),
            }

        return {
            "now": self.now.to_dict(),
            "enough": self.enough,
            "ramp_degc_per_min": self.ramp_degc_per_min,
            "range_degc": list(self.range_degc),
            "advice": [advice(a) for a in self.advice],
            "budget_h": self.budget_h,
            "target_drift_dps": self.target_drift_dps,
            "reaches_target": self.reaches_target,
            "sequence": [advice(a) for a in self.sequence],
        }


def candidate_runs(lo_degc: float, hi_degc: float, ramp: float, use: UseProfile) -> list[CandidateRun]:
    """The candidate runs of a calibration over [lo, hi] degC at ``ramp`` [degC/min], for the use profile ``use``:
    the range widened to the use profile's, or a quarter of the span past each end."""
    span = hi_degc - lo_degc
    cold = min(float(use.temperature_degc.min()), lo_degc - WIDEN_SHARE * span)
    hot = max(float(use.temperature_degc.max()), hi_degc + WIDEN_SHARE * span)
    mid = (lo_degc + hi_degc) / 2

    def cycle(a: float, b: float, rate: float = ramp) -> tuple:
        return (a, b, a), rate, HOLD_S

    specs = {
        "repeat": ("the same cycle again", *cycle(lo_degc, hi_degc)),
        "colder": ("a cycle to a colder end", *cycle(cold, hi_degc)),
        "hotter": ("a cycle to a hotter end", *cycle(lo_degc, hot)),
        "wider": ("a cycle past both ends", *cycle(cold, hot)),
        "slower": ("the cycle at half the ramp rate", *cycle(lo_degc, hi_degc, ramp / 2)),
        "faster": ("the cycle at twice the ramp rate", *cycle(lo_degc, hi_degc, ramp * 2)),
        "dwells": ("dwells at the ends and the middle", (lo_degc, mid, hi_degc, mid, lo_degc), ramp, DWELL_S),
        "heating leg": ("one heating leg", (lo_degc, hi_degc), ramp, HOLD_S),
        "cooling leg": ("one cooling leg", (hi_degc, lo_degc), ramp, HOLD_S),
    }
    return [CandidateRun(name, what, points, rate, hold) for name, (what, points, rate, hold) in specs.items()]


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


@dataclass
class _Planner:
    """The runs' information per axis, the use profile and the alternatives, and what the runs chosen so far add."""

    infos: dict[str, AxisInformation]
    use: UseProfile
    window_s: float
    close: dict[str, tuple[str, ...]]
    alternatives: tuple
    extra: dict[str, list] = field(default_factory=dict)
    told: dict[str, set] = field(default_factory=dict)

    def forecast(self, extra: dict[str, list], told: dict[str, set]) -> DriftForecast:
        return DriftForecast(
            self.use.name,
            self.window_s,
            {
                a: i.forecast(
                    self.use,
                    self.window_s,
                    extra.get(a, []),
                    self.close[a],
                    [alt for alt in self.alternatives if alt not in told.get(a, set())],
                )
                for a, i in self.infos.items()
            },
        )

    def score(self, run: CandidateRun, now: DriftForecast) -> tuple[RunAdvice, dict, dict]:
        """The advice for ``run`` after the runs chosen so far, and the information and resolved alternatives
        with it."""
        added = {
            a: i.with_run(run.profile.time_s, run.profile.temperature_degc, run.name) for a, i in self.infos.items()
        }
        found = {a: _told_apart(i, added[a], self.alternatives) for a, i in self.infos.items()}
        extra = {a: [*self.extra.get(a, []), added[a]] for a in self.infos}
        told = {a: self.told.get(a, set()) | set(found[a]) for a in self.infos}
        after = self.forecast(extra, told)
        worst = now.worst.axis
        gain = (now.worst.drift_dps - after.worst.drift_dps) / run.hours
        return RunAdvice(run, after, gain, _resolves(now.axes[worst], after.axes[worst], found[worst])), extra, told


def _within(
    planner: _Planner, runs: list[CandidateRun], now: DriftForecast, budget_h: float, target_dps: float | None
) -> tuple[RunAdvice, ...]:
    """Runs chosen one after another (each candidate once), each the best gain per hour after those before it that
    fits in what is left of ``budget_h`` [h], while one still lowers the drift and the worst axis's is above
    ``target_dps`` [deg/s]."""
    chosen, left = [], budget_h
    while target_dps is None or now.worst.drift_dps > target_dps:
        scored = [planner.score(r, now) for r in runs if r.hours <= left and all(r is not c.run for c in chosen)]
        scored = [s for s in scored if s[0].gain_dps_per_h > 0]
        if not scored:
            return tuple(chosen)
        best, planner.extra, planner.told = max(scored, key=lambda s: s[0].gain_dps_per_h)
        chosen.append(best)
        left -= best.run.hours
        now = best.after
    return tuple(chosen)


@single_threaded_blas
def plan(
    calibration: Calibration,
    recordings: Sequence[Recording],
    use: UseProfile | None = None,
    window_s: float = DEFAULT_WINDOW_S,
    model_choice: bool = True,
    budget_h: float | None = None,
    target_drift_dps: float | None = None,
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
    budget_h : float, optional
        Chamber time to spend [h]: the runs to record one after another within it (:attr:`CalibrationPlan.sequence`).
    target_drift_dps : float, optional
        The worst axis's expected drift to reach [deg/s]: the sequence stops at the run that reaches it (within
        ``budget_h`` when given).

    Returns
    -------
    CalibrationPlan
        The forecast now, each candidate run's gain per hour (best first), whether more runs pay, and within a
        budget the runs to record in turn.
    """
    if budget_h is not None and not (math.isfinite(budget_h) and budget_h > 0):
        raise InputError(f"budget_h: {budget_h!r}; give the chamber hours to spend, a positive number")
    if target_drift_dps is not None and not (math.isfinite(target_drift_dps) and target_drift_dps > 0):
        raise InputError(f"target_drift_dps: {target_drift_dps!r}; give the drift to reach, a positive number of deg/s")
    infos = axis_information(calibration, recordings, window_s)
    lo, hi = calibrated_range(infos)
    ramp = ramp_rate_degc_per_min(recordings)
    use = calibration_cycle(infos, ramp) if use is None else use
    warn_faster_use(use, ramp)
    alternatives = choice_alternatives(calibration, recordings) if model_choice else ()
    planner = _Planner(infos, use, window_s, {a: close_candidates(calibration, a) for a in infos}, alternatives)
    now = planner.forecast({}, {})
    runs = candidate_runs(lo, hi, ramp, use)
    advice = sorted((planner.score(run, now)[0] for run in runs), key=lambda a: -a.gain_dps_per_h)
    worst_now = now.worst.drift_dps
    best_after = min((a.after.worst.drift_dps for a in advice), default=worst_now)
    enough = not math.isfinite(best_after) or worst_now - best_after < WORTHWHILE_GAIN * worst_now
    planned = budget_h is not None or target_drift_dps is not None
    sequence = _within(planner, runs, now, budget_h or math.inf, target_drift_dps) if planned else ()
    return CalibrationPlan(now, tuple(advice), enough, ramp, (lo, hi), sequence, budget_h, target_drift_dps)


__all__ = ["CalibrationPlan", "CandidateRun", "RunAdvice", "candidate_runs", "plan"]
