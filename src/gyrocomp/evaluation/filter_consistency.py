"""Is a noise model one a Kalman filter can trust? The normalized estimation error squared (NEES) of a small
attitude filter fed by gyro errors of known truth.

The filter, per axis: the attitude theta [deg] propagated with the measured rate less the estimated bias, the bias
a random walk (and first-order Gauss-Markov terms when the noise model has them), an absolute attitude update
every ``update_period_s`` with noise ``update_sigma_deg``. The part is at rest, so the true attitude is 0 and the
measured rate is the gyro's error itself. Between updates the state and its covariance are propagated exactly
(the transition and the discrete process noise of the continuous model over the update period, by Van Loan's
matrix exponential), so the filter's covariance is the same for every run and only its estimates differ.

At each update the prior attitude error squared over its variance is one NEES sample of one degree of freedom;
a run's time-averaged NEES over K updates (after a burn-in) has, when the filter is consistent, mean 1 and lies in
[chi2(0.025, K) / K, chi2(0.975, K) / K] 95 times in 100 (Bar-Shalom, Li and Kirubarajan, *Estimation with
Applications to Tracking and Navigation*, 2001, section 5.4). Below the band the filter is over-cautious (its
noise too large), above it over-confident.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..allan.bound import NoiseBound
from ..errors import InputError


@dataclass(frozen=True)
class NeesResult:
    """The time-averaged NEES of each run and its 95 % band.

    Attributes
    ----------
    nees : array (runs,)
        Each run's time-averaged NEES over the updates after the burn-in.
    band : (float, float)
        Its 95 % chi-square band.
    epochs : int
        The updates averaged per run.
    """

    nees: np.ndarray
    band: tuple[float, float]
    epochs: int

    @property
    def inside(self) -> float:
        """The share of runs whose time-averaged NEES is inside the band."""
        return float(np.mean((self.nees >= self.band[0]) & (self.nees <= self.band[1])))


def nees_band(epochs: int, dof: int = 1, confidence: float = 0.95) -> tuple[float, float]:
    """The two-sided band of the mean of ``epochs`` NEES samples of ``dof`` degrees of freedom each.

    Parameters
    ----------
    epochs : int
        The samples averaged.
    dof : int
        The degrees of freedom of each.
    confidence : float
        Two-sided confidence of the band.
    """
    from scipy.stats import chi2  # scipy.stats is slow to import: only the band needs it

    k = epochs * dof
    tail = (1.0 - confidence) / 2.0
    return float(chi2.ppf(tail, k) / epochs), float(chi2.ppf(1.0 - tail, k) / epochs)


def _model(noise: NoiseBound, period_s: float) -> tuple[np.ndarray, np.ndarray]:
    """(transition, discrete process noise) of the filter's state [theta, bias, Gauss-Markov terms...] over one
    update period, exact for the continuous model (Van Loan)."""
    from scipy.linalg import expm  # scipy.linalg is slow to import: only the filter needs it

    m = len(noise.markov)
    size = 2 + m
    f = np.zeros((size, size))
    f[0, 1:] = -1.0  # theta' = measured rate - bias - sum of the Gauss-Markov terms
    q = np.zeros(size)
    q[0] = noise.white_noise_density**2
    q[1] = noise.random_walk**2
    for j, (sigma, time_constant) in enumerate(noise.markov):
        f[2 + j, 2 + j] = -1.0 / time_constant
        q[2 + j] = 2.0 * sigma**2 / time_constant
    block = np.zeros((2 * size, 2 * size))
    block[:size, :size] = -f
    block[:size, size:] = np.diag(q)
    block[size:, size:] = f.T
    e = expm(block * period_s)
    phi = e[size:, size:].T
    return phi, phi @ e[:size, size:]


def attitude_nees(
    errors_dps: np.ndarray,
    rate_hz: float,
    noise: NoiseBound,
    *,
    update_period_s: float = 2.0,
    update_sigma_deg: float = 0.01,
    burn_in_fraction: float = 0.2,
    schedule: Callable[[float], NoiseBound] | None = None,
    temperature_degc: np.ndarray | None = None,
) -> NeesResult:
    """The time-averaged NEES of the attitude filter (see the module) told ``noise``, on gyro errors of known
    truth.

    Parameters
    ----------
    errors_dps : array (runs, n)
        Each run's gyro error at rest [deg/s]: what the filter measures.
    rate_hz : float
        Their sample rate [Hz].
    noise : NoiseBound
        The noise model the filter is told (white noise [deg/s/sqrt(Hz)], random walk [deg/s/sqrt(s)], Gauss-Markov
        terms [deg/s, s]).
    update_period_s : float
        Time between absolute attitude updates [s].
    update_sigma_deg : float
        Their noise [deg].
    burn_in_fraction : float
        The share of the updates left out at the start (the bias estimate converging).
    schedule : callable, optional
        ``schedule(temperature_degc) -> NoiseBound``: the noise the filter is told at each update period's mean
        temperature instead of ``noise`` (white noise and random walk only), with ``temperature_degc``.
    temperature_degc : array (n,), optional
        The temperature along the runs [degC], for ``schedule``.

    Returns
    -------
    NeesResult
    """
    errors = np.atleast_2d(np.asarray(errors_dps, dtype=float))
    per = int(round(update_period_s * rate_hz))
    epochs = errors.shape[1] // per
    first = int(math.ceil(burn_in_fraction * epochs))
    if per < 1 or epochs - first < 2:
        raise InputError(
            f"update_period_s: {update_period_s:g} s leaves fewer than two updates after the burn-in in "
            f"{errors.shape[1] / rate_hz:g} s"
        )
    if schedule is not None and (temperature_degc is None or noise.markov):
        raise InputError("schedule: needs temperature_degc, and a noise model of white noise and random walk only")
    # the measured angle of each update period: the rate integrated over it [deg]
    integrated = errors[:, : epochs * per].reshape(errors.shape[0], epochs, per).sum(axis=2) / rate_hz
    models = _models(noise, schedule, temperature_degc, epochs, per, rate_hz)
    p = _initial_covariance(models[0][0].shape[0], errors[:, : max(per, 1)], noise, update_sigma_deg)
    samples = _filter(integrated, models, p, first, update_sigma_deg)
    return NeesResult(np.mean(samples, axis=0), nees_band(len(samples)), len(samples))


def _models(noise: NoiseBound, schedule, temperature_degc, epochs: int, per: int, rate_hz: float) -> list:
    """The filter's model of each update period of ``per`` samples: ``noise``'s, or the schedule's at the
    period's mean temperature [degC]."""
    if schedule is None:
        return [_model(noise, per / rate_hz)] * epochs
    periods = np.asarray(temperature_degc, dtype=float)[: epochs * per].reshape(epochs, per)
    return [_model(schedule(float(np.mean(t))), per / rate_hz) for t in periods]


