"""Hysteresis and thermal lag on top of the temperature polynomial, and the data's choice between them.

Per gyro axis and run r, the bias is modelled as

    b_r(t) = c_r + p(T_s(t)) + H(T_s, history)

- T_s is the reported temperature T, or, with thermal lag, T through a first-order lag of time
  constant tau (the MEMS structure is not at the reported temperature while it changes), tau fitted;
- p is the polynomial of :mod:`gyrocomp.curves.polynomial` (no constant; the run constants c_r
  take that);
- H is the thesis's hysteresis (section 2.6): after a confirmed reversal of T_s, sum_j h_j d^j with
  d = |T_s - T_turn|, one set of h for cooling branches and one for heating branches, optionally only
  inside a temperature band.

The fit works on block means of each run (``block_s`` seconds), in time order, weighted so that
every temperature bin of every run counts equally (as the polynomial's binning does). For a fixed
tau everything is linear; tau is found by a log-spaced search refined by a bounded scalar
minimization (variable projection, :mod:`gyrocomp.fitting.grid_search`). Where this model chooses the memory
itself (a fixed order), the candidates of :data:`CANDIDATES` (none, lag, turning-point, branches, a
temperature-rate term, each with and without the lag) are compared by leave-one-run-out error (the held-out
run's constant refitted), or by BIC with one run; the hysteresis order (1-3) is chosen the same way. The
default's choice is made on held-out folds (:mod:`gyrocomp.fitting.selection`) and fitted here.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..curves.polynomial import POLY_FAMILY
from ..curves.rate import TemperatureRateTerm
from ..effects import find_turns, thermal_lag
from ..errors import DataQualityWarning, InputError, ModelError, user_stacklevel
from ..calibration.fit_report import MEMORIES, memory_name
from ..recording import Recording
from .design import Terms, ThermalDesign
from .grid_search import LAG_MIN_BLOCKS, best_lag_s, lag_search_top_s, plausible_middle
from .gsensitivity import ACCELERATION_CHOICES, excited_columns
from ..runs.prepared import PreparedRun, RunBlocks, fit_axes
from ..runs.prepared import one_temperature_column
from .temperature_bins import bin_width_for
from .learned_attributes import LearnedAttributes
from ..curves.hysteresis import BranchCurve, HysteresisCurve, parting_band_degc, turn_threshold_degc
from ..curves.play_bank import PLAY_BANK_SIZES, PlayBankCurve, play_half_widths_degc
from ..curves.turning_table import (
    TURNING_TABLE_SIZES,
    TurningTableCurve,
    largest_turn_distance_degc,
    turning_table_knots_degc,
)
from .polynomial_model import simplest_within

#: what ``hysteresis`` may ask for: a memory, or ``auto`` (the data's choice among CANDIDATES)
HYSTERESIS_CHOICES = ("auto", *MEMORIES)
#: the memories the default compares, simplest first: every memory but the turning-point table and the bank of
#: plays, which are fitted where asked for (docs/how-the-fit-works.md says why); where the runs ramp at one rate a rate term counts as
#: more complex in the model choice (gyrocomp.fitting.selection.ONE_RATE_RATE_TERM_COST)
CANDIDATES = tuple(c for c in HYSTERESIS_CHOICES[1:] if not c.startswith(("turning-table", "play-bank")))
#: smoothing time constants the final fit tries for a temperature-rate term [s] (the middle of those the data
#: cannot tell from the best: _Problem.best_smoothing); the model choice's folds try FOLD_RATE_SMOOTHINGS_S
RATE_SMOOTHINGS_S = tuple(float(s) for s in np.geomspace(30.0, 3000.0, 11))
#: terms of the difference between the heating and the cooling curve (a constant, then a slope)
MAX_BRANCH_ORDER = 2
#: crossover widths the final fit tries for a branch model [degC] (refined: see _Problem.best_width); the
#: model choice's folds try the coarser gyrocomp.fitting.selection.FOLD_BRANCH_WIDTHS_DEGC
BRANCH_WIDTHS_DEGC = tuple(float(w) for w in np.geomspace(1.0, 40.0, 9))
MAX_HYSTERESIS_ORDER = 3
DEFAULT_BLOCK_S = 2.0
#: with this many runs or fewer, a band's edges and the lag are refined together (_Problem.refine_band_with_lag):
#: the runs' few turns are all that tell the lag from the band's edge. With more, the lag is held by runs of other
#: ramps and the band refined at it (jointly on three runs the ADXRS450 preset's lag came out 72-78 s for a truth
#: of 60, against 48-60 s; the next run's drift 2.03x perfect against 1.97x over ten seeds)
JOINT_BAND_MAX_RUNS = 2
#: held-out residuals are moving-averaged over this long before their RMS is taken [s], so that the
#: score measures drift (what compensation is for) rather than white noise, which no model removes
SCORE_WINDOW_S = 60.0


@dataclass(frozen=True)
class _Spec:
    """One candidate: polynomial order, thermal lag on/off, hysteresis order (0 = none), branch terms (0 = none)
    and the branch crossover width [degC] (0: to be found)."""

    order: int
    lag: bool
    hysteresis_order: int
    branch: int = 0
    width_degc: float = 0.0
    #: the curve family of the shape (:data:`gyrocomp.curves.protocol.BASES`), ``order`` its size
    curve: str = POLY_FAMILY
    #: a temperature-rate term, and its smoothing time constant [s] (0: to be found)
    rate: bool = False
    smoothing_s: float = 0.0
    #: knots per branch of a turning-point table (0: none)
    table: int = 0
    #: plays of a bank of plays (0: none)
    plays: int = 0

    @property
    def name(self) -> str:
        return memory_name(self.lag, self.hysteresis_order, self.branch, self.rate, self.table, self.plays)


@dataclass
class _Problem:
    runs: list[RunBlocks]
    t_ref: float
    t_scale: float
    threshold: float
    band: tuple[float, float] | None
    block_s: float
    accel_cols: tuple[int, ...] = ()
    square_cols: tuple[int, ...] = ()
    #: a polynomial continues along its tangent past its range (as the model choice scored it), else is held
    extended: bool = False
    _lagged: dict = dataclasses.field(default_factory=dict, repr=False)
    _solved: dict = dataclasses.field(default_factory=dict, repr=False)

    def model_temperature(self, run: RunBlocks, spec: _Spec, tau: float) -> np.ndarray:
        """The temperature the model reads [degC]: reported, or through the lag ``tau`` [s] (kept per run and tau:
        the searches over the lag, the band and the branch width ask for the same ones again)."""
        if not (spec.lag and tau > 0):
            return run.temperature_degc
        key = (id(run), float(tau))
        if key not in self._lagged:
            self._lagged[key] = thermal_lag(run.time_s, run.temperature_degc, tau, period_s=self.block_s)[0]
        return self._lagged[key]

    @property
    def thermal_design(self) -> ThermalDesign:
        """The columns' builder (the curves' own coefficients: distances in degC)."""
        return ThermalDesign(
            self.t_ref,
            self.t_scale,
            self.threshold,
            self.accel_cols,
            self.square_cols,
            extended=self.extended,
            period_s=self.block_s,
        )

    def terms(self, spec: _Spec) -> Terms:
        """The blocks of ``spec``: its shape, its hysteresis (inside the band, if any), its branch terms at its
        crossover width, the g-sensitivity."""
        return Terms(
            shapes=((spec.curve, spec.order),),
            turning_point_order=spec.hysteresis_order,
            bands_degc=(self.band,),
            turning_table_knots_degc=(self.table_knots_degc(spec.table),) if spec.table else (),
            play_half_widths_degc=(self.play_widths_degc(spec.plays),) if spec.plays else (),
            branch_order=spec.branch,
            branch_widths_degc=(spec.width_degc,),
            rate_smoothings_s=(spec.smoothing_s,) if spec.rate else (),
        )

    @functools.cached_property
    def turn_reach_degc(self) -> float:
        """The largest distance from a turn the runs reach [degC] (a turning-point table's last knot)."""
        return largest_turn_distance_degc([r.temperature_degc for r in self.runs], self.threshold)

    def table_knots_degc(self, size: int) -> tuple[float, ...]:
        """The knots [degC] of a turning-point table of ``size`` knots per branch, to the runs' reach."""
        return turning_table_knots_degc(self.turn_reach_degc, size)

    def play_widths_degc(self, size: int) -> tuple[float, ...]:
        """The half-widths [degC] of a bank of ``size`` plays over the calibration span."""
        return play_half_widths_degc(2.0 * self.t_scale, self.threshold, size)

    def features(self, run: RunBlocks, temp: np.ndarray, spec: _Spec, t_lo: float, t_hi: float) -> np.ndarray:
        """Columns of the shape and the hysteresis at model temperature ``temp`` [degC] (the curves applied as fitted
        on [t_lo, t_hi]), then of the g and g x g sensitivity (the excited accelerometer axes only)."""
        return self.thermal_design.columns(temp, run.accel_g, self.terms(spec), t_lo, t_hi, time_s=run.time_s)

    def branch_reach(self, spec: _Spec, tau: float) -> tuple[float, float]:
        """The largest |T - T_turn| on the cooling and on the heating branches after a reversal (inside the
        band, if any) over every run [degC]: how far each branch's polynomial in d was fitted."""
        reach = [0.0, 0.0]
        for run in self.runs:
            temp = self.model_temperature(run, spec, tau)
            turns = find_turns(temp, self.threshold)
            active = ~np.isnan(turns.turn_degc)
            if self.band is not None:
                active &= (temp >= self.band[0]) & (temp <= self.band[1])
            d = np.abs(temp - np.where(active, turns.turn_degc, temp))
            for i, sign in enumerate((-1, 1)):
                on = active & (turns.direction == sign)
                if np.any(on):
                    reach[i] = max(reach[i], float(d[on].max()))
        return reach[0], reach[1]

    def design(self, spec: _Spec, tau: float, which: list[int]):
        """The weighted least-squares problem on the runs ``which``: design matrix (one constant column per
        run, then the features), values, weights, and the model-temperature range of those runs."""
        temps = [self.model_temperature(self.runs[r], spec, tau) for r in which]
        t_lo = min(float(t.min()) for t in temps)
        t_hi = max(float(t.max()) for t in temps)
        feats, onehots = [], []
        for k, temp in enumerate(temps):
            oh = np.zeros((temp.size, len(which)))
            oh[:, k] = 1.0
            feats.append(self.features(self.runs[which[k]], temp, spec, t_lo, t_hi))
            onehots.append(oh)
        x = np.hstack([np.vstack(onehots), np.vstack(feats)])
        y = np.concatenate([self.runs[r].value for r in which])
        w = np.concatenate([self.runs[r].weight for r in which])
        return x, y, w, (t_lo, t_hi)

    def solve(self, spec: _Spec, tau: float, which: list[int]):
        """Weighted least squares on the runs ``which``: (coefficients, run constants, weighted RSS, range); kept
        per spec, lag, runs and band (the searches over the lag, the width and the band ask for the same again)."""
        key = (spec, float(tau), tuple(which), self.band)
        if key not in self._solved:
            x, y, w, t_range = self.design(spec, tau, which)
            sw = np.sqrt(w)
            coef, *_ = np.linalg.lstsq(x * sw[:, None], y * sw, rcond=None)
            coef.setflags(write=False)
            rss = float(np.sum(w * (y - x @ coef) ** 2))
            self._solved[key] = coef[len(which) :], coef[: len(which)], rss, t_range
        return self._solved[key]

    def best_width(self, spec: _Spec, tau: float, which: list[int]) -> _Spec:
        """``spec`` with the branch crossover width [degC] of :data:`BRANCH_WIDTHS_DEGC` at lag ``tau`` [s]
        (``spec`` itself without branches or with a width set): the middle of the widths the data cannot tell
        from the best (:func:`plausible_middle`). Only a turn where the curves stand apart shows the crossover;
        one where they nearly meet (the only turn of a single cycle, often) leaves every width alike, and the
        least residual there is chance (measured: 1.6 degC picked against a true 5, the next turn's crossover
        then left 8x the drift of 6.3 degC)."""
        if not spec.branch or spec.width_degc > 0:
            return spec
        specs = [dataclasses.replace(spec, width_degc=w) for w in BRANCH_WIDTHS_DEGC]
        rss = np.array([self.solve(s, tau, which)[2] for s in specs])
        duration_s = sum(float(self.runs[r].time_s[-1] - self.runs[r].time_s[0]) for r in which)
        return specs[plausible_middle(rss, duration_s / SCORE_WINDOW_S)]

    def best_smoothing(self, spec: _Spec, tau: float, which: list[int]) -> _Spec:
        """``spec`` with the rate term's smoothing [s] of :data:`RATE_SMOOTHINGS_S` at lag ``tau`` [s] (``spec``
        itself without a rate term or with its smoothing set): the middle of those the data cannot tell from the
        best (:func:`plausible_middle`), as for the branch width; none longer than half the longest run."""
        if not spec.rate or spec.smoothing_s > 0:
            return spec
        top = max(float(self.runs[r].time_s[-1] - self.runs[r].time_s[0]) for r in which) / 2.0
        grid = [s for s in RATE_SMOOTHINGS_S if s <= max(top, RATE_SMOOTHINGS_S[0])]
        specs = [dataclasses.replace(spec, smoothing_s=s) for s in grid]
        rss = np.array([self.solve(s, tau, which)[2] for s in specs])
        duration_s = sum(float(self.runs[r].time_s[-1] - self.runs[r].time_s[0]) for r in which)
        return specs[plausible_middle(rss, duration_s / SCORE_WINDOW_S)]

    def best_shape(self, spec: _Spec, tau: float, which: list[int]) -> _Spec:
        """``spec`` with its branch crossover width and its rate term's smoothing found at lag ``tau`` [s]."""
        return self.best_smoothing(self.best_width(spec, tau, which), tau, which)

    def fit(self, spec: _Spec, which: list[int], tau_s: float | None = None):
        """Best tau for the spec (0 without lag; ``tau_s`` when given) and the solution there; a branch model's
        crossover width is found at each tau tried. Returns (tau, solution, spec with its width)."""
        if not spec.lag:
            spec = self.best_shape(spec, 0.0, which)
            return 0.0, self.solve(spec, 0.0, which), spec
        if tau_s is None:
            lo_s = LAG_MIN_BLOCKS * self.block_s
            tau_s = best_lag_s(
                lambda tau: self.solve(self.best_shape(spec, tau, which), tau, which)[2],
                lo_s,
                lag_search_top_s(self.runs, lo_s),
            )
        spec = self.best_shape(spec, tau_s, which)
        return tau_s, self.solve(spec, tau_s, which), spec

    def refine_band(self, spec: _Spec, tau_s: float, step_degc: float) -> None:
        """Move each edge of the band [degC] to where the all-run weighted residual is least, on a grid of
        ``step_degc`` / 4 within one ``step_degc`` of where it was found (the band is found on temperature bins;
        a bump that ends sharply leaves a step of its height at an edge placed a bin off)."""
        if self.band is None or not spec.hysteresis_order:
            return
        which = list(range(len(self.runs)))
        lo0, hi0 = self.band
        offsets = np.linspace(-step_degc, step_degc, 9)
        best = (self.solve(spec, tau_s, which)[2], self.band)
        for lo in lo0 + offsets:
            for hi in hi0 + offsets:
                if hi - lo < step_degc:
                    continue
                self.band = (float(lo), float(hi))
                rss = self.solve(spec, tau_s, which)[2]
                if rss < best[0]:
                    best = (rss, self.band)
        self.band = best[1]

    def refine_band_with_lag(self, spec: _Spec, step_degc: float) -> None:
        """:meth:`refine_band` at each lag of a grid about the best lag with the band as found (a quarter to four
        times it, 13 log-spaced points, within the search's bounds), the band kept from the lag whose refined band
        leaves the least all-run residual. An edge a little off is a jump of the hysteresis at the wrong
        temperature, which a longer or shorter lag moves back in time: refined at one lag, band and lag settle
        where they make up for each other (measured on the ADXRS450-like part with a 30 s lag: band edge 80.7
        instead of 80 degC, lag 57 s; refined over the lags, 80.0 degC and 28 s)."""
        which = list(range(len(self.runs)))
        lo_s = LAG_MIN_BLOCKS * self.block_s
        top_s = lag_search_top_s(self.runs, lo_s)
        found = self.band
        tau0 = self.fit(spec, which)[0]
        best = None
        for tau in np.unique(np.clip(tau0 * np.geomspace(0.25, 4.0, 13), lo_s, top_s)):
            self.band = found
            self.refine_band(spec, float(tau), step_degc)
            rss = self.solve(self.best_width(spec, float(tau), which), float(tau), which)[2]
            if best is None or rss < best[0]:
                best = (rss, self.band)
        self.band = best[1]

    def lag_evidence(self, spec: _Spec, tau_s: float, rss: float) -> float:
        """How far the all-run fit of ``spec`` at lag ``tau_s`` [s] (weighted residual sum of squares ``rss``)
        stands from the same fit at the bottom of the lag search (two blocks), as a chi-square of one parameter:
        the residual's independent stretches (its length over :data:`SCORE_WINDOW_S`, as the block residuals are
        correlated over that long) times the relative increase of the rss there."""
        which = list(range(len(self.runs)))
        floor = self.solve(spec, LAG_MIN_BLOCKS * self.block_s, which)[2]
        duration_s = sum(float(r.time_s[-1] - r.time_s[0]) for r in self.runs)
        return duration_s / SCORE_WINDOW_S * (floor - rss) / max(rss, 1e-300)

    def lag_profile(self, spec: _Spec) -> Callable[[float], float]:
        """The all-run residual sum of squares as a function of tau [s], divided by its minimum (1 at the
        axis's own best tau), so that axes with different noise weigh the same in a shared lag."""
        which = list(range(len(self.runs)))
        _, (_, _, own, _), spec = self.fit(spec, which)  # a branch model's width: the one at its own best lag
        return lambda tau: self.solve(spec, tau, which)[2] / max(own, 1e-300)

    def held_out_error(self, spec: _Spec) -> float:
        """RMS [deg/s] of each run predicted by a fit on the others, its constant refitted."""
        sse = wsum = 0.0
        n = len(self.runs)
        for held in range(n):
            train = [r for r in range(n) if r != held]
            tau, (coef, _, _, (t_lo, t_hi)), fitted = self.fit(spec, train)
            run = self.runs[held]
            x = self.features(run, self.model_temperature(run, spec, tau), fitted, t_lo, t_hi)
            e = run.value - x @ coef
            e -= np.sum(run.weight * e) / np.sum(run.weight)
            w = max(1, min(e.size, int(round(SCORE_WINDOW_S / self.block_s))))
            kernel = np.ones(w) / w
            smooth_e = np.convolve(e, kernel, mode="valid")
            smooth_w = np.convolve(run.weight, kernel, mode="valid")
            sse += float(np.sum(smooth_w * smooth_e**2))
            wsum += float(np.sum(smooth_w))
        return math.sqrt(sse / wsum)

    def observed_band(self, order: int) -> tuple[float, float] | None:
        """The temperature band where the branches after a reversal part from the others, from the residual
        of the polynomial alone; None when no band stands out or it spans most of the range.

        See :func:`gyrocomp.curves.hysteresis.parting_band_degc`.
        """
        spec = _Spec(order, False, 0)
        which = list(range(len(self.runs)))
        coef, consts, _, (t_lo, t_hi) = self.solve(spec, 0.0, which)
        temps, resid, after, rising = [], [], [], []
        for k, run in enumerate(self.runs):
            t = run.temperature_degc
            e = run.value - self.features(run, t, spec, t_lo, t_hi) @ coef - consts[k]
            turns = find_turns(t, self.threshold)
            temps.append(t)
            resid.append(e)
            after.append(~np.isnan(turns.turn_degc))
            rising.append(turns.direction)
        return parting_band_degc(*map(np.concatenate, (temps, resid, after, rising)))

    def covariance(self, spec: _Spec, tau: float) -> tuple[np.ndarray, np.ndarray]:
        """Coefficients (run constants first) and their cluster-robust covariance: the sandwich estimator
        with the static segments (or stretches) of each run as clusters, since the noise within a
        segment is correlated (flicker) while different positions are close to independent."""
        n = len(self.runs)
        x, y, w, _ = self.design(spec, tau, list(range(n)))
        clusters = np.concatenate(
            [
                run.cluster * n + k if run.cluster is not None else np.full(run.value.size, k)
                for k, run in enumerate(self.runs)
            ]
        )
        xtw = x.T * w
        bread = np.linalg.pinv(xtw @ x)
        coef = bread @ (xtw @ y)
        score = x * (w * (y - x @ coef))[:, None]
        _, inverse = np.unique(clusters, return_inverse=True)
        per_cluster = np.zeros((inverse.max() + 1, x.shape[1]))
        np.add.at(per_cluster, inverse, score)
        g = per_cluster.shape[0]
        if g <= x.shape[1]:  # fewer clusters than coefficients: the spread of the clusters says nothing
            return coef, np.full((x.shape[1], x.shape[1]), np.nan)
        meat = per_cluster.T @ per_cluster * (g / (g - 1))
        return coef, bread @ meat @ bread

    def bic(self, spec: _Spec) -> float:
        _, (coef, consts, rss, _), _ = self.fit(spec, list(range(len(self.runs))))
        n = sum(r.value.size for r in self.runs)
        w = sum(float(np.sum(r.weight)) for r in self.runs)
        k = coef.size + consts.size + (1 if spec.lag else 0)
        return n * math.log(max(rss / w, 1e-300)) + k * math.log(n)


@dataclass(frozen=True)
class _AxisChoice:
    """What one axis's choice settled: its problem (band set), the candidate and every candidate's score."""

    problem: _Problem
    spec: _Spec
    name: str
    scores: dict[str, float]


def _simplest(tried: dict[int, float], n_runs: int) -> int:
    """The smallest key whose score is within the parsimony tolerance of the best (the best with BIC)."""
    return simplest_within(tried, sorted(tried), by_bic=n_runs < 2)


@dataclass
class ThermalHysteresisModel(LearnedAttributes):
    """Polynomial temperature model with thermal lag and/or turning-point hysteresis, chosen by the data.

    Parameters
    ----------
    order : int or dict
        Polynomial order of the temperature shape, or one per axis (from :class:`PolynomialTemperatureModel`'s
        choice, or :mod:`gyrocomp.fitting.selection`'s).
    hysteresis : {"auto", "none", "turning-point", "lag", "turning-point+lag"} or dict
        The model, or ``"auto"``: every candidate compared by leave-one-run-out error; or a fixed model per axis.
    hysteresis_order : int or "auto" or dict
        Order of the turning-point polynomial (1..3), or chosen by the same validation; or one per axis
        (0 for an axis without turning-point hysteresis).
    band_degc : (lo, hi), optional
        Limit the hysteresis to this temperature band [degC] (the ADXRS450 shows it only from 55 to 80).
        Without it, the band where the branches visibly part (:meth:`_Problem.observed_band`) is tried
        against no band, and the validation keeps the better.
    block_s : float
        Length of the block means the fit works on [s].
    bin_width_degc : float, optional
        Temperature bin of the weights [degC]; default span / 100.
    reselect_order : bool
        Choose the polynomial order again (1..max_order) inside the winning candidate.
    max_order : int
    acceleration : {"none", "matrix", "matrix2"}
        Fit the g-sensitivity row G (thesis 2.7.1) jointly with the temperature model and the run
        constants (``matrix2`` adds the g x g terms), on the static segments of the runs only.
    weighting : {"time", "temperature-balanced"} or dict
        Weights of the block means: every second equal, or every temperature bin of every run equal.
    shared_lag : bool
        Axes that read one temperature column and all have lag get one time constant, fitted on all of them
        together (the lag is the die's, behind one sensor); False fits one per axis.
    branch_order : int or dict
        Terms of the difference between the heating and the cooling curve of a branch model (1: a constant,
        2: and a slope), or one per axis.
    turning_table_size : int or "auto" or dict
        Knots per branch of a turning-point table (``turning-table``, ``turning-table+lag``;
        :class:`~gyrocomp.curves.turning_table.TurningTableCurve`), or chosen among
        :data:`~gyrocomp.curves.turning_table.TURNING_TABLE_SIZES` by the same validation; or one per axis.
    play_bank_size : int or "auto" or dict
        Plays of a bank of plays (``play-bank``, ``play-bank+lag``; :class:`~gyrocomp.curves.play_bank.PlayBankCurve`),
        or chosen among :data:`~gyrocomp.curves.play_bank.PLAY_BANK_SIZES`; or one per axis.
    curve : str or dict
        The family of the temperature shape, a name of :data:`gyrocomp.curves.protocol.BASES` (``poly``,
        ``table``), ``order`` its size; or one per axis.
    extended : bool
        A polynomial continues along its tangent past its range (how the model choice scored it), else is held.
    refine_band : bool
        ``band_degc`` was found on temperature bins (:func:`~gyrocomp.curves.hysteresis.parting_band_degc`): move
        its edges, within one bin, to where the residual is least, then fit the lag again.

    Attributes (after ``fit``)
    --------------------------
    curves_ : dict[str, TemperatureCurve]
        A polynomial (:class:`~gyrocomp.curves.polynomial.PolynomialCurve`), or the curve of the family
        ``curve`` names (:data:`gyrocomp.curves.protocol.BASES`).
    lag_time_constants_s_ : dict[str, float]
        Fitted thermal time constant per axis [s], 0 without lag.
    lag_evidence_ : dict[str, float]
        Per axis with a lag, how far its all-run fit stands from the same at the bottom of the lag search (two
        blocks), as a chi-square of one parameter (:meth:`_Problem.lag_evidence`); at most
        :data:`gyrocomp.fitting.grid_search.LAG_EVIDENCE_CHI2`, this axis's data do not see the lag. NaN without lag.
    hysteresis_ : dict[str, HysteresisCurve, TurningTableCurve, BranchCurve or None]
    turn_on_biases_ : dict[str, np.ndarray]
    memories_ : dict[str, (str, int)]
        The candidate kept per axis: its memory (``none``, ``lag``, ``turning-point``, ``turning-point+lag``) and
        turning-point order (in words: :func:`gyrocomp.calibration.fit_report.memory_label`).
    scores_ : dict[str, dict[str, float]]
        Per axis, the validation score of every candidate tried (RMS [deg/s], or BIC with one run).
    selection_ : str
        ``"leave-one-run-out"``, ``"bic"`` or ``"fixed"``.
    g_sensitivity_dps_per_g_, g_sensitivity_se_dps_per_g_ : dict[str, np.ndarray (3,)]
        Fitted G row and its cluster-robust standard error [deg/s/g] (0 and NaN for axes not excited).
    g_squared_dps_per_g2_, g_squared_se_dps_per_g2_ : dict[str, np.ndarray (6,)]
        The g x g terms in the order of ``gyrocomp.effects.G_SQUARED_TERMS`` (``matrix2`` only).
    rate_terms_ : dict[str, TemperatureRateTerm]
        Per axis with a temperature-rate term (``rate``, ``rate+lag``), the term fitted.
    bands_ : dict[str, tuple or None]
        The hysteresis band used per axis [degC] (given, found in the data, or None).
    excited_axes_ : tuple of str
        Accelerometer axes the positions excite (within-run spread above ``EXCITATION_G``).
    segments_ : list of list of StaticSegment
        The static segments used, per run.
    """

    order: int | dict[str, int]
    hysteresis: str = "auto"
    hysteresis_order: int | str = "auto"
    band_degc: tuple[float, float] | None | dict[str, tuple[float, float] | None] = None
    block_s: float = DEFAULT_BLOCK_S
    bin_width_degc: float | None = None
    reselect_order: bool = False
    max_order: int = 5
    acceleration: str = "none"
    static_min_duration_s: float = 10.0
    weighting: str | dict[str, str] = "temperature-balanced"
    shared_lag: bool = True
    refine_band: bool = False
    branch_order: int | dict[str, int] = MAX_BRANCH_ORDER
    curve: str | dict[str, str] = POLY_FAMILY
    extended: bool = False
    turning_table_size: int | str | dict[str, int] = "auto"
    play_bank_size: int | str | dict[str, int] = "auto"

    @staticmethod
    def _of(value, axis: str):
        return value[axis] if isinstance(value, dict) else value

    def _candidates(self, axis: str) -> list[str]:
        mode = self._of(self.hysteresis, axis)
        return list(CANDIDATES) if mode == "auto" else [mode]

    def _spec(self, name: str, order: int, hysteresis_order: int = 2, axis: str = "", size: int = 0) -> _Spec:
        """The candidate ``name`` at polynomial ``order`` (``hysteresis_order``: a turning-point polynomial's; ``size``:
        a turning-point table's knots or a bank's plays, 0 for 8 where the size is chosen)."""
        lag = name == "lag" or name.endswith("+lag")
        curve = self._of(self.curve, axis)
        if "turning-table" in name:
            fixed = self._of(self.turning_table_size, axis)
            return _Spec(order, lag, 0, curve=curve, table=int(fixed) if fixed != "auto" else size or 8)
        if "play-bank" in name:
            fixed = self._of(self.play_bank_size, axis)
            return _Spec(order, lag, 0, curve=curve, plays=int(fixed) if fixed != "auto" else size or 8)
        if "rate" in name:
            return _Spec(order, lag, 0, curve=curve, rate=True)
        if "branch" in name:
            return _Spec(order, lag, 0, int(self._of(self.branch_order, axis)), curve=curve)
        if "turning-point" not in name:
            return _Spec(order, lag, 0, curve=curve)
        fixed = self._of(self.hysteresis_order, axis)
        return _Spec(order, lag, hysteresis_order if fixed == "auto" else int(fixed), curve=curve)

    def fit(self, recordings: list[Recording]) -> "ThermalHysteresisModel":
        """Fit on ``recordings`` (each one power-on at rest) and return self."""
        if isinstance(recordings, Recording):
            recordings = [recordings]
        self._check_settings()
        self.curves_, self.lag_time_constants_s_, self.hysteresis_ = {}, {}, {}
        self.turn_on_biases_, self.scores_, self.order_scores_ = {}, {}, {}
        self.memories_ = {}
        self.bands_ = {}
        self.rate_terms_ = {}
        self.g_sensitivity_dps_per_g_, self.g_sensitivity_se_dps_per_g_ = {}, {}
        self.g_squared_dps_per_g2_, self.g_squared_se_dps_per_g2_ = {}, {}
        axes = fit_axes(recordings)
        pieces = self._pieces(recordings)
        self.selection_ = (
            "fixed"
            if self.hysteresis != "auto" and self.hysteresis_order != "auto"
            else ("leave-one-run-out" if len(recordings) >= 2 else "bic")
        )
        choices = {axis: self._choose(axis, recordings, pieces, first=axis == axes[0]) for axis in axes}
        taus = self._shared_lag(choices) if self.shared_lag and one_temperature_column(recordings) else {}
        self.lag_evidence_ = {}
        for axis, choice in choices.items():
            self._store(axis, choice, taus.get(axis))
        return self

    def _check_settings(self) -> None:
        for mode in self.hysteresis.values() if isinstance(self.hysteresis, dict) else [self.hysteresis]:
            if mode not in HYSTERESIS_CHOICES:
                raise InputError(f"hysteresis: {mode!r}; use one of {', '.join(HYSTERESIS_CHOICES)}")
        for h in self.hysteresis_order.values() if isinstance(self.hysteresis_order, dict) else [self.hysteresis_order]:
            if h != "auto" and not (isinstance(h, int) and 0 <= h <= MAX_HYSTERESIS_ORDER):
                raise InputError(f"hysteresis_order: {h!r}; use 'auto' or 1..{MAX_HYSTERESIS_ORDER}")
        for w in self.weighting.values() if isinstance(self.weighting, dict) else [self.weighting]:
            if w not in ("time", "temperature-balanced"):
                raise InputError(f"weighting: {w!r}; use 'time' or 'temperature-balanced'")
        for band in self.band_degc.values() if isinstance(self.band_degc, dict) else [self.band_degc]:
            if band is not None and not band[0] < band[1]:
                raise InputError(f"band_degc: {band}; give (low, high) with low < high [degC]")
        if not self.block_s > 0:
            raise InputError(f"block_s: must be positive, got {self.block_s}")
        if self.acceleration not in ACCELERATION_CHOICES:
            raise InputError(f"acceleration: {self.acceleration!r}; use one of {', '.join(ACCELERATION_CHOICES)}")

    def _problem(self, axis: str, recordings: list[Recording], pieces, first: bool) -> _Problem:
        """The least-squares problem of one axis: block means of every run, weights, hysteresis threshold and
        the accelerometer columns."""
        temps = [rec.temperature_for(axis) for rec in recordings]
        lo = min(float(t.min()) for t in temps)
        hi = max(float(t.max()) for t in temps)
        width = bin_width_for(temps, self.bin_width_degc)
        block_s = max(self.block_s, 1.0 / recordings[0].rate_hz)
        runs = [PreparedRun.of(rec).block_means(axis, block_s, width, piece) for rec, piece in zip(recordings, pieces)]
        if self._of(self.weighting, axis) == "time":  # every second counts equally, as in the drift judged
            runs = [dataclasses.replace(r, weight=r.samples / r.samples.max()) for r in runs]
        threshold = max(
            PreparedRun.of(rec).of_temperature(axis, "turn threshold", turn_threshold_degc) for rec in recordings
        )
        accel_cols, square_cols = self._accel_columns(runs, first)
        return _Problem(
            runs,
            (lo + hi) / 2,
            (hi - lo) / 2 if hi > lo else 1.0,
            threshold,
            self._of(self.band_degc, axis),
            block_s,
            accel_cols,
            square_cols,
            self.extended,
        )

    def _choose(self, axis: str, recordings: list[Recording], pieces, first: bool) -> _AxisChoice:
        """The candidate of one axis: given, or the best by leave-one-run-out error (BIC with one run)."""
        problem = self._problem(axis, recordings, pieces, first)
        band = problem.band
        n_runs = len(recordings)
        scores: dict[str, float] = {}
        best_spec: dict[str, _Spec] = {}
        order = self.order[axis] if isinstance(self.order, dict) else int(self.order)
        score = problem.held_out_error if n_runs >= 2 else problem.bic
        found = None
        if band is None and self.selection_ != "fixed" and any("turning-point" in c for c in self._candidates(axis)):
            found = problem.observed_band(order)
        bands: dict[str, tuple[float, float] | None] = {}
        for name in self._candidates(axis):
            # candidates compared at hysteresis order 2 (the thesis's); the winner's order is validated after
            best_spec[name] = self._spec(name, order, axis=axis)
            scores[name] = math.nan if self.selection_ == "fixed" else score(best_spec[name])
            bands[name] = band
            if found is not None and "turning-point" in name:
                # the band the data shows, tried against none: the data chooses
                problem.band = found
                with_band = score(best_spec[name])
                problem.band = band
                if with_band < scores[name]:
                    scores[name], bands[name] = with_band, found
        chosen = self._pick(axis, scores, n_runs)
        sized = self._sized(chosen, order, axis, score, scores[chosen], n_runs)
        if sized is not None:
            best_spec[chosen], scores[chosen] = sized
        problem.band = bands.get(chosen, band)
        spec = best_spec[chosen]
        if self.reselect_order and self.selection_ != "fixed" and (chosen != "none" or self.acceleration != "none"):
            # the binned polynomial's order was chosen with lag, hysteresis and g-sensitivity unmodelled,
            # which a higher order partly imitates; choose it again inside the winning candidate
            tried = {
                o: score(dataclasses.replace(spec, order=o, branch=0, width_degc=0.0, smoothing_s=0.0))
                for o in range(1, self.max_order + 1)
            }
            spec = dataclasses.replace(spec, order=_simplest(tried, n_runs), branch=0, width_degc=0.0, smoothing_s=0.0)
            self.order_scores_[axis] = tried
        return _AxisChoice(problem, spec, chosen, scores)

    def _sized(self, chosen: str, order: int, axis: str, score, scored: float, n_runs: int):
        """The memory ``chosen`` at the size its validation picks where the size is not given (the turning-point
        polynomial's order, scored as ``scored`` at order 2; a turning-point table's knots; a bank's plays), with
        its score: (spec, score), or None where there is no size to choose."""
        if self.selection_ == "fixed":
            return None
        if "turning-point" in chosen and self.hysteresis_order == "auto":
            tried = {
                p: scored if p == 2 else score(self._spec(chosen, order, p, axis))
                for p in range(1, MAX_HYSTERESIS_ORDER + 1)
            }
            pick = _simplest(tried, n_runs)
            return self._spec(chosen, order, pick, axis), tried[pick]
        sizes = {
            "turning-table": (TURNING_TABLE_SIZES, self.turning_table_size),
            "play-bank": (PLAY_BANK_SIZES, self.play_bank_size),
        }
        family = next((sizes[f] for f in sizes if f in chosen), None)
        if family is None or family[1] != "auto":
            return None
        tried = {m: score(self._spec(chosen, order, axis=axis, size=m)) for m in family[0]}
        pick = _simplest(tried, n_runs)
        return self._spec(chosen, order, axis=axis, size=pick), tried[pick]

    def _pick(self, axis: str, scores: dict[str, float], n_runs: int) -> str:
        if len(scores) == 1:
            return next(iter(scores))
        finite = {k: v for k, v in scores.items() if math.isfinite(v)}
        if not finite:
            raise ModelError(f"{axis}: no hysteresis candidate could be scored")
        return simplest_within(finite, CANDIDATES, by_bic=self.selection_ == "bic")

    @staticmethod
    def _shared_lag(choices: dict[str, _AxisChoice]) -> dict[str, float]:
        """One time constant [s] for every axis with lag: the lag is that of the die behind one temperature
        sensor, not of an axis, and the axes together pin it down better than any one of them. It minimizes
        the sum over those axes of each one's residual sum of squares relative to its own minimum."""
        lagged = {axis: c for axis, c in choices.items() if c.spec.lag}
        if len(lagged) < 2:
            return {}
        profiles = [c.problem.lag_profile(c.spec) for c in lagged.values()]
        lo_s = LAG_MIN_BLOCKS * max(c.problem.block_s for c in lagged.values())
        top_s = lag_search_top_s([r for c in lagged.values() for r in c.problem.runs], lo_s)
        tau_s = best_lag_s(lambda tau: sum(f(tau) for f in profiles), lo_s, top_s)
        return {axis: tau_s for axis in lagged}

    def _store(self, axis: str, choice: _AxisChoice, tau_s: float | None) -> None:
        """Fit the chosen model of one axis on every run (at the shared lag ``tau_s`` [s] when given) and
        keep what it learned."""
        problem, spec = choice.problem, choice.spec
        n_runs = len(problem.runs)
        if self.refine_band and problem.band is not None and spec.hysteresis_order:
            temps = np.concatenate([r.temperature_degc for r in problem.runs])
            step = max(1.0, float(np.ptp(temps)) / 40.0)
            if spec.lag and tau_s is None and n_runs <= JOINT_BAND_MAX_RUNS:
                problem.refine_band_with_lag(spec, step)
            else:
                problem.refine_band(spec, problem.fit(spec, list(range(n_runs)), tau_s)[0], step)
        tau, (coef, consts, rss, (t_lo, t_hi)), spec = problem.fit(spec, list(range(n_runs)), tau_s)
        self.lag_evidence_[axis] = problem.lag_evidence(spec, tau, rss) if tau > 0 else math.nan
        self.curves_[axis] = problem.thermal_design.basis(spec.curve).curve(coef[: spec.order], t_lo, t_hi)
        self.lag_time_constants_s_[axis] = float(tau)
        blocks = problem.thermal_design.layout(problem.terms(spec))  # where each term's coefficients lie
        p = spec.hysteresis_order
        self.hysteresis_[axis] = None
        if p:
            turning = coef[blocks[("turning-point", problem.band)]]
            self.hysteresis_[axis] = HysteresisCurve(
                tuple(float(v) for v in turning[:p]),
                tuple(float(v) for v in turning[p:]),
                problem.threshold,
                problem.band,
                problem.branch_reach(spec, tau),
            )
        if spec.table:
            knots = problem.table_knots_degc(spec.table)
            table = coef[blocks[("turning-table", knots)]]
            self.hysteresis_[axis] = TurningTableCurve(
                knots,
                tuple(float(v) for v in table[: spec.table]),
                tuple(float(v) for v in table[spec.table :]),
                problem.threshold,
            )
        if spec.plays:
            widths = problem.play_widths_degc(spec.plays)
            bank = coef[blocks[("play-bank", widths)]]
            self.hysteresis_[axis] = PlayBankCurve(widths, tuple(float(v) for v in bank))
        if spec.branch:
            self.hysteresis_[axis] = BranchCurve(
                tuple(float(v) for v in coef[blocks[("branch", spec.width_degc)]]),
                problem.t_ref,
                problem.t_scale,
                spec.width_degc,
                problem.threshold,
                t_lo,
                t_hi,
            )
        if spec.rate:
            (rate,) = coef[blocks[("rate", spec.smoothing_s)]]
            self.rate_terms_[axis] = TemperatureRateTerm(float(rate), spec.smoothing_s)
        self.bands_[axis] = problem.band
        self.turn_on_biases_[axis] = consts
        self.memories_[axis] = (choice.name, spec.branch or p or spec.table or spec.plays)
        self.scores_[axis] = choice.scores
        if self.acceleration != "none":
            self._store_acceleration(axis, problem, spec, tau, coef, blocks[("acceleration",)].start, n_runs)

    def _pieces(self, recordings: list[Recording]) -> list[list[slice] | None]:
        self.segments_, pieces = static_pieces(recordings, self.static_min_duration_s)
        return pieces

    def _accel_columns(self, runs: list[RunBlocks], warn: bool) -> tuple[tuple[int, ...], tuple[int, ...]]:
        if self.acceleration == "none":
            return (), ()
        if any(r.accel_g is None for r in runs):
            raise InputError(
                "acceleration: the runs need accel_x, accel_y and accel_z columns for a g-sensitivity "
                "fit; map them with columns= or fit with acceleration='none'"
            )
        excited, squares, self.excited_axes_ = excited_columns(
            [r.accel_g for r in runs], [r.weight for r in runs], squares=self.acceleration == "matrix2", warn=warn
        )
        return excited, squares

    def _store_acceleration(
        self, axis: str, problem: _Problem, spec: _Spec, tau: float, coef: np.ndarray, start: int, n_runs: int
    ) -> None:
        """Keep the g (and g x g) sensitivity of one axis, whose coefficients begin at ``coef[start]``."""
        full, cov = problem.covariance(spec, tau)
        se_all = np.sqrt(np.maximum(np.diag(cov), 0.0))[n_runs:]
        g, g_se = np.zeros(3), np.full(3, np.nan)
        for k, j in enumerate(problem.accel_cols):
            g[j], g_se[j] = coef[start + k], se_all[start + k]
        self.g_sensitivity_dps_per_g_[axis] = g
        self.g_sensitivity_se_dps_per_g_[axis] = g_se
        if self.acceleration == "matrix2":
            q, q_se = np.zeros(6), np.full(6, np.nan)
            base = start + len(problem.accel_cols)
            for k, m in enumerate(problem.square_cols):
                q[m], q_se[m] = coef[base + k], se_all[base + k]
            self.g_squared_dps_per_g2_[axis] = q
            self.g_squared_se_dps_per_g2_[axis] = q_se


def static_pieces(
    recordings: list[Recording], min_duration_s: float, warn: bool = True
) -> tuple[list, list[list[slice] | None]]:
    """Per run, its static segments and the stretches a fit uses: the static segments where the unit moves
    between positions (runs with an accelerometer), else None (every stretch between time gaps); with ``warn``,
    a run with an accelerometer but no static segment is said (once per fit: the model choice asks without)."""
    segments, out = [], []
    for rec in recordings:
        # an accelerometer's own model uses the pieces it is given: its motion is what it measures
        moves = rec.accel_g is not None and PreparedRun.of(rec).channel == "gyro"
        segs = PreparedRun.of(rec).static_segments(min_duration_s=min_duration_s) if moves else []
        segments.append(segs)
        if moves and not segs and warn:
            warnings.warn(
                f"{rec.source}: no static segment found; fitting on every sample",
                DataQualityWarning,
                stacklevel=user_stacklevel(),
            )
        out.append([slice(g.start, g.stop) for g in segs] if segs else None)
    return segments, out


__all__ = ["CANDIDATES", "HYSTERESIS_CHOICES", "ThermalHysteresisModel", "static_pieces"]
