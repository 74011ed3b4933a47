"""The thermal fit's least-squares problem of one axis: the block means of every run, the columns of one
candidate (:class:`ThermalSpec`) at a lag, the weighted solve, and the one-parameter searches over the lag, the
branch crossover width, the rate term's smoothing and the band's edges, the held-out error and the covariance.
:class:`gyrocomp.fitting.thermal.ThermalHysteresisModel` chooses and fits a candidate per axis on it.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..curves.polynomial import POLY_FAMILY
from ..effects import find_turns, thermal_lag
from ..calibration.candidate import memory_name
from .design import Terms, ThermalDesign
from .grid_search import LAG_MIN_BLOCKS, best_lag_s, lag_search_top_s, plausible_middle
from ..runs.prepared import RunBlocks
from ..curves.hysteresis import parting_band_degc
from ..curves.play_bank import play_half_widths_degc
from ..curves.turning_table import largest_turn_distance_degc, turning_table_knots_degc


#: smoothing time constants the final fit tries for a temperature-rate term [s] (the middle of those the data
#: cannot tell from the best: ThermalProblem.best_smoothing); the model choice's folds try FOLD_RATE_SMOOTHINGS_S
RATE_SMOOTHINGS_S = tuple(float(s) for s in np.geomspace(30.0, 3000.0, 11))
#: crossover widths the final fit tries for a branch model [degC] (refined: see ThermalProblem.best_width); the
#: model choice's folds try the coarser gyrocomp.fitting.selection.FOLD_BRANCH_WIDTHS_DEGC
BRANCH_WIDTHS_DEGC = tuple(float(w) for w in np.geomspace(1.0, 40.0, 9))
#: held-out residuals are moving-averaged over this long before their RMS is taken [s], so that the
#: score measures drift (what compensation is for) rather than white noise, which no model removes
SCORE_WINDOW_S = 60.0


@dataclass(frozen=True)
class ThermalSpec:
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
class ThermalProblem:
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

    def model_temperature(self, run: RunBlocks, spec: ThermalSpec, tau: float) -> np.ndarray:
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

    def terms(self, spec: ThermalSpec) -> Terms:
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

    def features(self, run: RunBlocks, temp: np.ndarray, spec: ThermalSpec, t_lo: float, t_hi: float) -> np.ndarray:
        """Columns of the shape and the hysteresis at model temperature ``temp`` [degC] (the curves applied as fitted
        on [t_lo, t_hi]), then of the g and g x g sensitivity (the excited accelerometer axes only)."""
        return self.thermal_design.columns(temp, run.accel_g, self.terms(spec), t_lo, t_hi, time_s=run.time_s)

    def branch_reach(self, spec: ThermalSpec, tau: float) -> tuple[float, float]:
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

    def design(self, spec: ThermalSpec, tau: float, which: list[int]):
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

    def solve(self, spec: ThermalSpec, tau: float, which: list[int]):
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

    def best_width(self, spec: ThermalSpec, tau: float, which: list[int]) -> ThermalSpec:
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

    def best_smoothing(self, spec: ThermalSpec, tau: float, which: list[int]) -> ThermalSpec:
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

    def best_shape(self, spec: ThermalSpec, tau: float, which: list[int]) -> ThermalSpec:
        """``spec`` with its branch crossover width and its rate term's smoothing found at lag ``tau`` [s]."""
        return self.best_smoothing(self.best_width(spec, tau, which), tau, which)

    def fit(self, spec: ThermalSpec, which: list[int], tau_s: float | None = None):
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

    def refine_band(self, spec: ThermalSpec, tau_s: float, step_degc: float) -> None:
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

    def refine_band_with_lag(self, spec: ThermalSpec, step_degc: float) -> None:
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

    def lag_evidence(self, spec: ThermalSpec, tau_s: float, rss: float) -> float:
        """How far the all-run fit of ``spec`` at lag ``tau_s`` [s] (weighted residual sum of squares ``rss``)
        stands from the same fit at the bottom of the lag search (two blocks), as a chi-square of one parameter:
        the residual's independent stretches (its length over :data:`SCORE_WINDOW_S`, as the block residuals are
        correlated over that long) times the relative increase of the rss there."""
        which = list(range(len(self.runs)))
        floor = self.solve(spec, LAG_MIN_BLOCKS * self.block_s, which)[2]
        duration_s = sum(float(r.time_s[-1] - r.time_s[0]) for r in self.runs)
        return duration_s / SCORE_WINDOW_S * (floor - rss) / max(rss, 1e-300)

    def lag_profile(self, spec: ThermalSpec) -> Callable[[float], float]:
        """The all-run residual sum of squares as a function of tau [s], divided by its minimum (1 at the
        axis's own best tau), so that axes with different noise weigh the same in a shared lag."""
        which = list(range(len(self.runs)))
        _, (_, _, own, _), spec = self.fit(spec, which)  # a branch model's width: the one at its own best lag
        return lambda tau: self.solve(spec, tau, which)[2] / max(own, 1e-300)

    def held_out_error(self, spec: ThermalSpec) -> float:
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
        spec = ThermalSpec(order, False, 0)
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

    def covariance(self, spec: ThermalSpec, tau: float) -> tuple[np.ndarray, np.ndarray]:
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

    def bic(self, spec: ThermalSpec) -> float:
        _, (coef, consts, rss, _), _ = self.fit(spec, list(range(len(self.runs))))
        n = sum(r.value.size for r in self.runs)
        w = sum(float(np.sum(r.weight)) for r in self.runs)
        k = coef.size + consts.size + (1 if spec.lag else 0)
        return n * math.log(max(rss / w, 1e-300)) + k * math.log(n)


__all__ = ["BRANCH_WIDTHS_DEGC", "RATE_SMOOTHINGS_S", "SCORE_WINDOW_S", "ThermalProblem", "ThermalSpec"]
