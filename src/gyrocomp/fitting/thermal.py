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
import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..curves.polynomial import POLY_FAMILY
from ..curves.rate import TemperatureRateTerm
from ..errors import DataQualityWarning, InputError, ModelError, user_stacklevel
from ..calibration.candidate import MEMORIES
from ..recording import Recording
from .thermal_problem import ThermalProblem, ThermalSpec
from .grid_search import LAG_MIN_BLOCKS, best_lag_s, lag_search_top_s
from .gsensitivity import ACCELERATION_CHOICES, excited_columns
from ..runs.prepared import PreparedRun, RunBlocks, fit_axes
from ..runs.prepared import one_temperature_column
from .temperature_bins import bin_width_for
from .learned_attributes import LearnedAttributes
from ..curves.hysteresis import BranchCurve, HysteresisCurve, turn_threshold_degc
from ..curves.play_bank import PLAY_BANK_SIZES, PlayBankCurve
from ..curves.turning_table import TURNING_TABLE_SIZES, TurningTableCurve
from .polynomial_model import simplest_within

#: what ``hysteresis`` may ask for: a memory, or ``auto`` (the data's choice among CANDIDATES)
HYSTERESIS_CHOICES = ("auto", *MEMORIES)
#: the memories the default compares, simplest first: every memory but the turning-point table and the bank of
#: plays, which are fitted where asked for (docs/how-the-fit-works.md says why); where the runs ramp at one rate a rate term counts as
#: more complex in the model choice (gyrocomp.fitting.selection.ONE_RATE_RATE_TERM_COST)
CANDIDATES = tuple(c for c in HYSTERESIS_CHOICES[1:] if not c.startswith(("turning-table", "play-bank")))
#: terms of the difference between the heating and the cooling curve (a constant, then a slope)
MAX_BRANCH_ORDER = 2
MAX_HYSTERESIS_ORDER = 3
DEFAULT_BLOCK_S = 2.0
#: with this many runs or fewer, a band's edges and the lag are refined together (ThermalProblem.refine_band_with_lag):
#: the runs' few turns are all that tell the lag from the band's edge. With more, the lag is held by runs of other
#: ramps and the band refined at it (jointly on three runs the ADXRS450 preset's lag came out 72-78 s for a truth
#: of 60, against 48-60 s; the next run's drift 2.03x perfect against 1.97x over ten seeds)
JOINT_BAND_MAX_RUNS = 2


@dataclass(frozen=True)
class _AxisChoice:
    """What one axis's choice settled: its problem (band set), the candidate and every candidate's score."""

    problem: ThermalProblem
    spec: ThermalSpec
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
        Without it, the band where the branches visibly part (:meth:`ThermalProblem.observed_band`) is tried
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
        blocks), as a chi-square of one parameter (:meth:`ThermalProblem.lag_evidence`); at most
        :data:`gyrocomp.fitting.grid_search.LAG_EVIDENCE_CHI2`, this axis's data do not see the lag. NaN without lag.
    hysteresis_ : dict[str, HysteresisCurve, TurningTableCurve, BranchCurve or None]
    turn_on_biases_ : dict[str, np.ndarray]
    memories_ : dict[str, (str, int)]
        The candidate kept per axis: its memory (``none``, ``lag``, ``turning-point``, ``turning-point+lag``) and
        turning-point order (in words: :func:`gyrocomp.calibration.candidate.memory_label`).
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

    def _spec(self, name: str, order: int, hysteresis_order: int = 2, axis: str = "", size: int = 0) -> ThermalSpec:
        """The candidate ``name`` at polynomial ``order`` (``hysteresis_order``: a turning-point polynomial's; ``size``:
        a turning-point table's knots or a bank's plays, 0 for 8 where the size is chosen)."""
        lag = name == "lag" or name.endswith("+lag")
        curve = self._of(self.curve, axis)
        if "turning-table" in name:
            fixed = self._of(self.turning_table_size, axis)
            return ThermalSpec(order, lag, 0, curve=curve, table=int(fixed) if fixed != "auto" else size or 8)
        if "play-bank" in name:
            fixed = self._of(self.play_bank_size, axis)
            return ThermalSpec(order, lag, 0, curve=curve, plays=int(fixed) if fixed != "auto" else size or 8)
        if "rate" in name:
            return ThermalSpec(order, lag, 0, curve=curve, rate=True)
        if "branch" in name:
            return ThermalSpec(order, lag, 0, int(self._of(self.branch_order, axis)), curve=curve)
        if "turning-point" not in name:
            return ThermalSpec(order, lag, 0, curve=curve)
        fixed = self._of(self.hysteresis_order, axis)
        return ThermalSpec(order, lag, hysteresis_order if fixed == "auto" else int(fixed), curve=curve)

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

    def _problem(self, axis: str, recordings: list[Recording], pieces, first: bool) -> ThermalProblem:
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
        return ThermalProblem(
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
        best_spec: dict[str, ThermalSpec] = {}
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
        self,
        axis: str,
        problem: ThermalProblem,
        spec: ThermalSpec,
        tau: float,
        coef: np.ndarray,
        start: int,
        n_runs: int,
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
