"""Is a noise model one a Kalman filter can trust? The normalized estimation error squared (NEES) of a small
attitude filter fed by gyro errors of known truth.

The filter, per axis: the attitude theta [deg] propagated with the measured rate less the estimated bias, the bias
a random walk (and first-order Gauss-Markov terms when the noise model has them), an absolute attitude update
every ``update_period_s`` with noise ``update_sigma_deg``. The part is at rest, so the true attitude is 0 and the
measured rate is the gyro's error itself. Between updates the state and its covariance are propagated exactly
(the transition and the discrete process noise of the continuous model over the update period, by Van Loan's
matrix exponential), so the filter's covariance is the same for every run and only its estimates differ.

At each update the prior attitude error squared over its variance is one NEES sample of one degree of freedom;
a run's time-averaged NEES over K updates (after a burn-in) has, when the filter is consistent, mean 1 (Bar-Shalom,
Li and Kirubarajan, *Estimation with Applications to Tracking and Navigation*, 2001, section 5.4). Its 95 % band
is [chi2(0.025, nu) / nu, chi2(0.975, nu) / nu]: for independent samples nu = K, but successive prior errors share
the bias estimate's error, so their squares are correlated and the mean spreads wider. Under consistency the
filter itself says how: the prior error of update k + j is A_{k+j-1} ... A_k times that of update k plus noise
independent of it, A_i = Phi_{i+1} (I - G_i H) (the transition after the update with gain G_i), so the normalized
errors z_k have correlations rho_kl = (A_{l-1} ... A_k P_k)[0, 0] / sqrt(P_k[0, 0] P_l[0, 0]), and for
Gaussian errors cov(z_k^2, z_l^2) = 2 rho_kl^2. The band takes the chi-square of the same mean and variance
(Satterthwaite, *Biometrics Bulletin* 2, 1946): nu = K^2 / sum_kl rho_kl^2, equal to K when the errors are
independent. Below the band the filter is over-cautious (its noise too large), above it over-confident.
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
        Its 95 % chi-square band (on ``effective_epochs`` degrees of freedom).
    epochs : int
        The updates averaged per run.
    effective_epochs : float
        The independent samples their correlation is worth (nu in the module's text; ``epochs`` when independent).
    """

    nees: np.ndarray
    band: tuple[float, float]
    epochs: int
    effective_epochs: float

    @property
    def inside(self) -> float:
        """The share of runs whose time-averaged NEES is inside the band."""
        return float(np.mean((self.nees >= self.band[0]) & (self.nees <= self.band[1])))


