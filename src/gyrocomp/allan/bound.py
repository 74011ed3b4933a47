"""Noise models that bound a measured Allan deviation from above: what a Kalman filter can be given.

The IEEE Std 952 fit (:mod:`gyrocomp.allan.terms`) describes a curve; it is a least-squares fit, so it lies
below the measured curve somewhere, flicker (bias instability) has no state-space form, and an estimator tuned
with it is over-confident there. This module finds the tightest sum of processes a filter can carry whose
Allan variance is at or above the measured curve's upper confidence bound at every averaging time:

    sigma^2(tau) = N^2 / tau + K^2 tau / 3 + sum_j q_j^2 g(tau, T_j)

with white noise N [u/sqrt(Hz)], rate random walk K [u/sqrt(s)], and first-order Gauss-Markov processes of
correlation time T_j [s] driven by white noise of density q_j, whose Allan variance is (IEEE Std 952-1997,
Annex C; El-Sheimy, Hou and Niu 2008, eq. 17)

    g(tau, T) = T^2 / tau [1 - T / (2 tau) (3 - 4 exp(-tau / T) + exp(-2 tau / T))]

(q^2 tau / 3 for tau << T, a random walk; q^2 T^2 / tau for tau >> T, white). The T_j lie on a fixed grid, so the
variance is linear in the non-negative coefficients (N^2, K^2, q_j^2), and "at or above the bound at every tau,
as low as possible on average" is a linear programme: minimize sum_i model_i / bound_i subject to
model_i >= bound_i (scipy's HiGHS). The same programme over several curves at once (one per temperature) bounds
them all. ``markov=False`` keeps white noise and random walk only: what most estimators carry (Kalibr, VINS, the
autopilots' EKFs).

u is the data's unit (deg/s for a gyro, g for an accelerometer).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .estimators import AllanResult
from .intervals import confidence_interval

#: Gauss-Markov correlation times per decade of averaging time in the bound's grid
MARKOV_PER_DECADE = 2
#: the bound's constraints are met to this relative tolerance of the linear programme
BOUND_TOLERANCE = 1e-6
#: the one-sided confidence of the upper bound the model stays above, by default: the upper end of the two-sided
#: 95 % interval
BOUND_CONFIDENCE = 0.975


def markov_allan_variance(tau_s, time_constant_s: float) -> np.ndarray:
    """Allan variance of a first-order Gauss-Markov process driven by unit white noise [u^2 per (u^2/Hz)].

    Parameters
    ----------
    tau_s : array
        Averaging times [s].
    time_constant_s : float
        Its correlation time T [s].

    Returns
    -------
    array
        g(tau, T) = T^2 / tau [1 - T / (2 tau) (3 - 4 exp(-tau/T) + exp(-2 tau/T))] [s]; times q^2 [u^2/Hz] it
        is the process's Allan variance [u^2].
    """
    tau = np.asarray(tau_s, dtype=float)
    x = tau / time_constant_s
    small = x < 1e-3  # the series tau / 3 (1 - x/4 + ...) where the closed form cancels
    closed = (
        time_constant_s**2 / tau * (1.0 - (3.0 - 4.0 * np.exp(-x) + np.exp(-2.0 * x)) / (2.0 * np.where(small, 1.0, x)))
    )
    return np.where(small, tau / 3.0 * (1.0 - x / 4.0), closed)


@dataclass(frozen=True)
class NoiseBound:
    """A noise model a Kalman filter can carry, its Allan deviation at or above a measured one's upper bound.

    Attributes
    ----------
    white_noise_density : float
        N [u/sqrt(Hz)]: the continuous-time density of the white rate noise (angle random walk for a gyro).
    random_walk : float
        K [u/sqrt(s)]: the density of the white noise driving the bias random walk (rate random walk).
    markov : tuple of (float, float)
        (sigma [u], time constant [s]) of each first-order Gauss-Markov bias term: its stationary standard
        deviation and correlation time (driving density sqrt(2 sigma^2 / T)); empty for the two-term form.
    taus_s : tuple of float
        The averaging times it bounds [s].
    ratio_median, ratio_max : float
        Its Allan deviation over the measured one there: the median and the largest.
    """

    white_noise_density: float
    random_walk: float
    markov: tuple[tuple[float, float], ...]
    taus_s: tuple[float, ...]
    ratio_median: float
    ratio_max: float

    def deviation(self, tau_s) -> np.ndarray:
        """The model's Allan deviation [u] at ``tau_s`` [s]."""
        tau = np.asarray(tau_s, dtype=float)
        variance = self.white_noise_density**2 / tau + self.random_walk**2 * tau / 3.0
        for sigma, time_constant in self.markov:
            variance = variance + 2.0 * sigma**2 / time_constant * markov_allan_variance(tau, time_constant)
        return np.sqrt(variance)

    def to_dict(self) -> dict:
        """The model as JSON: each term with its unit's name (``u`` is the data's)."""
        return {
            "white_noise_density_u_per_sqrt_hz": self.white_noise_density,
            "random_walk_u_per_sqrt_s": self.random_walk,
            "gauss_markov": [{"sigma_u": s, "time_constant_s": t} for s, t in self.markov],
            "bounded_taus_s": [self.taus_s[0], self.taus_s[-1]] if self.taus_s else [],
            "ratio_to_measured_median": self.ratio_median,
            "ratio_to_measured_max": self.ratio_max,
        }