def _initial_covariance(size: int, first_errors_dps: np.ndarray, noise: NoiseBound, update_sigma_deg: float):
    """The filter's initial covariance: the attitude's [deg^2] from an update, the bias's [(deg/s)^2] from the
    spread of the runs' first update period, each Gauss-Markov state's [(deg/s)^2] its stationary variance."""
    p = np.zeros((size, size))
    p[0, 0] = update_sigma_deg**2
    p[1, 1] = (first_errors_dps.mean(axis=1).std() + noise.deviation(1.0)) ** 2  # the turn-on bias
    for j, (sigma, _) in enumerate(noise.markov):
        p[2 + j, 2 + j] = sigma**2
    return p


def _filter(integrated: np.ndarray, models: list, p: np.ndarray, first: int, update_sigma_deg: float) -> list:
    """Each update's prior NEES of the attitude (from ``first`` on), every run at once: propagate with each
    period's (transition, process noise), then update with an absolute attitude of the true value 0."""
    x = np.zeros((integrated.shape[0], p.shape[0]))
    rng = np.random.default_rng(0)
    samples = []
    for k, (phi, q) in enumerate(models):
        x = x @ phi.T
        x[:, 0] += integrated[:, k]
        p = phi @ p @ phi.T + q
        if k >= first:
            samples.append(x[:, 0] ** 2 / p[0, 0])
        z = rng.standard_normal(integrated.shape[0]) * update_sigma_deg
        gain = p[:, 0] / (p[0, 0] + update_sigma_deg**2)
        x = x + np.outer(z - x[:, 0], gain)
        p = p - np.outer(gain, p[0, :])
    return samples


__all__ = ["NeesResult", "attitude_nees", "nees_band"]
