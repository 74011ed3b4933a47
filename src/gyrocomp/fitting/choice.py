"""Each axis's choice among its candidates' held-out scores, and the choices of the axes of one die together.

:mod:`gyrocomp.fitting.selection` scores a candidate on the folds (:meth:`SelectionProblem.score`) and
:mod:`gyrocomp.fitting.scores` holds the rule that chooses among scores (one standard error, do no harm). Here:

- which candidates may be chosen at all (a lag some fold puts at the top of its search is not a lag:
  :func:`unidentified_lags`), :func:`score_axis`;
- the choice for one axis, and where no fold can judge branch terms, the test that decides them
  (:func:`choose_axis`);
- the axes behind one temperature sensor: one lag per fold while scoring (:func:`share_fold_lags`), and the
  die's lag for an axis whose folds cannot tell its model with and without it (:func:`select_axes`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..curves.polynomial import POLY_FAMILY
from ..calibration.candidate import Candidate, Weighting
from ..calibration.fit_report import BranchTest, OrderTest
from ..errors import InputError
from .branch_evidence import branch_test
from .order_evidence import order_test
from .scores import CandidateScore, choose, harms, helps_on_every_fold, paired_difference
from .axis_selection import AxisSelection
from .selection import WEIGHTINGS, SelectionProblem
from .thermal import MAX_BRANCH_ORDER


def share_fold_lags(
    problems: list[SelectionProblem], orders: tuple[int, ...], weightings: tuple[Weighting, ...] = WEIGHTINGS
) -> None:
    """Give the axes one lag per fold and per (order, weighting): the lag is the die's, behind one temperature
    sensor, and the axes together pin it down better than any one of them (as the final fit does, see
    :class:`gyrocomp.fitting.thermal.ThermalHysteresisModel`'s ``shared_lag``). Each fold's lag minimizes the
    sum over axes of their relative training residuals (:meth:`SelectionProblem.lag_rss`). The problems must
    share their runs' times and folds; nothing is shared otherwise."""
    if len(problems) < 2 or len({(p.folds.count, p.block_s) for p in problems}) > 1:
        return
    grid = problems[0].lag_grid_s()
    for order in (o for o in orders if o > 0):
        for weighting in weightings:
            total = sum(p.lag_rss(order, weighting, grid) for p in problems)
            taus = grid[np.argmin(total, axis=1)]
            for p in problems:
                p.fold_lags_s[(order, weighting)] = taus


def unidentified_lags(scores: list[CandidateScore], top_s: float) -> set[Candidate]:
    """The lag candidates whose lag some fold's training data put at the top of the search (``top_s`` [s], the
    largest lag of :meth:`SelectionProblem.lag_grid_s`): there the least residual wants a longer time constant
    still, i.e. the lagged temperature stands for a slow drift in time, not for a die that follows its sensor.
    Such a candidate follows the drift its held-out legs share with their neighbours (the same runs), and the
    next run pays for it (measured before the search stopped at half the longest run: an ADIS16488-like part,
    true lag 300 s, two cycles: lag 11,100 s, the longest run, and poly:5 chosen; the third run 2.7x worse than
    raw)."""
    return {s.candidate for s in scores if s.candidate.lag and max(s.fold_lag_s, default=0.0) >= top_s * (1 - 1e-9)}


@dataclass(frozen=True)
class AxisScores:
    """Every candidate's held-out score on one axis (the run constant's among them) and the candidates that may
    be chosen (those asked for, less the lags the data did not identify: :func:`unidentified_lags`)."""

    scores: tuple[CandidateScore, ...]
    eligible: frozenset[Candidate]


def score_axis(
    axis: str,
    problem: SelectionProblem,
    orders: tuple[int, ...],
    memories: tuple[str, ...],
    weightings: tuple[Weighting, ...] = WEIGHTINGS,
) -> AxisScores:
    """Score every candidate of one axis on the held-out folds (:meth:`SelectionProblem.score`)."""
    cands = problem.candidates(orders, memories, weightings)
    if not cands:
        raise InputError(
            f"hysteresis={'/'.join(memories)!r}: the temperature of {axis} never reverses in these "
            "runs, so there is no branch to fit; use hysteresis='none' or 'lag'"
        )
    eligible = set(cands)
    if Candidate(0) not in cands:  # the reference every score is read against; chosen only when asked for
        cands.insert(0, Candidate(0))
    scores = tuple(problem.score(c) for c in cands)
    return AxisScores(scores, frozenset(eligible - unidentified_lags(scores, float(problem.lag_grid_s()[-1]))))


#: with this many folds (one heating and one cooling leg), the held-out scores alone are thin evidence
TWO_FOLDS = 2


def choose_axis(
    axis: str, problem: SelectionProblem, scored: AxisScores, do_no_harm: bool = True, unit_lag: bool = False
) -> AxisSelection:
    """Choose among the scores of one axis (see the module doc); with ``do_no_harm``, a temperature model only
    where it beats the run constant (:func:`gyrocomp.fitting.scores.beats_constant`; with two folds,
    :func:`_choose_on_two_folds`), and whatever rule or test chose, never a model that leaves more held-out drift
    than the constant by more than the standard error (:func:`gyrocomp.fitting.scores.harms`): do no harm is the
    last word. :attr:`AxisSelection.decided_by` says which rule made the choice.

    ``unit_lag``: another axis behind the same temperature sensor chose a thermal lag, so the die has one; here
    the lag costs nothing and, between candidates of equal complexity the held-out folds cannot tell apart (within
    one standard error), the one with the lag is taken. Held-out legs remove each leg's mean, and a lag shifts a
    steady ramp by a constant, so the legs see a lag only at turns and holds; the next leg sees all of it (measured
    on a simulated consumer-grade part, true lag 30 s, one cycle at 2 degC/min: an axis left without the lag its
    two sister axes found drifted 4.2x the noise on the next leg, 1.2x with it; the final fit keeps it only where
    the axis's own runs see it, :attr:`AxisSelection.alone` being the fallback). Where the branch terms are decided
    by their test (one heating and one cooling leg), they are tested beyond the die's lag, which parts the two legs
    as well (by the slope times the ramp rate times the lag), and only on an axis the held-out legs gave a
    temperature model: a test adds terms only where the held-out legs do not contradict it."""
    constant = next(s for s in scored.scores if s.candidate == Candidate(0))
    complexity = _with_free_lag if unit_lag else problem.complexity
    offered = [s for s in scored.scores if s.candidate in scored.eligible]
    evidence = None
    if do_no_harm and problem.folds.count == TWO_FOLDS:
        best, chosen, decided_by, evidence = _choose_on_two_folds(problem, offered, complexity, constant)
    else:
        best, chosen = choose(offered, complexity, constant if do_no_harm else None)
        decided_by = (
            f"held-out drift ({problem.window_s:.3g} s window): the simplest within one standard error of the best"
            if do_no_harm
            else f"held-out drift ({problem.window_s:.3g} s window) among the candidates asked for"
        )
        if do_no_harm and not chosen.has_temperature_model and best.has_temperature_model:
            decided_by = "do no harm: no temperature model beats the constant on the held-out folds"
    chosen, decided_by = _lag_at_the_short_window(problem, scored, chosen, decided_by)
    chosen, test, decided_by = _branch_step(problem, scored, chosen, decided_by, unit_lag)
    if do_no_harm and chosen.has_temperature_model and harms(_score(scored, chosen), constant):
        decided_by = (
            f"do no harm: {chosen.label} leaves more held-out drift than the constant by more than its standard error"
        )
        chosen = constant.candidate
    return AxisSelection(
        axis,
        problem.folds.kind,
        problem.folds.names,
        problem.window_s,
        problem.temperature_step_degc,
        scored.scores,
        best,
        chosen,
        problem.band_degc,
        problem.unit,
        problem.folds.note,
        test,
        lag_from_unit=unit_lag and chosen.lag,
        decided_by=decided_by,
        order_test=evidence,
        ramp_rates_degc_per_min=problem.ramp_rates_degc_per_min,
    )


def _branch_step(problem: SelectionProblem, scored: AxisScores, chosen: Candidate, decided_by: str, unit_lag: bool):
    """Where the branch terms are decided by their test (no fold holds both directions), the chosen candidate with
    the terms the test keeps (beyond the die's lag where ``unit_lag``), the test, and what decided."""
    if (
        not problem.branch_orders
        or not chosen.has_temperature_model
        or chosen.branch
        or chosen.hysteresis_order
        or np.any(problem.fold_has_both_directions())
    ):
        return chosen, None, decided_by
    twin = dataclasses.replace(chosen, lag=True)
    if unit_lag and twin in scored.eligible:
        chosen = twin  # a lag also parts the heating and cooling legs: the branch terms are tested beyond it
    chosen, test = _branch_by_test(problem, chosen, list(scored.scores), set(scored.eligible))
    if test is not None and test.order:
        decided_by += f"; branch terms by their test (Wald {test.statistic:.3g} against {test.threshold:.3g})"
    return chosen, test, decided_by


def _lag_at_the_short_window(
    problem: SelectionProblem, scored: AxisScores, chosen: Candidate, decided_by: str
) -> tuple[Candidate, str]:
    """``chosen`` with a thermal lag where the lag leaves less held-out drift at the short window (the thesis's
    timescale, :attr:`SelectionProblem.short_window_s`, where that is half the score's window or less) by more than
    the standard error of the paired difference over the folds (with two folds, on both), and no more at the
    score's window by more than that one's: a lag of tens of seconds shows at tens of seconds, and is averaged away
    at the long window the other candidates are told apart by (held-out legs remove each leg's mean, and a lag
    shifts a steady ramp by a constant)."""
    twin = dataclasses.replace(chosen, lag=True)
    if (
        chosen.lag
        or not chosen.has_temperature_model
        or twin not in scored.eligible
        or not 2.0 * problem.short_window_s <= problem.window_s
    ):
        return chosen, decided_by
    mine, theirs = problem.score(chosen, short_window=True), problem.score(twin, short_window=True)
    gain, se = paired_difference(mine.at_short_window(), theirs.at_short_window())
    loss, se_long = paired_difference(theirs, mine)
    # with two folds the standard error rests on one degree of freedom: the lag must then be better on both
    consistent = len(mine.fold_drift) > TWO_FOLDS or helps_on_every_fold(
        theirs.at_short_window(), mine.at_short_window()
    )
    if np.isfinite(gain) and np.isfinite(se) and gain > se and consistent and not loss > se_long:
        window = f"{problem.short_window_s:.3g} s"
        return twin, decided_by + f"; the lag by the {window} window (its drift there {gain:.3g} less, +- {se:.3g})"
    return chosen, decided_by


def _score(scored: AxisScores, candidate: Candidate) -> CandidateScore:
    return next(s for s in scored.scores if s.candidate == candidate)


def _choose_on_two_folds(
    problem: SelectionProblem, offered: list[CandidateScore], complexity, constant: CandidateScore
) -> tuple[Candidate, Candidate, str, OrderTest]:
    """(best, chosen, the rule that decided, the order test) where one heating and one cooling leg are the only
    folds.

    Two held-out numbers per candidate, one of them partly beyond its training range, say whether the axis follows
    its temperature at all, and little about how: the simplest candidate within their standard error is often too
    simple (on the real one-cycle log tofupilot, poly:2 on an axis a cubic fits to 0.04 deg/s; 0.09 chosen).
    So the two kinds of evidence each answer the question they can:

    - *whether*: some temperature model must leave less drift than the constant on both held-out legs (a drift
      that follows the temperature on one leg by chance does not on the other: measured on the real log's gyro_x,
      whose drift is not repeatable with temperature, no curve did), and the order test on all the data
      (:func:`gyrocomp.fitting.order_evidence.order_test`) must find a term beyond the drift;
    - *how*: the simplest candidate within one standard error of the best, among those that do no harm
      (:func:`gyrocomp.fitting.scores.harms`), its polynomial raised to the order the test supports where that
      candidate is offered and does no harm either.
    """
    finite = [s for s in offered if np.all(np.isfinite(s.fold_drift))]
    best = min(finite or offered, key=lambda s: s.mean_drift).candidate
    pool = [s for s in finite if s.candidate.has_temperature_model and not harms(s, constant)]
    if not pool:
        return (
            best,
            constant.candidate,
            "do no harm: every temperature model leaves more held-out drift than the "
            "constant by more than its standard error",
            order_test(problem.runs, problem.groups, problem.t_ref_degc, problem.t_scale_degc, 0, 0.0, problem.block_s),
        )
    _, held_out = choose(pool, complexity)
    tau = float(np.median(_of(pool, held_out).fold_lag_s)) if held_out.lag else 0.0
    test = _order_test(problem, tau)
    if not any(helps_on_every_fold(s, constant) for s in finite if s.candidate.has_temperature_model):
        return (
            best,
            constant.candidate,
            "do no harm: no temperature model leaves less drift than the constant on both held-out legs",
            test,
        )
    if test.order == 0:
        return (
            best,
            constant.candidate,
            "do no harm: no term of the temperature curve stands out of the drift "
            f"(order test, largest Wald {max(test.statistics, default=0.0):.3g} against {test.threshold:.3g})",
            test,
        )
    chosen, rule = _raised_order(problem, held_out, test, {s.candidate for s in pool})
    return best, chosen, rule, test


def _order_test(problem: SelectionProblem, tau_s: float) -> OrderTest:
    """The order test (:func:`gyrocomp.fitting.order_evidence.order_test`) on all of an axis's data, its lag
    ``tau_s`` [s], the acceleration columns fitted with it."""
    accel = [problem.accel_columns(k) for k in range(len(problem.runs))]
    return order_test(
        problem.runs,
        problem.groups,
        problem.t_ref_degc,
        problem.t_scale_degc,
        problem.max_order,
        tau_s,
        problem.block_s,
        accel if accel[0].shape[1] else None,
    )


def _raised_order(problem: SelectionProblem, held_out: Candidate, test: OrderTest, in_pool: set) -> tuple:
    """The held-out legs' choice with its polynomial raised to the highest order the test supports that is in
    ``in_pool`` (offered, doing no harm), and the rule that decided."""
    if held_out.curve == POLY_FAMILY and held_out.order < test.order:
        for order in range(test.order, held_out.order, -1):
            raised = dataclasses.replace(held_out, order=order)
            if raised in in_pool:
                statistic = test.statistics[order - 1]
                return raised, (
                    f"two held-out legs ({problem.window_s:.3g} s window), the order raised from "
                    f"{held_out.order} by the order test "
                    f"(the u^{order} term stands out of the drift: Wald {statistic:.3g} against "
                    f"{test.threshold:.3g})"
                )
    return held_out, (
        f"two held-out legs ({problem.window_s:.3g} s window): the simplest within one standard error of the best"
    )


def _of(scores: list[CandidateScore], candidate: Candidate) -> CandidateScore:
    return next(s for s in scores if s.candidate == candidate)


def _with_free_lag(c: Candidate) -> tuple[int, bool]:
    """Complexity with the lag free and, at equal complexity, a temperature model with the lag first."""
    return c.complexity - int(c.lag), c.has_temperature_model and not c.lag


def select_axis(
    axis: str,
    problem: SelectionProblem,
    orders: tuple[int, ...],
    memories: tuple[str, ...],
    weightings: tuple[Weighting, ...] = WEIGHTINGS,
    do_no_harm: bool = True,
) -> AxisSelection:
    """Score every candidate of one axis and choose (:func:`score_axis`, :func:`choose_axis`)."""
    return choose_axis(axis, problem, score_axis(axis, problem, orders, memories, weightings), do_no_harm)


def select_axes(
    problems: dict[str, SelectionProblem],
    orders: tuple[int, ...],
    memories: tuple[str, ...],
    do_no_harm: bool = True,
    one_die: bool = True,
) -> dict[str, AxisSelection]:
    """Choose every axis's model (:func:`select_axis`). With ``one_die`` (one temperature column for every
    axis), when some axis chooses a thermal lag, the others choose again with the die's lag free
    (``unit_lag`` of :func:`choose_axis`); their scores are not computed again."""
    scored = {axis: score_axis(axis, p, orders, memories) for axis, p in problems.items()}
    out = {axis: choose_axis(axis, problems[axis], scored[axis], do_no_harm) for axis in problems}
    if one_die and any(sel.chosen.lag for sel in out.values()):
        out = {
            axis: sel if sel.chosen.lag else _with_the_dies_lag(problems[axis], scored[axis], sel, do_no_harm)
            for axis, sel in out.items()
        }
    return out


def _with_the_dies_lag(
    problem: SelectionProblem, scored: AxisScores, alone: AxisSelection, do_no_harm: bool
) -> AxisSelection:
    """``alone``'s axis chosen again with the die's lag free (:func:`choose_axis`), keeping ``alone`` to fall back
    on."""
    again = choose_axis(alone.axis, problem, scored, do_no_harm, unit_lag=True)
    return dataclasses.replace(again, alone=alone) if again.lag_from_unit else alone


def _branch_by_test(
    problem: SelectionProblem, chosen: Candidate, scores: list[CandidateScore], eligible: set[Candidate]
) -> tuple[Candidate, BranchTest | None]:
    """Where no fold can judge a branch model (every fold's training holds one direction of travel only), the
    chosen candidate with the branch terms :func:`branch_test` finds beyond the drift (and no change where it
    finds none, or where that candidate is not among the ones offered)."""
    with_branch = dataclasses.replace(chosen, order=max(chosen.order, 1), branch=MAX_BRANCH_ORDER)
    if with_branch not in eligible:
        return chosen, None
    tau = float(np.median(next(s for s in scores if s.candidate == chosen).fold_lag_s)) if chosen.lag else 0.0
    accel = [problem.accel_columns(k) for k in range(len(problem.runs))]
    test = branch_test(
        problem.runs,
        problem.groups,
        problem.threshold_degc,
        problem.t_ref_degc,
        problem.t_scale_degc,
        chosen.order,
        tau,
        problem.block_s,
        accel,
    )
    if not test.order:
        return chosen, test
    kept = dataclasses.replace(with_branch, branch=test.order)
    return (kept, test) if kept in eligible else (chosen, test)


__all__ = [
    "AxisScores",
    "TWO_FOLDS",
    "choose_axis",
    "score_axis",
    "select_axes",
    "select_axis",
    "share_fold_lags",
    "unidentified_lags",
]