def markov_grid(shortest_tau_s: float, longest_tau_s: float) -> np.ndarray:
    """The Gauss-Markov correlation times [s] a bound chooses from over averaging times from ``shortest_tau_s``
    to ``longest_tau_s`` [s]: ``MARKOV_PER_DECADE`` per decade, log-spaced, both ends included (none when the
    span is a single tau)."""
    if not longest_tau_s > shortest_tau_s:
        return np.empty(0)
    count = int(math.ceil(MARKOV_PER_DECADE * math.log10(longest_tau_s / shortest_tau_s))) + 1
    return np.geomspace(shortest_tau_s, longest_tau_s, count)


def _targets(
    curves: list[AllanResult], max_tau_s: float | None, confidence: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(tau, measured deviation, one-sided upper confidence bound) of every point bounded, all curves together:
    the chi-squared bound of each point's equivalent degrees of freedom (NIST SP 1065 eq. 45), or, where no
    noise type gave them, the deviation times 1 + 2 / sqrt(n)."""
    taus, devs, highs = [], [], []
    for curve in curves:
        if curve.kind not in ("oadev", "adev"):
            raise InputError(f"kind: a noise bound needs an Allan deviation (oadev or adev), not {curve.kind}")
        keep = np.isfinite(curve.deviation) & (curve.deviation > 0) & (curve.n >= 1)
        if max_tau_s is not None:
            keep &= curve.tau <= max_tau_s * (1 + 1e-9)
        _, high = confidence_interval(curve.deviation, curve.edf, 2.0 * confidence - 1.0)
        fallback = curve.deviation * (1.0 + 2.0 / np.sqrt(np.maximum(curve.n, 1)))
        high = np.where(np.isfinite(high) & (high >= curve.deviation), high, fallback)
        taus.append(curve.tau[keep])
        devs.append(curve.deviation[keep])
        highs.append(high[keep])
    tau, dev, high = np.concatenate(taus), np.concatenate(devs), np.concatenate(highs)
    if tau.size < 2:
        raise InputError("data: too short for a noise bound; need at least two averaging times")
    return tau, dev, high


def _columns(tau: np.ndarray, times: np.ndarray) -> np.ndarray:
    return np.column_stack([1.0 / tau, tau / 3.0, *(markov_allan_variance(tau, t) for t in times)])


def _least_strengths(basis: np.ndarray) -> np.ndarray:
    """The non-negative strengths of the model's terms that keep every row of ``basis`` @ x (the model's variance
    over the bound's at each tau) at or above one, with the least sum of those ratios (a linear program)."""
    scale = basis.max(axis=0)
    scale[scale <= 0] = 1.0
    a = basis / scale
    from scipy.optimize import linprog  # scipy.optimize is slow to import: only the bound needs it here

    solution = linprog(
        a.sum(axis=0),
        A_ub=-a,
        b_ub=-np.ones(a.shape[0]) * (1 + BOUND_TOLERANCE),
        bounds=[(0, None)] * a.shape[1],
        method="highs",
    )
    if not solution.success:
        raise InputError(f"data: no noise bound found ({solution.message})")
    return solution.x / scale


def bound_noise(
    curves: AllanResult | list[AllanResult],
    *,
    markov: bool = True,
    max_tau_s: float | None = None,
    confidence: float = BOUND_CONFIDENCE,
    time_constants_s=None,
) -> NoiseBound:
    """The tightest noise model a filter can carry whose Allan deviation is at or above the upper confidence
    bound of every curve at every averaging time (see the module).

    Parameters
    ----------
    curves : AllanResult or list of AllanResult
        Overlapping (or plain) Allan deviations of rate data [u], with their confidence intervals; several (one
        per temperature, say) are bounded together.
    markov : bool
        Also use first-order Gauss-Markov terms (on a grid of correlation times, ``MARKOV_PER_DECADE`` per
        decade over the bounded taus); False: white noise and random walk only.
    max_tau_s : float, optional
        Bound the curves up to this averaging time [s] (default: every point with an estimate), e.g. a tenth of
        the record, beyond which a curve has too few averages to trust.
    confidence : float
        One-sided confidence of the upper bound of each measured point that the model stays above (default
        0.975, the upper end of the two-sided 95 % interval: a point's true deviation lies below it 39 times in
        40).
    time_constants_s : array, optional
        The Gauss-Markov terms' correlation times [s] to choose from (default: the grid over the bounded taus), e.g.
        one grid for the logs of several temperatures so that their terms match (:func:`markov_grid`).

    Returns
    -------
    NoiseBound
    """
    curves = [curves] if isinstance(curves, AllanResult) else list(curves)
    if not 0.5 < confidence < 1.0:
        raise InputError(f"confidence: a one-sided confidence between 0.5 and 1, got {confidence!r}")
    tau, dev, high = _targets(curves, max_tau_s, confidence)
    if not markov:
        times = np.empty(0)
    elif time_constants_s is None:
        times = markov_grid(float(tau.min()), float(tau.max()))
    else:
        times = np.asarray(time_constants_s, dtype=float)
        if times.ndim != 1 or not np.all(np.isfinite(times) & (times > 0)):
            raise InputError("time_constants_s: positive correlation times [s], one list")
    x = _least_strengths(_columns(tau, times) / (high**2)[:, None])
    model = np.sqrt(_columns(tau, times) @ x)
    ratio = model / dev
    terms = tuple((math.sqrt(q2 * t / 2.0), float(t)) for q2, t in zip(x[2:], times) if q2 > 0)
    return NoiseBound(
        math.sqrt(x[0]),
        math.sqrt(x[1]),
        terms,
        tuple(float(t) for t in np.unique(tau)),
        float(np.median(ratio)),
        float(ratio.max()),
    )


__all__ = [
    "BOUND_CONFIDENCE",
    "BOUND_TOLERANCE",
    "MARKOV_PER_DECADE",
    "NoiseBound",
    "bound_noise",
    "markov_allan_variance",
    "markov_grid",
]
