"""The drift a fitted model should leave on a use profile, and what more calibration data would change: the
model's own uncertainty turned into a prediction.

For one gyro axis, the error a model leaves on a new power-on is, to first order in what its fit got wrong,

    e(t) = x(t) . delta + n(t) + h(t)

- ``x(t)`` the columns of the axis's curve at the model temperature (its thermal lag's too: the derivative of the
  curve's output by the lag; the temperature-rate term's column), ``delta`` the error of their coefficients;
- ``n(t)`` the part's own residual, white plus power-law drift (:mod:`gyrocomp.fitting.drift_gls`), estimated from
  the variogram of what the model leaves on its calibration runs;
- ``h(t)`` what holding the curve (or continuing it along its tangent) past the calibrated range leaves,
  estimated from the curve's own slope (or curvature) at the edge, or, when larger, from how fast the curve's
  family fitted without the top (or bottom) fifth of the runs' range parts past that cut from the same family
  fitted on all of them (:class:`EdgeRates`).

Under the residual's drift model, generalized least squares on the calibration runs (each with its own turn-on
constant, projected out) gives the covariance of ``delta``. The held-out drift the accuracy page scores, the RMS
about its mean of the 60 s moving average of ``e``, squared, is then a quadratic form of Gaussian vectors plus the
white noise's share; its mean and its 2.5 and 97.5 % points come from the form's eigenvalues
(:class:`DriftForecast`). Adding the information of a run not yet recorded (:meth:`AxisInformation.with_run`)
predicts the drift after it: the basis of :mod:`gyrocomp.evaluation.run_advice`.

The forecast takes the model's form as right: a memory of the turn (turning-point or branch hysteresis) is
applied but its coefficients' uncertainty is not counted (:attr:`AxisForecast.not_covered` says so), and what
the form cannot carry shows only as far as it is in the residual's drift. The model choice's own uncertainty is
added to the interval's upper end: how far the nearest forms it could not tell apart, fitted in their own right
(:mod:`gyrocomp.evaluation.choice_alternatives`), part from the chosen curve on the profile.

References: T. W. Anderson, *The Statistical Analysis of Time Series*, 1971 (GLS); A. M. Mathai, S. B. Provost,
*Quadratic Forms in Random Variables*, 1992 (a quadratic form of Gaussians as a weighted sum of chi-squares).
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..calibration.calibration import AxisCalibration, Calibration
from ..calibration.compensate import apply
from ..curves.lookup import LookupTableCurve
from ..curves.polynomial import POLY_FAMILY, PolynomialCurve
from ..curves.protocol import BASES, RANGE_TOLERANCE_DEGC, RANGE_TOLERANCE_FRACTION
from ..curves.rate import rate_columns
from ..effects import thermal_lag
from ..errors import DataQualityWarning, InputError, user_stacklevel
from ..fitting.drift_gls import MAX_POINTS, DriftNoise, coarsen, covariance, fit_drift_noise
from ..measures.merit import smoothed_about_mean
from ..measures.ramp_rate import ramp_rate_degc_per_min, typical_ramp_degc_per_min
from ..recording import Recording
from ..simulation.profiles import Profile
from ..threads import single_threaded_blas
from .choice_alternatives import Alternative, choice_alternatives, close_candidates, predicted

#: the moving-average window the accuracy page scores the held-out drift with [s]
DEFAULT_WINDOW_S = 60.0
#: blocks per window: the time resolution of the forecast's series (the longest runs coarser: :data:`MAX_POINTS`)
BLOCKS_PER_WINDOW = 6
#: the residual's variogram is fitted up to 1/this of the run: the forecast needs the drift over a whole use
#: profile, where a fit to the short lags alone extrapolates a smooth misfit's steep growth
NOISE_REACH = 2
#: the most blocks a run not yet recorded is averaged into (its information changes little coarser; its
#: covariance is dense)
CANDIDATE_BLOCKS = 400
#: draws of the quadratic form for its percentiles, and its leading eigenvalues drawn (the rest by their mean)
DRAWS = 4000
LEADING = 60
#: the seed of those draws: a forecast is the same each time it is asked
SEED = 0


@dataclass(frozen=True)
class UseProfile:
    """The temperatures a compensated gyro will see.

    Attributes
    ----------
    time_s : array (n,)
        Times [s], increasing.
    temperature_degc : array (n,)
        Reported temperature at each time [degC].
    name : str
        What the profile is, for tables and messages.
    """

    time_s: np.ndarray
    temperature_degc: np.ndarray
    name: str

    def __post_init__(self) -> None:
        if self.time_s.size < 2 or self.time_s.size != self.temperature_degc.size:
            raise InputError(f"{self.name}: a use profile needs at least 2 times and one temperature at each")

    @classmethod
    def of(cls, recording: Recording) -> "UseProfile":
        """The temperatures of a recorded log (the mean of its columns when it has one per axis).

        Parameters
        ----------
        recording : Recording
            The log; its temperature column is read, its source names the profile.
        """
        if recording.temperature_degc is None:
            raise InputError(f"{recording.source}: no temperature column; a use profile is its temperatures")
        return cls(
            np.asarray(recording.time_s, dtype=float),
            np.asarray(recording.die_temperature_degc, dtype=float),
            recording.source,
        )

    @classmethod
    def cycle(
        cls,
        lo_degc: float,
        hi_degc: float,
        ramp_degc_per_min: float,
        hold_s: float = 600.0,
        cycles: int = 1,
        name: str | None = None,
    ) -> "UseProfile":
        """Heat-cool cycles, sampled at 1 Hz.

        Parameters
        ----------
        lo_degc, hi_degc : float
            The cycle's lower and upper temperature [degC].
        ramp_degc_per_min : float
            The ramp rate [degC/min].
        hold_s : float
            The hold at each end [s].
        cycles : int
            How many cycles, each from ``lo_degc`` up and back.
        name : str, optional
            The profile's name (default: its range and rate in words).
        """
        if not (math.isfinite(lo_degc) and math.isfinite(hi_degc) and hi_degc > lo_degc):
            raise InputError(f"use range {lo_degc:g}..{hi_degc:g} degC: give the lower end first, both finite")
        if not (math.isfinite(ramp_degc_per_min) and ramp_degc_per_min > 0):
            raise InputError(f"ramp {ramp_degc_per_min:g} degC/min: give a positive rate")
        points = [lo_degc] + [hi_degc, lo_degc] * max(1, cycles)
        return set_point_profile(
            points,
            ramp_degc_per_min,
            hold_s,
            name or f"{lo_degc:g}..{hi_degc:g} degC at {ramp_degc_per_min:g} degC/min",
        )


def set_point_profile(points_degc: Sequence[float], ramp_degc_per_min: float, hold_s: float, name: str) -> UseProfile:
    """A chamber's profile: hold ``hold_s`` [s] at each set point of ``points_degc`` [degC], ramping between them at
    ``ramp_degc_per_min`` [degC/min], sampled at 1 Hz (the simulator's ``chamber`` profile)."""
    chamber = Profile(
        "chamber",
        set_points_degc=tuple(float(p) for p in points_degc),
        ramp_rate_degc_per_min=ramp_degc_per_min,
        dwell_s=hold_s,
    ).trajectory(1.0)
    return UseProfile(chamber.time_s, chamber.temperature_degc, name)


#: the share of the calibrated span held out at each end to measure how fast the curve loses track past it
HELD_SHARE = 0.2


@dataclass(frozen=True)
class EdgeRates:
    """An axis's measured extrapolation rates past the low and the high end (None: not measured).

    Attributes
    ----------
    low_dps, high_dps : float or None
        ``k`` of ``e = k d^power`` past the low and the high end [deg/s per degC^power], d the distance [degC].
    power : int
        2 for a curve continued along its tangent, 1 for one held at its edge.
    """

    low_dps: float | None
    high_dps: float | None
    power: int

    def error_dps(self, model_degc: np.ndarray, lo_degc: float, hi_degc: float) -> np.ndarray:
        """The extrapolation error these rates give at ``model_degc`` past [lo, hi] degC [deg/s] (0 inside)."""
        out = np.zeros(np.size(model_degc))
        for rate, beyond, dist in (
            (self.low_dps, model_degc < lo_degc, lo_degc - model_degc),
            (self.high_dps, model_degc > hi_degc, model_degc - hi_degc),
        ):
            if rate is not None:
                out[beyond] = rate * dist[beyond] ** self.power
        return out


@dataclass(frozen=True)
class AxisForecast:
    """One axis's predicted held-out drift on a use profile [deg/s]: the RMS about its mean of the moving average.

    Attributes
    ----------
    axis : str
        The gyro axis.
    drift_dps : float
        Expected drift (the root of the mean square) [deg/s].
    low_dps, high_dps : float
        Its 95 % interval [deg/s] (the upper end with the extrapolation's size added).
    coefficients_dps : float
        The share of the fitted coefficients' uncertainty (RMS) [deg/s].
    noise_dps : float
        The share of the part's own residual, white and drift [deg/s].
    extrapolation_dps : float
        The estimated size of what the curve held (or continued) past the calibrated range leaves [deg/s].
    outside_range_fraction : float
        The share of the profile's model temperature outside the calibrated range (past the tolerance of the
        model's range warning) [0..1].
    lag_s, lag_standard_error_s : float or None
        The thermal lag and its standard error under the residual's drift model [s] (None: no lag).
    not_covered : tuple of str
        What the model applies whose uncertainty the forecast does not count.
    close_candidates : tuple of str
        Candidates of the model choice whose held-out drift was within one standard error of the chosen one's.
    model_choice_dps : float
        How far the fitted alternatives among them part from the chosen curve on the profile (the RMS about its
        mean of the moving average of their difference, the largest) [deg/s]; added to the interval's upper end.
    alternatives : tuple of str
        The forms of those alternatives (:mod:`gyrocomp.evaluation.choice_alternatives`).
    """

    axis: str
    drift_dps: float
    low_dps: float
    high_dps: float
    coefficients_dps: float
    noise_dps: float
    extrapolation_dps: float
    outside_range_fraction: float
    lag_s: float | None = None
    lag_standard_error_s: float | None = None
    not_covered: tuple[str, ...] = ()
    close_candidates: tuple[str, ...] = ()
    model_choice_dps: float = 0.0
    alternatives: tuple[str, ...] = ()

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class DriftForecast:
    """The predicted drift of every gyro axis a model compensates, on one use profile, at a moving-average
    window of ``window_s`` [s]."""

    profile: str
    window_s: float
    axes: dict[str, AxisForecast]

    @property
    def worst(self) -> AxisForecast:
        """The axis of the largest expected drift."""
        return max(self.axes.values(), key=lambda a: a.drift_dps)

    def to_dict(self) -> dict:
        return {
            "profile": self.profile,
            "window_s": self.window_s,
            "axes": {k: v.to_dict() for k, v in self.axes.items()},
        }


#: a use profile ramping faster than this many times the calibration runs' is warned about
FASTER_USE = 1.25


def warn_faster_use(use: UseProfile, calibration_ramp_degc_per_min: float) -> None:
    """Warn when ``use`` ramps faster than :data:`FASTER_USE` times the calibration runs' rate [degC/min]: what the
    model leaves may grow with the ramp rate, which runs at one rate cannot show."""
    ramp = typical_ramp_degc_per_min([(use.time_s, use.temperature_degc)])
    if ramp > FASTER_USE * calibration_ramp_degc_per_min:
        warnings.warn(
            f"{use.name}: the use profile ramps at {ramp:.2g} degC/min, faster than the calibration runs' "
            f"{calibration_ramp_degc_per_min:.2g}: the forecast takes what the model leaves to be the same at any "
            "ramp rate, which runs at one rate cannot show (measured on parts with a term in dT/dt: half the drift "
            "forecast); a run at the faster rate shows it",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )


def _surrogate(ax: AxisCalibration, axis: str) -> tuple[str, int, bool]:
    """(family, size, extended) of the curve family whose columns stand for the axis's curve."""
    curve = ax.temperature
    if isinstance(curve, PolynomialCurve):
        return POLY_FAMILY, curve.order, curve.extrapolation == "linear"
    if isinstance(curve, LookupTableCurve):
        return "table", len(curve.values) - 1, False
    kind = getattr(curve, "kind", type(curve).__name__)
    raise InputError(
        f"{axis}: its temperature curve is a {kind}; "
        "fit a polynomial (the default curve) or a lookup table for a forecast"
    )


def _continued(ax: AxisCalibration):
    """The axis's curve continued along its tangent past its range (a polynomial), else as it is applied."""
    curve = ax.temperature
    if isinstance(curve, PolynomialCurve):
        return dataclasses.replace(curve, extrapolation="linear")
    return curve


@dataclass
class _Run:
    """One run's series at full rate (model temperature) and as blocks, with its whitening factor."""

    time_s: np.ndarray
    reported_degc: np.ndarray
    model_degc: np.ndarray
    factor: int
    extra: np.ndarray  # block means of the columns that do not depend on the range (lag, rate) (m, q)
    block_s: float
    chol: np.ndarray | None = None
    raw: np.ndarray | None = None  # block means of the gyro axis as recorded [deg/s] (calibration runs)
    chosen: np.ndarray | None = None  # the error the chosen model predicts on it [deg/s], once asked
    partings: dict = dataclasses.field(default_factory=dict)  # (alternative, parting) by id of it and width

    def blocks(self, values: np.ndarray) -> np.ndarray:
        return coarsen(values, self.factor)


class AxisInformation:
    """What one axis's calibration runs know about its curve's coefficients, under the residual's drift model:
    build it with :meth:`of`, add a run with :meth:`with_run`, forecast with :meth:`forecast`.

    Parameters
    ----------
    calibration : Calibration
        The fitted model.
    axis : str
        The gyro axis.
    block_s : float
        The block length the series are averaged over [s].
    noise : DriftNoise
        The residual's white and drift model, per block.
    runs : list
        The runs the information comes from.
    """

    def __init__(self, calibration: Calibration, axis: str, block_s: float, noise: DriftNoise, runs: list[_Run]):
        self.calibration, self.axis, self.block_s, self.noise, self.runs = calibration, axis, block_s, noise, runs
        ax = self.ax = calibration.axes[axis]
        self.family, self.size, self.extended = _surrogate(ax, axis)
        self.lo_degc = min(float(r.model_degc.min()) for r in runs)
        self.hi_degc = max(float(r.model_degc.max()) for r in runs)
        self.lo_degc = min(self.lo_degc, ax.temperature.t_min_degc)
        self.hi_degc = max(self.hi_degc, ax.temperature.t_max_degc)
        self._profiles: dict = {}  # a profile's series and its noise's eigenvalues, by profile and window
        self.edge: EdgeRates | None = None  # the measured extrapolation rates (edge_rates), when asked

    @classmethod
    def of(
        cls, calibration: Calibration, recordings: Sequence[Recording], axis: str, window_s: float, left=None
    ) -> "AxisInformation":
        """From a model and the runs it was fitted on (static runs: what it leaves on them is the residual);
        ``left``: what the model leaves on each run, when already computed (:func:`axis_information`)."""
        ax = calibration.axes[axis]
        if ax.temperature is None:
            raise InputError(
                f"{axis}: the model has no temperature curve (constants only); there is nothing to forecast"
            )
        longest = max(r.duration_s for r in recordings)
        block_s = max(window_s / BLOCKS_PER_WINDOW, longest / MAX_POINTS)
        left = _left(calibration, recordings) if left is None else left
        runs, residuals, times = [], [], []
        for rec, out in zip(recordings, left):
            if axis not in rec.gyro_axes:
                raise InputError(f"{rec.source}: no {axis} column; give the runs the model was fitted on")
            run = _series(ax, rec.time_s, rec.temperature_for(axis), block_s, rec.source)
            run.raw = run.blocks(rec.gyro(axis))
            runs.append(run)
            residuals.append(run.blocks(out.gyro(axis) - out.gyro(axis).mean()))
            times.append(run.blocks(rec.time_s))
        noise = fit_drift_noise(residuals, times, reach=NOISE_REACH)
        info = cls(calibration, axis, block_s, noise, runs)
        for run, t in zip(runs, times):
            run.chol = info.factor(t)
        return info

    def factor(self, t_blocks: np.ndarray, block_s: float | None = None) -> np.ndarray:
        """The Cholesky factor of a run's residual covariance at block times ``t_blocks`` [s], of blocks
        ``block_s`` [s] long (default the runs' own: the white part's variance per block scales with it)."""
        import scipy.linalg  # slow to import: only when a forecast is asked

        white = self.noise.white_var * self.block_s / (block_s or self.block_s)
        noise = DriftNoise(white, self.noise.walk_var_per_s, self.noise.exponent)
        return scipy.linalg.cholesky(covariance(t_blocks, noise), lower=True, check_finite=False)

    def columns(self, run: _Run, lo_degc: float, hi_degc: float) -> np.ndarray:
        """The run's block columns (m, p): the curve family's over [lo, hi] degC, then the lag's and rate's."""
        basis = BASES[self.family].over(lo_degc, hi_degc, self.extended)
        shape = basis.columns(run.model_degc, self.size, lo_degc, hi_degc)
        return np.hstack([run.blocks(shape), run.extra])

    def information(self, lo_degc: float, hi_degc: float, extra_runs: Sequence[_Run] = ()) -> np.ndarray:
        """The GLS information (p, p) of the shared coefficients, each run's constant projected out."""
        import scipy.linalg

        total = None
        for run in [*self.runs, *extra_runs]:
            x = self.columns(run, lo_degc, hi_degc)
            xw = scipy.linalg.solve_triangular(run.chol, x, lower=True, check_finite=False)
            one = scipy.linalg.solve_triangular(run.chol, np.ones(x.shape[0]), lower=True, check_finite=False)
            xw = xw - np.outer(one, one @ xw) / float(one @ one)
            total = xw.T @ xw if total is None else total + xw.T @ xw
        return total

    def with_run(self, time_s: np.ndarray, temperature_degc: np.ndarray, name: str) -> "_Run":
        """A run not yet recorded, at times ``time_s`` [s] and reported temperatures ``temperature_degc`` [degC],
        as the forecast adds it (:meth:`forecast`'s ``extra_runs``), in at most :data:`CANDIDATE_BLOCKS` blocks."""
        duration_s = float(time_s[-1] - time_s[0]) if np.size(time_s) > 1 else 0.0
        run = _series(self.ax, time_s, temperature_degc, max(self.block_s, duration_s / CANDIDATE_BLOCKS), name)
        run.chol = self.factor(run.blocks(time_s), run.block_s)
        return run

    def forecast(
        self,
        profile: UseProfile,
        window_s: float,
        extra_runs: Sequence[_Run] = (),
        close: tuple[str, ...] = (),
        alternatives: Sequence[Alternative] = (),
    ) -> AxisForecast:
        """The predicted drift on ``profile`` at a moving-average window ``window_s`` [s], from these runs and
        ``extra_runs``; ``alternatives``: the fitted forms the choice could not tell from this one on this axis."""
        lo = min([self.lo_degc] + [float(r.model_degc.min()) for r in extra_runs])
        hi = max([self.hi_degc] + [float(r.model_degc.max()) for r in extra_runs])
        cov = _inverse(self.information(lo, hi, extra_runs))
        use, width, noise_weights = self._profile(profile, window_s)
        x = _about_mean(self.columns(use, lo, hi), width)
        weights = np.concatenate([_form_weights(x, cov), noise_weights])
        white = self.noise.white_var * self.block_s / (width * use.block_s)
        past = _held_error(self.ax, use.model_degc, lo, hi, self.extended)
        if self.edge is not None:  # as fast as the same fit lost track past a cut in its own data, if faster
            past = np.maximum(past, self.edge.error_dps(use.model_degc, lo, hi))
        held = _about_mean(use.blocks(past), width)
        hold = float(np.sqrt(np.mean(held**2)))
        low, high = _percentiles(weights, white)
        parting = [self.parting(use, width, alt) for alt in alternatives if self.axis in alt.axes]
        choice = max(parting, default=0.0)
        coefficients = float(np.sum(weights[: x.shape[1]]))
        noise = float(np.sum(weights[x.shape[1] :])) + white
        lag = self.ax.lag_time_constant_s
        return AxisForecast(
            self.axis,
            math.sqrt(coefficients + noise + hold**2),
            low,
            high + hold + choice,
            math.sqrt(coefficients),
            math.sqrt(noise),
            hold,
            _outside_share(use.model_degc, lo, hi),
            lag if lag > 0 else None,
            math.sqrt(max(cov[self.size, self.size], 0.0)) if lag > 0 else None,
            ("memory of the turn",) if self.ax.hysteresis is not None else (),
            close,
            choice,
            tuple(alt.form for alt in alternatives if self.axis in alt.axes),
        )

    def edge_rates(self) -> EdgeRates:
        """How fast the axis's curve family, fitted to the runs without the top (or the bottom)
        :data:`HELD_SHARE` of their model temperature and continued past the cut as the model is, parts from the
        same family fitted on all of them, per degC^power past the cut (:class:`EdgeRates`)."""
        held = HELD_SHARE * (self.hi_degc - self.lo_degc)
        power = 2 if self.extended else 1
        full = self._surrogate_fit(self.lo_degc, self.hi_degc, None)
        rates = []
        for cut, sign in ((self.lo_degc + held, -1.0), (self.hi_degc - held, 1.0)):
            lo, hi = (cut, self.hi_degc) if sign < 0 else (self.lo_degc, cut)
            part = self._surrogate_fit(lo, hi, (lo, hi))
            num = den = 0.0
            for run, x_cut, x_all in zip(self.runs, part, full):
                temp = run.blocks(run.model_degc)
                band = sign * (temp - cut) > 0
                if not np.any(band) or np.all(band):
                    continue
                d = (x_cut - x_all) - (x_cut - x_all)[~band].mean()  # the constants put elsewhere: no extrapolation
                num += float(np.sum(d[band] ** 2))
                den += float(np.sum((sign * (temp[band] - cut)) ** (2 * power)))
            rates.append(math.sqrt(num / den) if den > 0 else None)
        return EdgeRates(rates[0], rates[1], power)

    def _surrogate_fit(self, lo: float, hi: float, within: tuple[float, float] | None) -> list:
        """Per run, the surrogate's fitted bias without its constant (blocks) [deg/s], its curve over [lo, hi] degC
        (held or continued past it), fitted on the blocks within ``within`` (all: None) by least squares with a
        constant per run."""
        cols, ys, owners, keep = [], [], [], []
        for k, run in enumerate(self.runs):
            x = self.columns(run, lo, hi)
            temp = run.blocks(run.model_degc)
            cols.append(x)
            ys.append(run.raw)
            owners.append(np.full(x.shape[0], k))
            keep.append(np.ones(x.shape[0], bool) if within is None else (temp >= within[0]) & (temp <= within[1]))
        x, y, owner, keep = np.vstack(cols), np.concatenate(ys), np.concatenate(owners), np.concatenate(keep)
        design = np.hstack([np.eye(len(self.runs))[owner], x])
        coef = np.linalg.lstsq(design[keep], y[keep], rcond=None)[0]
        return [c @ coef[len(self.runs) :] for c in cols]

    def difference(self, run: _Run, alternative: Alternative) -> np.ndarray:
        """The block means of the error the chosen model predicts on ``run`` less the alternative's [deg/s] (the
        chosen model's prediction kept with the run: every alternative is set against it)."""
        if run.chosen is None:
            run.chosen = predicted(self.calibration, self.axis, run.time_s, run.reported_degc)
        return run.blocks(run.chosen - predicted(alternative.calibration, self.axis, run.time_s, run.reported_degc))

    def parting(self, use: _Run, width: int, alternative: Alternative) -> float:
        """How far ``alternative`` parts from the chosen model on a profile's series: the RMS about its mean of
        the moving average of their difference [deg/s] (kept with the series: each candidate run's forecast asks
        for the same)."""
        key = (id(alternative), width)
        if key not in use.partings:
            use.partings[key] = (
                alternative,
                float(np.sqrt(np.mean(_about_mean(self.difference(use, alternative), width) ** 2))),
            )
        return use.partings[key][1]

    def separation(self, run: _Run, alternative: Alternative) -> float:
        """The chi-square (one degree of freedom) a run would give the difference between the chosen model and
        ``alternative`` under the residual's drift model, its turn-on constant projected out: 9 or more, the run
        tells them apart at three standard deviations."""
        import scipy.linalg

        d = self.difference(run, alternative)
        dw = scipy.linalg.solve_triangular(run.chol, d, lower=True, check_finite=False)
        one = scipy.linalg.solve_triangular(run.chol, np.ones(d.size), lower=True, check_finite=False)
        dw = dw - one * (one @ dw) / float(one @ one)
        return float(dw @ dw)

    def _profile(self, profile: UseProfile, window_s: float) -> tuple[_Run, int, np.ndarray]:
        """The profile's series, the moving average's width in its blocks and the drift's eigenvalues on it (kept:
        each candidate run asks for the same)."""
        key = (id(profile), window_s)
        if key not in self._profiles or self._profiles[key][0] is not profile:
            duration_s = float(profile.time_s[-1] - profile.time_s[0])
            use_block_s = max(window_s / BLOCKS_PER_WINDOW, duration_s / MAX_POINTS)
            use = _series(self.ax, profile.time_s, profile.temperature_degc, use_block_s, profile.name)
            width = max(1, int(round(window_s / use.block_s)))
            self._profiles[key] = (profile, use, width, self._noise_weights(use, width))
        return self._profiles[key][1:]

    def _noise_weights(self, use: _Run, width: int) -> np.ndarray:
        """Eigenvalues of the drift's share of the quadratic form on the profile's blocks (the white part apart)."""
        t = use.blocks(use.time_s)
        drift = DriftNoise(0.0, self.noise.walk_var_per_s, self.noise.exponent)
        if drift.walk_var_per_s <= 0 or t.size < 2:
            return np.zeros(0)
        import scipy.linalg

        chol = scipy.linalg.cholesky(covariance(t, drift), lower=True, check_finite=False)
        b = _about_mean(chol, width) / math.sqrt(max(1, t.size - width + 1))
        return np.linalg.svd(b, compute_uv=False) ** 2


#: the step of the lag's central difference [s] (at most half the lag)
LAG_STEP_S = 1.0


def _series(ax: AxisCalibration, time_s: np.ndarray, temperature_degc: np.ndarray, block_s: float, name: str) -> _Run:
    """A run's model temperature and the block means of its lag and rate columns."""
    time_s = np.asarray(time_s, dtype=float)
    temperature_degc = np.asarray(temperature_degc, dtype=float)
    period = float(np.median(np.diff(time_s))) if time_s.size > 1 else 1.0
    factor = max(1, int(round(block_s / period)))
    tau = ax.lag_time_constant_s
    model = thermal_lag(time_s, temperature_degc, tau, period_s=period)[0] if tau > 0 else temperature_degc
    extra = []
    if tau > 0:
        curve = _continued(ax)
        step = min(LAG_STEP_S, tau / 2)
        ahead = thermal_lag(time_s, temperature_degc, tau + step, period_s=period)[0]
        behind = thermal_lag(time_s, temperature_degc, tau - step, period_s=period)[0]
        extra.append((curve.shape(ahead) - curve.shape(behind)) / (2 * step))  # [deg/s per s of lag]
    if ax.rate_term is not None:
        extra.append(rate_columns(time_s, model, (ax.rate_term.smoothing_s,), period)[:, 0])
    cols = np.column_stack(extra) if extra else np.zeros((time_s.size, 0))
    return _Run(time_s, temperature_degc, model, factor, coarsen(cols, factor), factor * period)


def calibrated_range(infos: dict[str, AxisInformation]) -> tuple[float, float]:
    """The model temperature's range [degC] the axes were calibrated over, all of them together.

    Parameters
    ----------
    infos : dict of str to AxisInformation
        Each axis's information (:func:`axis_information`).
    """
    return min(i.lo_degc for i in infos.values()), max(i.hi_degc for i in infos.values())


def calibration_cycle(infos: dict[str, AxisInformation], ramp_degc_per_min: float) -> UseProfile:
    """One heat-cool cycle over the calibrated range (:func:`calibrated_range`): the use profile when none is given.

    Parameters
    ----------
    infos : dict of str to AxisInformation
        Each axis's information (:func:`axis_information`).
    ramp_degc_per_min : float
        The cycle's ramp rate [degC/min] (the calibration runs').
    """
    lo, hi = calibrated_range(infos)
    name = f"one cycle {lo:.0f}..{hi:.0f} degC at {ramp_degc_per_min:.2g} degC/min (the calibration's)"
    return UseProfile.cycle(lo, hi, ramp_degc_per_min, name=name)


def _about_mean(x: np.ndarray, width: int) -> np.ndarray:
    """The moving average over ``width`` rows of each column of ``x``, about its mean."""
    x = np.asarray(x, dtype=float)
    if x.ndim == 1:
        x = x[:, None]
    if x.shape[1] == 0:
        return np.zeros((max(0, x.shape[0] - width + 1), 0))
    w = min(width, x.shape[0])
    return np.column_stack([smoothed_about_mean(x[:, k], w) for k in range(x.shape[1])])


def _inverse(information: np.ndarray) -> np.ndarray:
    """The covariance of the coefficients: the information inverted after scaling its columns alike."""
    scale = np.sqrt(np.maximum(np.diag(information), 1e-300))
    return np.linalg.pinv(information / np.outer(scale, scale), rcond=1e-12, hermitian=True) / np.outer(scale, scale)


def _form_weights(x: np.ndarray, cov: np.ndarray) -> np.ndarray:
    """Eigenvalues of ``mean_t (x_t . delta)^2`` with delta ~ N(0, cov): of cov^1/2 (x'x / n) cov^1/2."""
    values, vectors = np.linalg.eigh(cov)
    root = vectors * np.sqrt(np.maximum(values, 0.0))
    g = x.T @ x / max(1, x.shape[0])
    return np.clip(np.linalg.eigvalsh(root.T @ g @ root), 0.0, None)


def _held_error(ax: AxisCalibration, model_degc: np.ndarray, lo: float, hi: float, extended: bool) -> np.ndarray:
    """The estimated size of what the curve held (or continued along its tangent) past [lo, hi] degC leaves at
    ``model_degc``: the curve's slope at its own nearer edge times the distance past [lo, hi] (held), or half its
    curvature there times the distance squared (continued) [deg/s]."""
    curve = _continued(ax)
    own_lo, own_hi = curve.t_min_degc, curve.t_max_degc
    step = max((own_hi - own_lo) / 100, 1e-3)
    out = np.zeros(model_degc.size)
    for edge, own, sign, beyond in ((lo, own_lo, 1.0, model_degc < lo), (hi, own_hi, -1.0, model_degc > hi)):
        if not np.any(beyond):
            continue
        d = np.abs(model_degc[beyond] - edge)
        f0, f1, f2 = (float(curve.shape(np.array([own + sign * k * step]))[0]) for k in (0, 1, 2))
        if extended:
            out[beyond] = 0.5 * abs(f0 - 2 * f1 + f2) / step**2 * d**2
        else:
            out[beyond] = abs(f0 - f1) / step * d
    return out


def _outside_share(model_degc: np.ndarray, lo: float, hi: float) -> float:
    """The share of ``model_degc`` past [lo, hi] degC by more than the range tolerance the model's warning allows."""
    tol = max(RANGE_TOLERANCE_DEGC, RANGE_TOLERANCE_FRACTION * (hi - lo))
    return float(np.mean((model_degc < lo - tol) | (model_degc > hi + tol)))


def _percentiles(weights: np.ndarray, constant: float) -> tuple[float, float]:
    """The 2.5 and 97.5 % points of sqrt(sum_k w_k z_k^2 + constant), z standard normal (the leading weights
    drawn, the rest by their mean)."""
    w = np.sort(weights)[::-1]
    lead, rest = w[:LEADING], float(np.sum(w[LEADING:]))
    z = np.random.default_rng(SEED).standard_normal((DRAWS, lead.size))
    q = (z**2) @ lead + rest + constant
    lo, hi = np.percentile(q, [2.5, 97.5])
    return math.sqrt(max(lo, 0.0)), math.sqrt(max(hi, 0.0))


def _left(calibration: Calibration, recordings: Sequence[Recording]) -> list[Recording]:
    """What the model leaves on each run (its compensated output)."""
    with warnings.catch_warnings():  # what apply says of its own calibration runs is the fit's to say
        warnings.simplefilter("ignore")
        return [apply(calibration, rec) for rec in recordings]


def axis_information(
    calibration: Calibration, recordings: Sequence[Recording], window_s: float, extrapolation: bool = True
) -> dict[str, AxisInformation]:
    """:class:`AxisInformation` of every gyro axis with a temperature curve, the model applied to each run once.

    Parameters
    ----------
    calibration : Calibration
        The fitted model.
    recordings : sequence of Recording
        The static runs it was fitted on.
    window_s : float
        Moving-average window of the drift [s].
    extrapolation : bool
        Measure how fast the axis's curve family fitted to these runs loses track past a cut in their own range
        (:meth:`AxisInformation.edge_rates`), for the error past the calibrated range.

    Returns
    -------
    dict of str to AxisInformation
        By axis.
    """
    if not (math.isfinite(window_s) and window_s > 0):
        raise InputError(f"window_s: {window_s!r}; give a positive number of seconds")
    if not recordings:
        raise InputError("recordings: give the runs the model was fitted on")
    axes = [a for a in calibration.axes if calibration.axes[a].temperature is not None]
    if not axes:
        raise InputError(
            "the model has no temperature curve on any axis (constants only); there is nothing to forecast"
        )
    left = _left(calibration, recordings)
    infos = {a: AxisInformation.of(calibration, recordings, a, window_s, left) for a in axes}
    for info in infos.values() if extrapolation else ():
        info.edge = info.edge_rates()
    return infos


@single_threaded_blas
def forecast_drift(
    calibration: Calibration,
    recordings: Sequence[Recording],
    profile: UseProfile,
    window_s: float = DEFAULT_WINDOW_S,
    model_choice: bool = True,
) -> DriftForecast:
    """The predicted held-out drift of ``calibration`` on ``profile``, from the static runs it was fitted on.

    Parameters
    ----------
    calibration : Calibration
        The fitted model.
    recordings : sequence of Recording
        Its calibration runs (still, in a chamber): what the model leaves on them is the residual whose drift
        model the forecast rests on.
    profile : UseProfile
        The temperatures the gyro will see.
    window_s : float
        Moving-average window of the drift [s] (the accuracy page's 60 s).
    model_choice : bool
        Fit the nearest forms the model choice could not tell apart (:func:`choice_alternatives`) and add how far
        they part from the chosen curve to the interval (a fit of the runs each).

    Returns
    -------
    DriftForecast
        Each compensated gyro axis's expected drift [deg/s] with its 95 % interval and its shares.
    """
    infos = axis_information(calibration, recordings, window_s)
    warn_faster_use(profile, ramp_rate_degc_per_min(recordings))
    alternatives = choice_alternatives(calibration, recordings) if model_choice else ()
    return DriftForecast(
        profile.name,
        window_s,
        {
            a: i.forecast(profile, window_s, close=close_candidates(calibration, a), alternatives=alternatives)
            for a, i in infos.items()
        },
    )


__all__ = [
    "AxisForecast",
    "AxisInformation",
    "DEFAULT_WINDOW_S",
    "DriftForecast",
    "UseProfile",
    "axis_information",
    "calibrated_range",
    "calibration_cycle",
    "forecast_drift",
    "set_point_profile",
    "warn_faster_use",
]
