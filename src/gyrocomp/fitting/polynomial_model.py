"""Fitting the polynomial temperature model (thesis section 2.5.2): the shape a_1..a_p shared by the runs and one
turn-on constant per run, by least squares on temperature bins (every temperature interval counts equally,
whatever the heating rate), the order chosen by leave-one-run-out error (or BIC with one run). The curve it
produces is :class:`gyrocomp.curves.polynomial.PolynomialCurve`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, ModelError
from ..runs.prepared import fit_axes
from ..recording import Recording
from .temperature_bins import TemperatureBins, bin_by_temperature, bin_width_for
from .learned_attributes import LearnedAttributes
from ..curves.polynomial import MAX_ORDER, PolynomialCurve, power_columns

#: with automatic order, the lowest order whose CV score is within this factor of the best wins
PARSIMONY_TOLERANCE = 1.01


def simplest_within(scores: dict, simplest_first, *, by_bic: bool = False, tolerance: float = PARSIMONY_TOLERANCE):
    """The model choice's parsimony rule, shared by the order and the memory choices: the first key of
    ``simplest_first`` whose score is at most ``tolerance`` times the best finite score (held-out scores); with
    ``by_bic``, the first whose score is the best itself (BIC already charges for complexity).

    ``scores`` maps keys (orders, memory names) to scores, lower better; non-finite scores never win.
    """
    finite = {k: v for k, v in scores.items() if math.isfinite(v)}
    if not finite:
        raise ModelError("scores: no candidate has a finite score")
    best = min(finite.values())
    limit = best if by_bic else best * tolerance
    return next(k for k in simplest_first if k in finite and finite[k] <= limit)


@dataclass(frozen=True)
class _Design:
    bins: TemperatureBins
    n_runs: int
    t_ref: float
    t_scale: float
    t_min: float
    t_max: float
    folds: np.ndarray  # the validation fold of each run (runs of one fold are left out together)

    def powers(self, temperature: np.ndarray, order: int, t_min=None, t_max=None) -> np.ndarray:
        lo = self.t_min if t_min is None else t_min
        hi = self.t_max if t_max is None else t_max
        u = (np.clip(temperature, lo, hi) - self.t_ref) / self.t_scale
        return power_columns(u, 1, order)


def _solve(design: _Design, order: int, runs: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Weighted least squares of the bins of ``runs``: (shape coefficients, run constants, weighted RSS)."""
    b = design.bins
    sel = np.isin(b.run, runs)
    t, y, w, r = b.temperature_degc[sel], b.value[sel], b.weight[sel], b.run[sel]
    run_index = np.searchsorted(runs, r)
    onehot = np.zeros((t.size, runs.size))
    onehot[np.arange(t.size), run_index] = 1.0
    x = np.hstack([onehot, design.powers(t, order, t.min(), t.max())])
    sw = np.sqrt(w)
    coef, *_ = np.linalg.lstsq(x * sw[:, None], y * sw, rcond=None)
    resid = y - x @ coef
    return coef[runs.size :], coef[: runs.size], float(np.sum(w * resid**2))


def _leave_one_run_out(design: _Design, order: int) -> float:
    """RMS error [deg/s] of bins of each run predicted by a fit on the runs of the other folds (each run's
    constant refitted); with one fold per run, leave one run out."""
    b = design.bins
    sse = wsum = 0.0
    all_runs = np.arange(design.n_runs)
    for fold in np.unique(design.folds):
        train = all_runs[design.folds != fold]
        tr = np.isin(b.run, train)
        shape, _, _ = _solve(design, order, train)
        lo, hi = b.temperature_degc[tr].min(), b.temperature_degc[tr].max()
        for held in all_runs[design.folds == fold]:
            sel = b.run == held
            t, y, w = b.temperature_degc[sel], b.value[sel], b.weight[sel]
            if not y.size:
                continue
            pred = design.powers(t, order, lo, hi) @ shape if order else np.zeros_like(y)
            e = y - pred
            e -= np.sum(w * e) / np.sum(w)
            sse += float(np.sum(w * e**2))
            wsum += float(np.sum(w))
    return math.sqrt(sse / wsum)


def _bic(design: _Design, order: int) -> float:
    _, _, rss = _solve(design, order, np.arange(design.n_runs))
    n = float(np.sum(design.bins.weight))
    k = order + design.n_runs
    return n * math.log(max(rss, 1e-300) / n) + k * math.log(n)


