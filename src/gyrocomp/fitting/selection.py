"""Model choice by held-out drift: folds, candidates and their scores (the rule: :mod:`gyrocomp.fitting.scores`;
each axis's choice and the axes of one die together: :mod:`gyrocomp.fitting.choice`).

What a user judges a compensation by is the drift left in data the model has not seen: the RMS, about its
mean, of the moving-averaged compensated output. This module scores every candidate model of one axis by
exactly that, on folds of the calibration data, and keeps the simplest candidate whose score is within one
standard error of the best.

Folds (:func:`make_folds`)
    With three runs or more, each run is held out in turn (leave one run out). With one or two runs there
    is only one such fold per held-out run, too few to judge a choice, so the runs are split at their
    confirmed temperature reversals into heating and cooling legs, and each leg is held out in turn (the
    other legs, of the same run too, train). Runs without enough reversals are split into contiguous time
    blocks (temperature blocks, on a ramp). The held-out piece's constant is always refitted (its mean is
    removed): the score is drift, not the turn-on bias.

Candidates (:class:`Candidate`)
    Polynomial order 0..5 (0: the run constant alone, no temperature curve), thermal lag, turning-point
    hysteresis of order 1..3 (only where the runs reverse), and the weighting of the fit: ``time`` (every
    second of data counts equally, as in the score) or ``temperature-balanced`` (every temperature bin of
    every run counts equally, so a slow ramp cannot dominate). The lag of a fold's fit is chosen on that
    fold's training data (a log-spaced grid), so the held-out score judges the whole procedure; with one
    temperature column it is one lag for all axes (:func:`gyrocomp.fitting.choice.share_fold_lags`), as in
    the final fit.

Score and rule
    Per fold, the time-weighted RMS of the moving average (``window_s``) of the held-out residual about its
    mean [deg/s]; a candidate's score is the mean over folds, and the rule that chooses among the scores is
    :mod:`gyrocomp.fitting.scores`'s (Breiman's one-standard-error rule, with do-no-harm). Complexity is the
    number of shape terms: the order, plus 1 for the lag, plus 2 per hysteresis order. On a temperature
    register with coarse steps (:func:`temperature_step_degc`) the lag
    costs nothing: it is what turns the steps back into the smooth temperature of the structure.

Every fold's training solve comes from normal equations per (run, fold) piece, computed once per lag value
and weighting and shared by all candidates and folds.

"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from ..effects import find_turns, thermal_lag
from ..calibration.candidate import Candidate, Weighting
from ..measures.merit import moving_average
from ..measures.ramp_rate import ramp_rates_separate, run_ramp_rates_degc_per_min
from ..runs.prepared import PreparedRun, RunBlocks
from ..spilled_series import parts, streamed_median
from ..units import AxisUnit
from .temperature_bins import bin_width_for
from .design import Terms, ThermalDesign
from .folds import Folds, make_folds, window_for
from .normal_equations import solve_normal
from .scores import CandidateScore
from .branch_evidence import band_offer, branches_identified, branches_present, heats_and_cools_blocks
from ..curves.hysteresis import turn_threshold_degc
from ..curves.polynomial import POLY_FAMILY
from ..curves.play_bank import play_half_widths_degc
from ..curves.turning_table import largest_turn_distance_degc, turning_table_knots_degc
from .grid_search import LAG_MAX_S, LAG_MIN_BLOCKS, lag_search_top_s
from .thermal_problem import SCORE_WINDOW_S

WEIGHTINGS: tuple[Weighting, ...] = ("time", "temperature-balanced")
#: crossover widths of the branch candidates in each fold [degC] (each fold takes the one of least training
#: residual; each width is a block of columns at every lag of the grid, so the folds try three, and the final
#: fit refines the width of the chosen model on the finer grid of gyrocomp.fitting.thermal_problem.BRANCH_WIDTHS_DEGC)
FOLD_BRANCH_WIDTHS_DEGC = (2.0, 6.0, 18.0)
#: smoothing time constants of the temperature-rate candidates in each fold [s] (each fold takes the one of least
#: training residual; the final fit refines it on gyrocomp.fitting.thermal_problem.RATE_SMOOTHINGS_S)
FOLD_RATE_SMOOTHINGS_S = (60.0, 300.0, 1500.0)
#: what a rate term adds to its complexity where the runs ramp at one rate: there its heating-cooling difference
#: is also a memory of the turn's (a branch), and the two part at another rate, in opposite directions; so a
#: one-term branch scoring within one standard error of the best is taken before the rate term (measured on the
#: shape zoo, fitted at 1 degC/min and judged at 3: without it the rate term replaced the branch of a play on 1
#: axis in 9 and of a slow second thermal path on 4 in 9, leaving 1.4 to 3.8 times the branch's drift)
ONE_RATE_RATE_TERM_COST = 1
#: lag values tried per fold (log-spaced from two blocks to LAG_MAX_S or the longest run; SelectionProblem.lag_grid_s)
LAG_GRID_POINTS = 16
#: polynomial order of the residual in which the band where the branches part is looked for (the field's cubic)
BAND_ORDER = 3
#: a temperature register whose steps are at least this coarse is treated as quantized [degC]
COARSE_STEP_DEGC = 0.25


def temperature_step_degc(temperature_degc: np.ndarray) -> float:
    """The step of a quantized temperature register [degC], or 0 when the values are not on a coarse grid.

    The step is the most common non-zero difference between consecutive samples; the series counts as
    quantized when that step is at least ``COARSE_STEP_DEGC`` and almost every value (99 %) lies on its grid.
    The series (which may be a memory-mapped file) is read a part at a time: the steps are
    counted by their value (to 1e-6 degC, as many as there are distinct ones), the median offset from the grid
    taken exactly (:func:`gyrocomp.spilled_series.streamed_median`).
    """
    t = np.asarray(temperature_degc, dtype=float)
    values, counts = np.empty(0), np.empty(0, dtype=np.int64)
    for a, b in parts(t.size, overlap=1):
        steps = np.abs(np.diff(t[a:b]))
        here, many = np.unique(np.round(steps[steps > 1e-9], 6), return_counts=True)
        values, where = np.unique(np.concatenate([values, here]), return_inverse=True)
        counts = np.bincount(where, weights=np.concatenate([counts, many]), minlength=values.size).astype(np.int64)
    if not values.size:
        return 0.0
    step = float(values[np.argmax(counts)])
    if step < COARSE_STEP_DEGC:
        return 0.0

    def offsets():
        for a, b in parts(t.size):
            yield t[a:b] - np.round(t[a:b] / step) * step

    phase = streamed_median(offsets())
    on_grid = sum(int(np.count_nonzero(np.abs(offset - phase) < 0.01 * step)) for offset in offsets())
    return step if on_grid / t.size >= 0.99 else 0.0


@dataclass(frozen=True)
class DriftWeights:
    """The weights of one stretch of blocks for :func:`drift_rms`, with their moving average and sums, which do not
    depend on the residual (every candidate is scored on the same stretches)."""

    weight: np.ndarray
    window: int
    total: float
    smoothed: np.ndarray
    smoothed_total: float

    @classmethod
    def of(cls, weight: np.ndarray, window: int) -> "DriftWeights":
        window = max(1, min(window, weight.size))  # a fold shorter than the window: one mean over all of it
        smoothed = moving_average(weight, window)
        return cls(weight, window, float(np.sum(weight)), smoothed, float(np.sum(smoothed)))


def drift_rms(residual: np.ndarray, weights: DriftWeights) -> tuple[float, float]:
    """(weighted sum of squares, sum of weights) of the moving average of ``residual`` about its weighted mean."""
    e = residual - np.sum(weights.weight * residual) / weights.total
    smooth = moving_average(e, weights.window)
    w = weights.smoothed
    smooth = smooth - np.sum(w * smooth) / weights.smoothed_total
    return float(np.sum(w * smooth**2)), weights.smoothed_total


@dataclass
class SelectionProblem:
    """One axis's calibration data, prepared once for every candidate and fold.

    Parameters
    ----------
    runs : list of RunBlocks
        Block means of each recording [s, degC, deg/s]; ``samples`` gives the time weights.
    groups : tuple of int
        The run of each recording.
    folds : Folds
    t_ref_degc, t_scale_degc : float
        Centre and half-span of the temperature [degC] (conditioning of the polynomial columns).
    threshold_degc : float
        Turning-point threshold [degC].
    block_s : float
        Block length [s].
    window_s : float
        Moving-average window of the score [s].
    max_order : int
    hysteresis_orders : tuple of int
        Hysteresis orders to try (empty: no turning-point candidates).
    accel_cols, square_cols : tuple of int
        Accelerometer columns (and g x g products) fitted in every candidate (g-sensitivity).
    temperature_step_degc : float
        Step of a quantized temperature register [degC], 0 if none.
    band_degc : (lo, hi), optional
        Temperature band where the branches part in the data [degC]: turning-point candidates are also tried
        with their terms limited to it.
    fold_lags_s : dict
        Per (order, weighting), each fold's lag [s] shared with the other axes (:func:`gyrocomp.fitting.choice.share_fold_lags`); a lag
        candidate not in it picks its own per fold.
    band_only : bool
        Turning-point candidates only inside ``band_degc`` (none without a band): see :func:`prepare_axis`.
    branch_orders : tuple of int
        Terms of the heating-cooling difference of the branch candidates to try (empty: none); each fold's
        crossover width is the one of :data:`FOLD_BRANCH_WIDTHS_DEGC` that leaves the least training residual.
    """

    runs: list[RunBlocks]
    groups: tuple[int, ...]
    folds: Folds
    t_ref_degc: float
    t_scale_degc: float
    threshold_degc: float
    block_s: float
    window_s: float
    max_order: int = 5
    hysteresis_orders: tuple[int, ...] = (1, 2, 3)
    accel_cols: tuple[int, ...] = ()
    square_cols: tuple[int, ...] = ()
    temperature_step_degc: float = 0.0
    band_degc: tuple[float, float] | None = None
    fold_lags_s: dict[tuple[int, str], np.ndarray] = field(default_factory=dict)
    unit: AxisUnit = "deg/s"
    band_only: bool = False
    branch_orders: tuple[int, ...] = ()
    #: curves of families besides the polynomial: (name in :data:`gyrocomp.curves.protocol.BASES`, size) pairs
    other_curves: tuple[tuple[str, int], ...] = ()
    #: smoothing time constants of the temperature-rate columns [s] (empty: no rate candidates)
    rate_smoothings_s: tuple[float, ...] = ()
    #: each recording's typical ramp rate [degC/min] (NaN: it does not ramp;
    #: :func:`gyrocomp.measures.ramp_rate.run_ramp_rates_degc_per_min`); empty: not known, taken as one rate
    ramp_rates_degc_per_min: tuple[float, ...] = ()
    #: knots per branch of the turning-point table candidates (empty: none), and the largest distance from a turn
    #: the runs reach [degC] (the tables' last knot)
    turning_table_sizes: tuple[int, ...] = ()
    turn_reach_degc: float = 0.0
    #: plays per bank of the bank-of-plays candidates (empty: none)
    play_bank_sizes: tuple[int, ...] = ()
    _cache: dict = field(default_factory=dict, init=False, repr=False)

    @property
    def max_hysteresis(self) -> int:
        return max(self.hysteresis_orders, default=0)

    def lag_grid_s(self) -> np.ndarray:
        """The lags each fold's fit chooses from [s]: :data:`LAG_GRID_POINTS` log-spaced from two blocks to the
        longest run (at most :data:`gyrocomp.fitting.grid_search.LAG_MAX_S`), those up to
        :func:`gyrocomp.fitting.grid_search.lag_search_top_s` kept."""
        lo = LAG_MIN_BLOCKS * self.block_s
        longest = max(float(r.time_s[-1] - r.time_s[0]) for r in self.runs)
        grid = np.geomspace(lo, max(2.0 * lo, min(LAG_MAX_S, longest)), LAG_GRID_POINTS)
        return grid[grid <= lag_search_top_s(self.runs, lo) * (1 + 1e-9)]

    # -- columns ---------------------------------------------------------------------------------------
    def model_temperature(self, k: int, tau_s: float) -> np.ndarray:
        run = self.runs[k]
        if tau_s > 0:
            return thermal_lag(run.time_s, run.temperature_degc, tau_s, period_s=self.block_s)[0]
        return run.temperature_degc

    @property
    def thermal_design(self) -> ThermalDesign:
        """The columns' builder (distances scaled by the half-span, for well-conditioned normal matrices)."""
        return ThermalDesign(
            self.t_ref_degc,
            self.t_scale_degc,
            self.threshold_degc,
            self.accel_cols,
            self.square_cols,
            distance_scale_degc=self.t_scale_degc,
            period_s=self.block_s,
        )

    def terms(self, lagged: bool = False) -> Terms:
        """Every block any candidate uses: u^1..u^max_order, the other families' blocks (none at a lag:
        ``lagged``, see :meth:`other_blocks`), the hysteresis terms over the whole range and inside the band,
        the branch terms at each crossover width, the accelerometer columns."""
        shapes = ((POLY_FAMILY, self.max_order),) + tuple((name, size) for name, size, _ in self.other_blocks(lagged))
        return Terms(
            shapes=shapes,
            turning_point_order=self.max_hysteresis,
            bands_degc=(None,) if self.band_degc is None else (None, self.band_degc),
            turning_table_knots_degc=tuple(self.table_knots_degc(m) for m in self.turning_table_sizes),
            play_half_widths_degc=tuple(self.play_widths_degc(m) for m in self.play_bank_sizes),
            branch_order=self.max_branch,
            branch_widths_degc=FOLD_BRANCH_WIDTHS_DEGC if self.branch_orders else (),
            rate_smoothings_s=self.rate_smoothings_s,
        )

    def table_knots_degc(self, size: int) -> tuple[float, ...]:
        """The knots [degC] of a turning-point table of ``size`` knots per branch, to the runs' reach."""
        return turning_table_knots_degc(self.turn_reach_degc, size)

    def play_widths_degc(self, size: int) -> tuple[float, ...]:
        """The half-widths [degC] of a bank of ``size`` plays over this axis's temperature span."""
        return play_half_widths_degc(2.0 * self.t_scale_degc, self.threshold_degc, size)

    def columns(self, k: int, temp: np.ndarray, lagged: bool = False) -> np.ndarray:
        """Every column any candidate uses (:meth:`terms`) at model temperature ``temp`` [degC], and last the value
        fitted (the run's block means [the axis's unit]: the normal matrices' last row, without a copy of the
        columns to join it). (A fold's training range is applied where its held-out blocks are scored,
        :meth:`_held_out`.)"""
        run = self.runs[k]
        columns = self.thermal_design.columns(temp, run.accel_g, self.terms(lagged), time_s=run.time_s)
        return np.hstack([columns, run.value[:, None]])

    def accel_columns(self, k: int) -> np.ndarray:
        """The g and g x g sensitivity columns of run ``k`` (n, m), m = 0 without them."""
        run = self.runs[k]
        return self.thermal_design.acceleration_columns(run.accel_g, run.value.size)

    @property
    def max_branch(self) -> int:
        return max(self.branch_orders, default=0)

    def basis(self, name: str):
        """The curve family ``name`` over this axis's temperature range (polynomials continued along their
        tangent past a fold's training range, as the chosen curve is applied)."""
        return self.thermal_design.basis(name)

    def other_blocks(self, lagged: bool = False) -> list[tuple[str, int, int]]:
        """(family, size, first column) of each block of columns of a family other than the polynomial: they
        follow the polynomial's u^1..u^max_order, one block per size (a table's sizes share no columns). None
        at a lag (``lagged``): the other families are offered without one (a table with a lag followed the
        runs' common drift on a simulated fleet, and its columns at every lag of the grid cost a quarter of
        the fit)."""
        out, start = [], self.max_order
        if lagged:
            return out
        for name, size in self.other_curves:
            out.append((name, size, start))
            start += size
        return out

    def column_index(self, c: Candidate, width: int = 0, smoothing: int = 0) -> np.ndarray:
        """The columns of candidate ``c`` (its branch terms at crossover width number ``width``, its rate term at
        smoothing number ``smoothing``), among the columns at a lag when ``c`` has one (no block of another family
        there)."""
        key = ("layout", c.lag)  # asked for every candidate, fold, lag and width: built once per lagged or not
        if key not in self._cache:
            self._cache[key] = self.thermal_design.layout(self.terms(c.lag))
        at = self._cache[key]
        idx: list[int] = []
        if c.order:
            shape = at[
                ("shape", POLY_FAMILY, self.max_order) if c.curve == POLY_FAMILY else ("shape", c.curve, c.order)
            ]
            idx += list(range(shape.start, shape.start + c.order))
        if c.hysteresis_order:
            first, h = at[("turning-point", self.band_degc if c.band else None)].start, self.max_hysteresis
            idx += [first + j for j in range(c.hysteresis_order)] + [first + h + j for j in range(c.hysteresis_order)]
        if c.turning_table:
            table = at[("turning-table", self.table_knots_degc(c.turning_table))]
            idx += list(range(table.start, table.stop))
        if c.plays:
            bank = at[("play-bank", self.play_widths_degc(c.plays))]
            idx += list(range(bank.start, bank.stop))
        if c.branch:
            first = at[("branch", FOLD_BRANCH_WIDTHS_DEGC[width])].start
            idx += [first + j for j in range(c.branch)]
        if c.rate:
            idx.append(at[("rate", self.rate_smoothings_s[smoothing])].start)
        idx += list(range(at[("acceleration",)].start, at[("acceleration",)].stop))
        return np.asarray(idx, dtype=np.int64)

    def weights(self, k: int, weighting: Weighting) -> np.ndarray:
        run = self.runs[k]
        if weighting == "time":
            return run.samples / run.samples.max()
        return run.weight

    def shape_columns(self, k: int, temp: np.ndarray) -> np.ndarray:
        """The polynomial's columns u^1..u^max_order at model temperature ``temp`` [degC], then the accelerometer
        columns: what a ``poly + lag`` candidate uses (:meth:`lag_rss`), without the hysteresis and branch terms
        that :meth:`columns` also makes; the value last, as there."""
        run = self.runs[k]
        shape = Terms(shapes=((POLY_FAMILY, self.max_order),))
        return np.hstack([self.thermal_design.columns(temp, run.accel_g, shape), run.value[:, None]])

    # -- normal equations, per fold --------------------------------------------------------------------
    def _model_temperatures(self, tau_s: float) -> list[np.ndarray]:
        key = ("temp", tau_s)
        if key not in self._cache:
            self._cache[key] = [self.model_temperature(k, tau_s) for k in range(len(self.runs))]
        return self._cache[key]

    def _prepared(self, tau_s: float, shape_only: bool = False):
        """Per run at lag ``tau_s``: model temperature and columns, the value last (:meth:`columns`, or with
        ``shape_only`` :meth:`shape_columns`)."""
        key = ("prep", tau_s, shape_only)
        if key not in self._cache:
            temps = self._model_temperatures(tau_s)
            self._cache[key] = [
                (temp, self.shape_columns(k, temp) if shape_only else self.columns(k, temp, lagged=tau_s > 0))
                for k, temp in enumerate(temps)
            ]
        return self._cache[key]

    def training_matrices(
        self, tau_s: float, weighting: Weighting, shape_only: bool = False
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(F, P+1, P+1) centred normal matrices of [columns, y] over each fold's training data (each run's
        constant profiled out), and the (F,) lowest and highest training model temperature. The columns are
        :meth:`columns`, or with ``shape_only`` :meth:`shape_columns`."""
        key = ("train", tau_s, weighting, shape_only)
        if key in self._cache:
            return self._cache[key]
        n_folds = self.folds.count
        prepared = self._prepared(tau_s, shape_only)
        p = prepared[0][1].shape[1] - 1  # the columns; the value is last
        # per group (run) and fold: raw sums
        group_ids = sorted(set(self.groups))
        gram = np.zeros((len(group_ids), n_folds, p + 1, p + 1))
        first = np.zeros((len(group_ids), n_folds, p + 1))
        total = np.zeros((len(group_ids), n_folds))
        lo = np.full(n_folds, np.inf)
        hi = np.full(n_folds, -np.inf)
        t_lo = np.full((len(self.runs), n_folds), np.inf)
        t_hi = np.full((len(self.runs), n_folds), -np.inf)
        for k, (temp, z) in enumerate(prepared):
            g = group_ids.index(self.groups[k])
            w = self.weights(k, weighting)
            for f, sel in self._run_folds()[k]:
                zs, ws = z[sel], w[sel]
                zw = zs * ws[:, None]
                gram[g, f] += zw.T @ zs
                first[g, f] += zw.sum(axis=0)
                total[g, f] += ws.sum()
                t_lo[k, f], t_hi[k, f] = temp[sel].min(), temp[sel].max()
        matrices = np.zeros((n_folds, p + 1, p + 1))
        g_all, m_all, s_all = gram.sum(axis=1), first.sum(axis=1), total.sum(axis=1)
        for f in range(n_folds):
            for g in range(len(group_ids)):
                s = s_all[g] - total[g, f]
                if s <= 0:
                    continue
                m = m_all[g] - first[g, f]
                matrices[f] += g_all[g] - gram[g, f] - np.outer(m, m) / s
            keep = np.ones(n_folds, dtype=bool)
            keep[f] = False
            lo[f], hi[f] = t_lo[:, keep].min(), t_hi[:, keep].max()
        self._cache[key] = (matrices, lo, hi)
        return self._cache[key]

    @staticmethod
    def solve(matrix: np.ndarray, idx: np.ndarray) -> tuple[np.ndarray, float]:
        """Coefficients of the columns ``idx`` and the training residual sum of squares, from a centred normal
        matrix (minimum-norm where columns are not identified, e.g. a branch absent from the training data)."""
        if idx.size == 0:
            return np.zeros(0), float(matrix[-1, -1])
        a = matrix.take(idx, axis=0).take(idx, axis=1)
        b = matrix[idx, -1]
        scale = np.sqrt(np.maximum(a.diagonal(), 1e-300))
        coef = solve_normal(a / scale[:, None] / scale, b / scale) / scale
        return coef, float(matrix[-1, -1] - b @ coef)

    def _held_out(
        self,
        f: int,
        c: Candidate,
        tau_s: float,
        coef: np.ndarray,
        lo: float,
        hi: float,
        idx: np.ndarray,
        windows_s: tuple[float, ...],
    ) -> tuple[float, ...]:
        """The held-out drift of fold ``f`` at each of ``windows_s`` [s] [the axis's unit]."""
        if not (math.isfinite(lo) and math.isfinite(hi) and np.all(np.isfinite(coef))):
            return (math.nan,) * len(windows_s)  # nothing left to train on without this fold
        sums = np.zeros(len(windows_s))
        wsum = np.zeros(len(windows_s))
        weights_of = [self._fold_weights(w)[f] for w in windows_s]
        for j, (t, columns, value) in enumerate(self._held_out_rows(tau_s, f)):
            x = columns[idx]
            past = (t < lo) | (t > hi)
            if c.order and np.any(past):  # past the training range the curve goes on as applied (tangent, or held)
                x[: c.order, past] = self.basis(c.curve).columns(t[past], c.order, lo, hi).T
            residual = value - (coef @ x if idx.size else 0.0)
            for i, weights in enumerate(weights_of):
                sse, total = drift_rms(residual, weights[j])
                sums[i] += sse
                wsum[i] += total
        return tuple(float(math.sqrt(a / b)) if b > 0 else math.nan for a, b in zip(sums, wsum))

    def _held_out_rows(self, tau_s: float, f: int) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """Per run with blocks in fold ``f`` (in the order of :meth:`fold_members`): the model temperature
        [degC], every column (:meth:`columns`, one row each: a candidate's columns are then whole rows, gathered
        four times faster than columns of a row-major table) and the value [the axis's unit] of those blocks at
        lag ``tau_s`` [s]; the same for every candidate scored on the fold."""
        key = ("held out", tau_s, f)
        if key not in self._cache:
            prepared = self._prepared(tau_s)
            self._cache[key] = [
                (prepared[k][0][sel], np.ascontiguousarray(prepared[k][1][sel, :-1].T), self.runs[k].value[sel])
                for k, sel in self.fold_members()[f]
            ]
        return self._cache[key]

    def fold_members(self) -> list[list[tuple[int, np.ndarray | slice]]]:
        """Per fold, (run, its blocks in the fold) for every run with blocks in it: a slice where they follow one
        another (a leg, a run: then read in place), their indices otherwise."""
        if "members" not in self._cache:
            members = [[] for _ in range(self.folds.count)]
            for k, fold in enumerate(self.folds.of_block):
                for f in np.unique(fold):
                    rows = np.flatnonzero(fold == f)
                    whole = rows[-1] - rows[0] + 1 == rows.size
                    members[int(f)].append((k, slice(int(rows[0]), int(rows[-1]) + 1) if whole else rows))
            self._cache["members"] = members
        return self._cache["members"]

    def _run_folds(self) -> list[list[tuple[int, np.ndarray | slice]]]:
        """Per run, (fold, its blocks in the fold) for every fold it has blocks in (:meth:`fold_members`)."""
        if "run folds" not in self._cache:
            by_run = [[] for _ in self.runs]
            for f, members in enumerate(self.fold_members()):
                for k, sel in members:
                    by_run[k].append((f, sel))
            self._cache["run folds"] = by_run
        return self._cache["run folds"]

    def _fold_weights(self, window_s: float) -> list[list[DriftWeights]]:
        """Per fold, the :class:`DriftWeights` (block durations, a moving average of ``window_s`` [s]) of each of its
        runs' blocks, in the order of :meth:`fold_members`."""
        key = ("fold weights", window_s)
        if key not in self._cache:
            window = max(1, int(round(window_s / self.block_s)))
            self._cache[key] = [
                [DriftWeights.of(self.runs[k].samples[sel].astype(float), window) for k, sel in members]
                for members in self.fold_members()
            ]
        return self._cache[key]

    @property
    def short_window_s(self) -> float:
        """The short window of the score [s]: :data:`gyrocomp.fitting.thermal_problem.SCORE_WINDOW_S` (the timescale of the
        thesis's bias offset), at most the score's window and at least a block."""
        return max(self.block_s, min(SCORE_WINDOW_S, self.window_s))

    def score(self, c: Candidate, short_window: bool = False) -> CandidateScore:
        """Held-out drift of ``c`` on every fold: each fold's lag and branch crossover width are those of the
        least training residual; with ``short_window``, at the short window too (:attr:`short_window_s`)."""
        taus = self.lag_grid_s() if c.lag else np.array([0.0])
        drifts, lags = [], []
        shared = self.fold_lags_s.get((c.order, c.weighting)) if c.lag and c.curve == POLY_FAMILY else None
        both = self.fold_has_both_directions()
        for f in range(self.folds.count):
            # a fold whose training data holds one direction only cannot tell the branches apart: there the
            # candidate is its polynomial (its branch or turning-point terms would be confounded with the curve, and
            # its rate term, of one sign but at the holds, with the run constant)
            fc = (
                c
                if both[f]
                else dataclasses.replace(
                    c, branch=0, hysteresis_order=0, band=False, rate=False, turning_table=0, plays=0
                )
            )
            widths = range(len(FOLD_BRANCH_WIDTHS_DEGC)) if fc.branch else (0,)
            smoothings = range(len(self.rate_smoothings_s)) if fc.rate else (0,)
            best = None
            for tau in taus if shared is None else shared[f : f + 1]:
                matrices, lo, hi = self.training_matrices(float(tau), c.weighting)
                for w, s in ((w, s) for w in widths for s in smoothings):
                    idx = self.column_index(fc, w, s)
                    coef, rss = self.solve(matrices[f], idx)
                    if best is None or rss < best[0]:
                        best = (rss, float(tau), coef, lo[f], hi[f], idx)
            _, tau, coef, lo_f, hi_f, idx = best
            windows = (self.window_s, self.short_window_s) if short_window else (self.window_s,)
            drifts.append(self._held_out(f, c, tau, coef, lo_f, hi_f, idx, windows))
            lags.append(tau)
        return CandidateScore(
            c, tuple(d[0] for d in drifts), tuple(lags), tuple(d[1] for d in drifts) if short_window else ()
        )

    def fold_has_both_directions(self) -> np.ndarray:
        """(F,) whether each fold's training data holds both heating and cooling blocks."""
        if "directions" not in self._cache:
            heat = np.zeros(self.folds.count, dtype=bool)
            cool = np.zeros(self.folds.count, dtype=bool)
            for run, fold in zip(self.runs, self.folds.of_block):
                direction = find_turns(run.temperature_degc, self.threshold_degc).direction
                for f in range(self.folds.count):
                    train = fold != f
                    heat[f] |= bool(np.any(direction[train] > 0))
                    cool[f] |= bool(np.any(direction[train] < 0))
            # (the crossover after a turn alone, inside one leg, was tried as evidence too: chosen on one heating
            # and one cooling leg, it left the next leg 20 % worse than a cubic)
            self._cache["directions"] = heat & cool
        return self._cache["directions"]

    def lag_rss(self, order: int, weighting: Weighting, grid_s: np.ndarray) -> np.ndarray:
        """(folds, lags) training residual sum of squares of ``poly:order + lag`` at each lag of ``grid_s`` [s],
        each fold's row divided by its minimum (so that axes of different noise weigh the same). From the normal
        matrices of :meth:`shape_columns` alone: the hysteresis and branch columns at every lag of the grid cost
        half the model choice, and the candidates are scored at the lags chosen here only."""
        n_accel = len(self.accel_cols) + len(self.square_cols)
        idx = np.r_[np.arange(order), self.max_order + np.arange(n_accel)].astype(np.int64)
        out = np.empty((self.folds.count, grid_s.size))
        for g, tau in enumerate(grid_s):
            matrices = self.training_matrices(float(tau), weighting, shape_only=True)[0]
            out[:, g] = [self.solve(matrices[f], idx)[1] for f in range(self.folds.count)]
        return out / np.maximum(out.min(axis=1, keepdims=True), 1e-300)

    def candidates(
        self, orders: tuple[int, ...], memories: tuple[str, ...], weightings: tuple[Weighting, ...] = WEIGHTINGS
    ) -> list[Candidate]:
        out = []
        sized_memories = self._sized_memories()
        for w in weightings:
            if "none" in memories:  # the other families: no lag, no hysteresis
                out += [Candidate(size, False, 0, w, curve=name) for name, size in self.other_curves]
            for p in orders:
                for mem in memories:
                    lag = "lag" in mem
                    if "rate" in mem:
                        c = Candidate(p, lag, 0, w, rate=True)
                        if p > 0 and self.rate_smoothings_s and c not in out:
                            out.append(c)
                        continue
                    sized = next((k for k in sized_memories if k in mem), None)
                    if sized is not None:  # a memory of one size per candidate: the sizes offered, with a curve
                        field_name, sizes = sized_memories[sized]
                        for m in sizes if p > 0 else ():
                            c = Candidate(p, lag, 0, w, **{field_name: m})
                            if c not in out:
                                out.append(c)
                        continue
                    if mem in ("none", "lag"):
                        hs = (0,)
                    else:
                        hs = self.hysteresis_orders
                    for h in hs:
                        if (lag or h) and p == 0:
                            continue
                        bands = (False, True) if h and self.band_degc is not None else (False,)
                        if h and self.band_only:
                            bands = (True,) if self.band_degc is not None else ()
                        for band in bands:
                            c = Candidate(p, lag, h, w, band)
                            if c not in out:
                                out.append(c)
        return out

    def _sized_memories(self) -> dict[str, tuple[str, tuple[int, ...]]]:
        """The memories with a size of their own: name to (the candidate's field, the sizes offered)."""
        return {
            "play-bank": ("plays", self.play_bank_sizes),
            "turning-table": ("turning_table", self.turning_table_sizes),
            "branch": ("branch", self.branch_orders),
        }

    @property
    def rates_separate(self) -> bool:
        """Whether the runs' ramp rates can tell a memory that grows with the rate from one that does not
        (:func:`gyrocomp.measures.ramp_rate.ramp_rates_separate`)."""
        return ramp_rates_separate(self.ramp_rates_degc_per_min)

    def complexity(self, c: Candidate) -> int:
        """Complexity for the rule: on a coarsely quantized register the lag is free (it de-quantizes); where the
        runs ramp at one rate, a rate term counts one more (:data:`ONE_RATE_RATE_TERM_COST`)."""
        lag_free = 1 if c.lag and self.temperature_step_degc > 0 else 0
        one_rate = ONE_RATE_RATE_TERM_COST if c.rate and not self.rates_separate else 0
        return c.complexity - lag_free + one_rate


def prepare_axis(
    recordings: list,
    axis: str,
    *,
    pieces: list | None = None,
    groups: tuple[int, ...] | None = None,
    block_s: float = 2.0,
    bin_width_degc: float | None = None,
    fold_kind: str = "auto",
    max_order: int = 5,
    hysteresis_orders: tuple[int, ...] = (1, 2, 3),
    accel_cols: tuple[int, ...] = (),
    square_cols: tuple[int, ...] = (),
    both_directions: bool = True,
    branch_orders: tuple[int, ...] = (),
    other_curves: tuple[tuple[str, int], ...] = (),
    rate_smoothings_s: tuple[float, ...] = (),
    turning_table_sizes: tuple[int, ...] = (),
    play_bank_sizes: tuple[int, ...] = (),
) -> SelectionProblem:
    """Block means, folds and window of one axis: the :class:`SelectionProblem` every candidate is scored on.

    Parameters
    ----------
    recordings : list of Recording
    axis : str
    pieces : list of (list of slice or None), optional
        Per recording, the stretches to use (static segments of a multi-position run); default every stretch.
    groups : tuple of int, optional
        The run of each recording (default: each its own run).
    block_s : float
        Block length [s] (at least one sample).
    bin_width_degc : float, optional
        Temperature bin of the temperature-balanced weights [degC].
    fold_kind : {"auto", "runs", "legs", "blocks"}
    max_order : int
    hysteresis_orders : tuple of int
        Turning-point orders to try.
    accel_cols, square_cols : tuple of int
        g-sensitivity columns fitted with every candidate.
    both_directions : bool
        Offer turning-point candidates only where the branches after reversals can be told apart from the
        polynomial (:func:`branches_identified`; when hysteresis is being chosen rather than asked for), else
        wherever a branch exists.
    branch_orders : tuple of int
        Terms of the heating-cooling difference of the branch candidates; offered only where the runs both heat
        and cool.
    other_curves : tuple of (str, int)
        The curves of other families than the polynomial offered, (name in
        :data:`gyrocomp.curves.protocol.BASES`, size) each (the polynomial's orders come from ``max_order``).
    rate_smoothings_s : tuple of float
        Smoothing time constants of the temperature-rate columns [s] (empty: no rate candidates).
    turning_table_sizes : tuple of int
        Knots per branch of the turning-point table candidates, offered where turning-point candidates are.
    play_bank_sizes : tuple of int
        Plays of the bank-of-plays candidates, offered where the runs both heat and cool.
    """
    temps = [rec.temperature_for(axis) for rec in recordings]
    lo = min(float(t.min()) for t in temps)
    hi = max(float(t.max()) for t in temps)
    width = bin_width_for(temps, bin_width_degc)
    block_s = max(block_s, 1.0 / recordings[0].rate_hz)
    pieces = pieces or [None] * len(recordings)
    prepared = [PreparedRun.of(rec) for rec in recordings]
    runs = [p.block_means(axis, block_s, width, piece) for p, piece in zip(prepared, pieces)]
    thresholds = [p.of_temperature(axis, "turn threshold", turn_threshold_degc) for p in prepared]
    groups = tuple(range(len(recordings))) if groups is None else tuple(int(g) for g in groups)
    folds = make_folds(runs, groups, thresholds, fold_kind)
    step = max(p.of_temperature(axis, "step", temperature_step_degc) for p in prepared)
    reverses = branches_identified(runs, thresholds) if both_directions else branches_present(runs, thresholds)
    heats_and_cools = heats_and_cools_blocks(runs, thresholds)
    tables = tuple(turning_table_sizes) if reverses else ()
    t_ref, t_scale = (lo + hi) / 2, (hi - lo) / 2 if hi > lo else 1.0
    band, band_only = (
        band_offer(
            runs, groups, thresholds, folds, t_ref, t_scale, min(BAND_ORDER, max_order), block_s, both_directions
        )
        if reverses and hysteresis_orders
        else (None, False)
    )
    return SelectionProblem(
        runs,
        groups,
        folds,
        t_ref,
        t_scale,
        max(thresholds),
        block_s,
        window_for(folds, runs, block_s),
        max_order,
        hysteresis_orders if reverses else (),
        accel_cols,
        square_cols,
        step,
        band,
        unit=recordings[0].unit_of(axis),
        band_only=band_only,
        branch_orders=branch_orders if heats_and_cools else (),
        other_curves=tuple(other_curves),
        rate_smoothings_s=tuple(rate_smoothings_s),
        ramp_rates_degc_per_min=run_ramp_rates_degc_per_min(recordings),
        turning_table_sizes=tables,
        # the turns' reach only where a table is offered: every other fit goes without it
        turn_reach_degc=largest_turn_distance_degc([r.temperature_degc for r in runs], max(thresholds))
        if tables
        else 0.0,
        play_bank_sizes=tuple(play_bank_sizes) if heats_and_cools else (),
    )


__all__ = [
    "FOLD_BRANCH_WIDTHS_DEGC",
    "FOLD_RATE_SMOOTHINGS_S",
    "ONE_RATE_RATE_TERM_COST",
    "Candidate",
    "SelectionProblem",
    "Weighting",
    "prepare_axis",
    "temperature_step_degc",
]
