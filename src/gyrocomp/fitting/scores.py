"""The rule that chooses among the candidates' held-out scores (:mod:`gyrocomp.fitting.selection` makes the scores).

A candidate's score is its held-out drift on every fold [the axis's unit]; its mean over folds is what it is
judged by. The least complex candidate whose mean is within one standard error (of the best candidate's mean over
folds) of the best is chosen: Breiman's one-standard-error rule. (Its paired form, on per-fold differences, was
tried and rejected: with three folds its standard error is so uncertain that a candidate far worse on one fold
passes.) Do no harm: a temperature model is kept only where it beats the run constant alone
(:func:`beats_constant`).

References: L. Breiman et al., *Classification and Regression Trees*, 1984, section 3.4.3 (the one-SE rule);
T. Hastie, R. Tibshirani, J. Friedman, *The Elements of Statistical Learning*, 2nd ed., 2009, section 7.10.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..curves.polynomial import POLY_FAMILY
from ..calibration.candidate import Candidate
from ..units import AxisUnit, unit_suffix


def json_number(value: float) -> float | None:
    """A score for a JSON file: None where it could not be computed (too little held-out data)."""
    return float(value) if math.isfinite(value) else None


def fold_mean(fold_drift: tuple[float, ...]) -> float:
    """Mean of the held-out drift over the folds [the drift's unit]."""
    return float(np.mean(fold_drift))


def fold_standard_error(fold_drift: tuple[float, ...]) -> float:
    """Standard error of the mean over the folds [the drift's unit] (NaN with one fold)."""
    f = len(fold_drift)
    return float(np.std(fold_drift, ddof=1) / math.sqrt(f)) if f > 1 else math.nan


@dataclass(frozen=True)
class CandidateScore:
    """Held-out drift of one candidate on every fold [the axis's unit: deg/s for a gyro axis, g for an
    accelerometer axis], and what each fold's fit chose for the lag [s]; ``short_fold_drift`` the same drift
    at the short window (:attr:`gyrocomp.fitting.selection.SelectionProblem.short_window_s`), where it was asked
    for (``SelectionProblem.score(..., short_window=True)``; empty elsewhere, and not stored in the model file)."""

    candidate: Candidate
    fold_drift: tuple[float, ...]
    fold_lag_s: tuple[float, ...]
    short_fold_drift: tuple[float, ...] = ()

    def at_short_window(self) -> "CandidateScore":
        """The same candidate scored by its drift at the short window."""
        return CandidateScore(self.candidate, self.short_fold_drift, self.fold_lag_s)

    @property
    def mean_drift(self) -> float:
        return fold_mean(self.fold_drift)

    @property
    def standard_error(self) -> float:
        return fold_standard_error(self.fold_drift)

    def to_dict(self, unit: AxisUnit = "deg/s") -> dict:
        """As the model file stores it: the drifts under names that say ``unit``."""
        u = unit_suffix(unit)
        return {
            **self.candidate.to_dict(),
            f"mean_drift{u}": json_number(self.mean_drift),
            f"standard_error{u}": json_number(self.standard_error),
            f"fold_drift{u}": [json_number(v) for v in self.fold_drift],
            "fold_lag_s": list(self.fold_lag_s),
        }


def paired_difference(worse: CandidateScore, better: CandidateScore) -> tuple[float, float]:
    """Mean over folds of ``worse``'s held-out drift minus ``better``'s, and the standard error of that mean
    [the drift's unit] (NaN with one fold). Both were scored on the same folds, so the spread of the folds'
    levels (a cooling leg that drifts more than a heating leg) cancels in the difference."""
    d = np.asarray(worse.fold_drift) - np.asarray(better.fold_drift)
    return float(np.mean(d)), fold_standard_error(tuple(d))


#: with two folds, a temperature model must leave at most this share of the run constant's drift on each
TWO_FOLD_RATIO = 0.5


def beats_constant(score: CandidateScore, constant: CandidateScore) -> bool:
    """Do no harm: whether ``score``'s candidate leaves less held-out drift than the run constant alone by more
    than the standard error of the paired difference over the folds.

    With two folds that standard error rests on one degree of freedom and says little; the candidate must then
    at least halve the constant's drift on both (:data:`TWO_FOLD_RATIO`). A slow random walk unrelated to
    temperature often follows the temperature on one heating and one cooling leg by chance, and a curve fitted
    to it makes the next leg worse (measured on a simulated one-cycle run: a chance fit cut the two legs' drift by 39
    and 49 %, and left the next leg 40 % worse than raw; the ADXRS450's temperature dependence cut them by 97 %).
    With one fold: better by anything."""
    gain, se = paired_difference(constant, score)
    if not np.isfinite(gain):
        return False
    if not np.isfinite(se):
        return gain > 0
    if len(score.fold_drift) == 2:
        return bool(np.all(np.asarray(score.fold_drift) <= TWO_FOLD_RATIO * np.asarray(constant.fold_drift)))
    return bool(gain > se)


def harms(score: CandidateScore, constant: CandidateScore) -> bool:
    """Whether ``score``'s candidate leaves more held-out drift than the run constant alone by more than the standard
    error of the paired difference over the folds (by anything, with one fold; not where the folds could not be
    scored): the last check of every choice, whatever rule or test made it."""
    loss, se = paired_difference(score, constant)
    if not np.isfinite(loss):
        return False
    return bool(loss > (se if np.isfinite(se) else 0.0))


def helps_on_every_fold(score: CandidateScore, constant: CandidateScore) -> bool:
    """Whether ``score``'s candidate leaves less held-out drift than the run constant alone on every fold."""
    mine, theirs = np.asarray(score.fold_drift), np.asarray(constant.fold_drift)
    return bool(np.all(np.isfinite(mine)) and np.all(mine < theirs))


def choose(
    scores: list[CandidateScore], complexity, constant: CandidateScore | None = None
) -> tuple[Candidate, Candidate]:
    """(best, chosen).

    ``best`` has the lowest mean held-out drift. ``chosen`` is the least complex candidate whose mean lies within
    one standard error (of the best candidate's mean over folds) of the best's; ties in complexity go to the
    lower score. (A tolerance from the paired per-fold differences was tried: it moved the choice on the CATS
    recording to terms that doubled a held-out run's drift.) With ``constant`` (the run constant's score), only
    candidates that beat it (:func:`beats_constant`) may be chosen; when none does, the constant is."""
    finite = [s for s in scores if np.all(np.isfinite(s.fold_drift))]
    if not finite:  # too little data to hold anything out: the simplest candidate, unvalidated
        simplest = min(scores, key=lambda s: complexity(s.candidate)).candidate
        return simplest, simplest
    finite = _other_families_that_earn_it(finite)
    best = min(finite, key=lambda s: s.mean_drift)
    if constant is not None and np.all(np.isfinite(constant.fold_drift)):
        finite = [s for s in finite if not s.candidate.has_temperature_model or beats_constant(s, constant)]
        if not finite:
            return best.candidate, constant.candidate
    pool_best = min(finite, key=lambda s: s.mean_drift)
    se = pool_best.standard_error if len(pool_best.fold_drift) > 1 else 0.0
    accepted = [s for s in finite if s.mean_drift <= pool_best.mean_drift + se]
    chosen = min(accepted, key=lambda s: (complexity(s.candidate), s.mean_drift))
    return best.candidate, chosen.candidate


def _other_families_that_earn_it(finite: list[CandidateScore]) -> list[CandidateScore]:
    """The scores without the candidates of a curve family other than the polynomial (a lookup table) that do not
    beat the best polynomial on the held-out folds as a temperature model must beat the constant
    (:func:`beats_constant`: by more than the standard error of the paired difference; with two folds, half its
    drift on both). A table has many terms and follows what the folds share by chance: measured on a simulated
    fleet of consumer-grade units (three 15-minute runs each), tables chosen by the one-SE rule alone moved the
    units' temperature figures off their truth and tripled the good units flagged as outliers."""
    polys = [s for s in finite if s.candidate.curve == POLY_FAMILY and s.candidate.has_temperature_model]
    if not polys:
        return finite
    best_poly = min(polys, key=lambda s: s.mean_drift)
    return [s for s in finite if s.candidate.curve == POLY_FAMILY or beats_constant(s, best_poly)]


__all__ = [
    "CandidateScore",
    "TWO_FOLD_RATIO",
    "beats_constant",
    "choose",
    "fold_mean",
    "fold_standard_error",
    "harms",
    "helps_on_every_fold",
    "json_number",
    "paired_difference",
]