@dataclass
class PolynomialTemperatureModel(LearnedAttributes):
    """Polynomial temperature model, fitted per gyro axis on one or many runs jointly.

    Parameters
    ----------
    order : int or "auto"
        Polynomial order (0..5), or ``"auto"``: chosen by leave-one-run-out cross-validation
        with two runs or more, by the Bayesian information criterion with one.
    max_order : int
        Highest order tried by ``"auto"``.
    bin_width_degc : float, optional
        Temperature bin width [degC]; default: the temperature span / 100.
    folds : tuple of int, optional
        The validation fold of each recording: pieces of one run (its static positions, each with its own
        constant) are left out together. Default: one fold per recording.

    Attributes (after ``fit``)
    --------------------------
    curves_ : dict[str, PolynomialCurve]
        The fitted shape of each axis.
    turn_on_biases_ : dict[str, np.ndarray]
        The fitted constant of each run [deg/s; g for an accelerometer's axes], per axis.
    scores_ : dict[str, dict[int, float]]
        Per axis, the selection score of each order tried (CV RMS [the axis's unit], or BIC).
    selection_ : str
        ``"fixed"``, ``"leave-one-run-out"`` or ``"bic"``.
    fit_rms_ : dict[str, float]
        Weighted RMS of the bin residuals of the final fit [the axis's unit: deg/s; g for an accelerometer's axes].
    """

    order: int | str = "auto"
    max_order: int = MAX_ORDER
    bin_width_degc: float | None = None
    folds: tuple[int, ...] | None = None

    def fit(self, recordings: list[Recording]) -> "PolynomialTemperatureModel":
        """Fit on ``recordings`` (each one power-on) and return self."""
        if isinstance(recordings, Recording):
            recordings = [recordings]
        if not recordings:
            raise InputError("fit: no recordings given")
        if self.order != "auto" and not (isinstance(self.order, int) and 0 <= self.order <= MAX_ORDER):
            raise InputError(f"order: {self.order!r}; use 'auto' or a whole number from 0 to {MAX_ORDER}")
        axes = fit_axes(recordings)
        for rec in recordings[1:]:
            if fit_axes([rec]) != axes:
                kind = "accelerometer" if rec.unit_of(axes[0]) == "g" else "gyro"
                raise InputError(
                    f"{rec.source}: {kind} axes {', '.join(fit_axes([rec]))} differ from "
                    f"{recordings[0].source}'s ({', '.join(axes)}); fit runs of the same sensor together"
                )
        self.curves_, self.turn_on_biases_, self.scores_, self.fit_rms_ = {}, {}, {}, {}
        for axis in axes:
            temps = [rec.temperature_for(axis) for rec in recordings]
            values = [rec.signal(axis) for rec in recordings]
            width = bin_width_for(temps, self.bin_width_degc)
            bins = bin_by_temperature(temps, values, width)
            t_min = min(float(t.min()) for t in temps)
            t_max = max(float(t.max()) for t in temps)
            span = t_max - t_min
            folds = np.arange(len(recordings)) if self.folds is None else np.asarray(self.folds)
            if folds.shape != (len(recordings),):
                raise InputError(f"folds: {folds.size} given for {len(recordings)} recordings; give one per recording")
            design = _Design(
                bins, len(recordings), (t_min + t_max) / 2, span / 2 if span > 0 else 1.0, t_min, t_max, folds
            )
            distinct = np.unique(bins.temperature_degc).size
            order = self._choose_order(axis, design, distinct)
            shape, consts, rss = _solve(design, order, np.arange(len(recordings)))
            self.curves_[axis] = PolynomialCurve(
                tuple(float(a) for a in shape), design.t_ref, design.t_scale, t_min, t_max
            )
            self.turn_on_biases_[axis] = consts
            self.fit_rms_[axis] = math.sqrt(rss / float(np.sum(bins.weight)))
        return self

    def _choose_order(self, axis: str, design: _Design, distinct: int) -> int:
        usable = distinct - 1  # a polynomial of order p needs p+1 distinct temperatures
        if self.order != "auto":
            if self.order > usable:
                raise ModelError(
                    f"{axis}: order {self.order} needs {self.order + 1} distinct temperature bins, "
                    f"the data has {distinct}; use a lower order or data over a wider temperature range"
                )
            self.selection_ = "fixed"
            self.scores_[axis] = {}
            return int(self.order)
        candidates = list(range(0, min(self.max_order, usable) + 1))
        if np.unique(design.folds).size >= 2:
            self.selection_ = "leave-one-run-out"
            scores = {p: _leave_one_run_out(design, p) for p in candidates}
            chosen = simplest_within(scores, candidates)
        else:
            self.selection_ = "bic"
            scores = {p: _bic(design, p) for p in candidates}
            chosen = simplest_within(scores, candidates, by_bic=True)
        self.scores_[axis] = scores
        return chosen

    def predict_error(self, recording: Recording) -> np.ndarray:
        """Predicted error (n, k) [deg/s]: the shape plus the mean turn-on constant of the fit runs."""
        curves, constants = self.curves_, self.turn_on_biases_  # NotFittedError before a fit
        cols = []
        for axis in recording.gyro_axes:
            cols.append(curves[axis].shape(recording.temperature_for(axis)) + constants[axis].mean())
        return np.column_stack(cols)


__all__ = ["PARSIMONY_TOLERANCE", "PolynomialTemperatureModel", "simplest_within"]