def nees_band(epochs: float, dof: int = 1, confidence: float = 0.95) -> tuple[float, float]:
    """The two-sided band of the mean of ``epochs`` independent NEES samples of ``dof`` degrees of freedom each.

    Parameters
    ----------
    epochs : float
        The samples averaged (or the independent samples correlated ones are worth).
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
        temperature instead of ``noise``, with ``temperature_degc`` (its Gauss-Markov terms, if any, of the same
        correlation times at every temperature).
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
    if schedule is not None and temperature_degc is None:
        raise InputError("schedule: needs temperature_degc, the temperature along the runs")
    # the measured angle of each update period: the rate integrated over it [deg]
    integrated = errors[:, : epochs * per].reshape(errors.shape[0], epochs, per).sum(axis=2) / rate_hz
    told = _told(noise, schedule, temperature_degc, epochs, per)
    models = (
        [_model(t, per / rate_hz) for t in told] if schedule is not None else [_model(noise, per / rate_hz)] * epochs
    )
    p = _initial_covariance(models[0][0].shape[0], errors[:, : max(per, 1)], told[0], update_sigma_deg)
    samples, effective = _filter(integrated, models, p, first, update_sigma_deg)
    return NeesResult(np.mean(samples, axis=0), nees_band(effective), len(samples), effective)


def _told(noise: NoiseBound, schedule, temperature_degc, epochs: int, per: int) -> list[NoiseBound]:
    """The noise model the filter is told for each update period of ``per`` samples: ``noise``, or the
    schedule's at the period's mean temperature [degC] (the same Gauss-Markov correlation times at every one)."""
    if schedule is None:
        return [noise] * epochs
    periods = np.asarray(temperature_degc, dtype=float)[: epochs * per].reshape(epochs, per)
    told = [schedule(float(np.mean(t))) for t in periods]
    times = {tuple(tc for _, tc in b.markov) for b in told}
    if len(times) > 1:
        raise InputError(
            "schedule: the Gauss-Markov terms' correlation times change with temperature; a filter's "
            "states cannot: give each temperature the same grid (scheduled_bound does)"
        )
    return told


def _initial_covariance(size: int, first_errors_dps: np.ndarray, noise: NoiseBound, update_sigma_deg: float):
    """The filter's initial covariance: the attitude's [deg^2] from an update, the bias's [(deg/s)^2] from the
    spread of the runs' first update period, each Gauss-Markov state's [(deg/s)^2] its stationary variance."""
    p = np.zeros((size, size))
    p[0, 0] = update_sigma_deg**2
    p[1, 1] = (first_errors_dps.mean(axis=1).std() + noise.deviation(1.0)) ** 2  # the turn-on bias
    for j, (sigma, _) in enumerate(noise.markov):
        p[2 + j, 2 + j] = sigma**2
    return p


def _filter(
    integrated: np.ndarray, models: list, p: np.ndarray, first: int, update_sigma_deg: float
) -> tuple[list, float]:
    """Each update's prior NEES of the attitude (from ``first`` on), every run at once: propagate with each
    period's (transition, process noise), then update with an absolute attitude of the true value 0. Also the
    independent samples they are worth under consistency (:func:`_effective_samples`)."""
    x = np.zeros((integrated.shape[0], p.shape[0]))
    rng = np.random.default_rng(0)
    samples, priors, after = [], [], []
    for k, (phi, q) in enumerate(models):
        x = x @ phi.T
        x[:, 0] += integrated[:, k]
        p = phi @ p @ phi.T + q
        if k >= first:
            samples.append(x[:, 0] ** 2 / p[0, 0])
            priors.append(p[:, 0].copy())
        z = rng.standard_normal(integrated.shape[0]) * update_sigma_deg
        gain = p[:, 0] / (p[0, 0] + update_sigma_deg**2)
        x = x + np.outer(z - x[:, 0], gain)
        p = p - np.outer(gain, p[0, :])
        if k >= first and k + 1 < len(models):
            update = np.eye(p.shape[0])
            update[:, 0] -= gain
            after.append(models[k + 1][0] @ update)  # A_k: the prior error of update k on to that of k + 1
    return samples, _effective_samples(np.array(priors), np.array(after))


def _effective_samples(priors: np.ndarray, after: np.ndarray) -> float:
    """nu = K^2 / sum_kl rho_kl^2 (the module's text) of K prior errors whose covariances with the attitude's,
    P_k[:, 0], are ``priors`` (K, size), ``after`` (K - 1, size, size) carrying each on to the next update.

    Lag by lag, every k at once: c_k <- A_{k+j-1} c_k is the covariance of update k + j's prior error with the
    attitude error of update k; the lags stop when every correlation is below 1e-6."""
    variance = priors[:, 0]
    count = len(variance)
    total = float(count)  # rho_kk = 1
    c = priors.copy()
    for lag in range(1, count):
        c = np.einsum("kij,kj->ki", after[lag - 1 :], c[: count - lag])
        rho = c[:, 0] / np.sqrt(variance[: count - lag] * variance[lag:])
        total += 2.0 * float(np.sum(rho**2))
        if np.max(np.abs(rho)) < 1e-6:
            break
    return count**2 / total


__all__ = ["NeesResult", "attitude_nees", "nees_band"]
