"""Least squares under slow drift: a white plus random-walk model of the residual, estimated from its variogram,
and the Wald statistic of a group of terms under that model (generalized least squares).

Block residuals of a gyro's bias are not independent: a slow drift (rate random walk, and flicker, which this
model over-states as a walk) makes neighbouring blocks alike and far ones apart. A term that only separates two
stretches of time (one heating leg from one cooling leg) then fits the drift by chance, and ordinary least squares
calls it significant. Under the model

    r(t_i) = w_i + W(t_i),   var(w_i) = a,   W a random walk from the run's start:  cov(W(t_i), W(t_j)) = K^2 min(t_i, t_j)

the variogram of the residual is ``E[(r(t + dt) - r(t))^2] = 2 a + K^2 dt`` (:func:`fit_drift_noise`), and
generalized least squares with that covariance weighs a term by how much more than a drift of that size it
explains (:func:`wald_statistic`).

References: N. El-Sheimy, H. Hou, X. Niu, "Analysis and modeling of inertial sensors using Allan variance", IEEE
TIM 57(1), 2008 (rate random walk); T. W. Anderson, *The Statistical Analysis of Time Series*, 1971 (GLS).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: the most points a test should be computed on (each recording's covariance is dense): average longer
#: series over consecutive blocks first (:func:`coarsen`)
MAX_POINTS = 1200
#: variogram lags: this many, log-spaced from one point to 1/VARIOGRAM_REACH of the recording (the residual of a
#: fitted curve loses the walk's long lags: over a quarter of the run, K was under-estimated twice over)
VARIOGRAM_LAGS = 10
VARIOGRAM_REACH = 16


@dataclass(frozen=True)
class DriftNoise:
    """White plus random-walk model of a residual: ``white_var`` per point [unit^2], ``walk_var_per_s`` K^2
    [unit^2/s]."""

    white_var: float
    walk_var_per_s: float


def coarsen(values: np.ndarray, factor: int) -> np.ndarray:
    """Means over consecutive groups of ``factor`` rows of ``values`` (n, ...) (the last group may be shorter)."""
    if factor <= 1:
        return values
    n = values.shape[0]
    edges = np.arange(0, n, factor)
    sums = np.add.reduceat(values, edges, axis=0)
    counts = np.diff(np.append(edges, n)).reshape((-1,) + (1,) * (values.ndim - 1))
    return sums / counts


def fit_drift_noise(residuals: list[np.ndarray], times_s: list[np.ndarray]) -> DriftNoise:
    """The white variance ``a`` [unit^2] and random-walk rate ``K^2`` [unit^2/s] of residuals (one array per
    recording, at times ``times_s`` [s]), from a non-negative least-squares fit of

        V(L) = mean_i (r_{i+L} - r_i)^2 = 2 a + K^2 dt(L)

    over log-spaced lags L up to 1/:data:`VARIOGRAM_REACH` of the recording (dt(L) the mean time they span), each lag weighted by 1 / V(L)^2 (a relative fit)."""
    rows, values = [], []
    for r, t in zip(residuals, times_s):
        n = r.size
        if n < 4:
            continue
        for lag in np.unique(np.round(np.geomspace(1, max(1, n // VARIOGRAM_REACH), VARIOGRAM_LAGS)).astype(int)):
            d = r[lag:] - r[:-lag]
            rows.append(float(np.mean(t[lag:] - t[:-lag])))
            values.append(float(np.mean(d ** 2)))
    if not rows:
        return DriftNoise(0.0, 0.0)
    dt, v = np.asarray(rows), np.asarray(values)
    w = 1.0 / np.maximum(v, 1e-300)
    x = np.column_stack([np.full(dt.size, 2.0), dt]) * w[:, None]
    (a, k2), *_ = np.linalg.lstsq(x, v * w, rcond=None)
    if k2 < 0:
        a, k2 = float(np.sum(w * w * v) / np.sum(w * w * 2.0)), 0.0
    elif a < 0:
        a, k2 = 0.0, float(np.sum(w * w * v * dt) / np.sum(w * w * dt * dt))
    return DriftNoise(float(max(a, 0.0)), float(max(k2, 0.0)))


def whitened(x: np.ndarray, y: np.ndarray, t_s: np.ndarray, noise: DriftNoise) -> tuple[np.ndarray, np.ndarray]:
    """``x`` (n, p) and ``y`` (n,) of one recording multiplied by the inverse Cholesky factor of its
    covariance ``a I + K^2 min(t_i - t_0, t_j - t_0)``: ordinary least squares on the result is GLS.

    ``a`` is at least ``K^2 dt / 3`` (dt the median spacing of the points [s]): the mean of a walk over a point's
    span scatters that much about the walk (without it, a pure walk pins the first point exactly)."""
    tau = t_s - t_s[0]
    cov = noise.walk_var_per_s * np.minimum.outer(tau, tau)
    spacing = float(np.median(np.diff(t_s))) if t_s.size > 1 else 0.0
    floor = max(noise.walk_var_per_s * spacing / 3.0, 1e-12 * max(float(np.max(np.diag(cov))), 1e-300))
    cov[np.diag_indices_from(cov)] += max(noise.white_var, floor)
    chol = np.linalg.cholesky(cov)
    from_left = np.linalg.solve(chol, np.column_stack([x, y]))
    return from_left[:, :-1], from_left[:, -1]


def wald_statistic(x: list[np.ndarray], y: list[np.ndarray], t_s: list[np.ndarray], noise: DriftNoise,
                   tested: np.ndarray) -> float:
    """The Wald statistic ``b' cov(b)^-1 b`` of the coefficients ``b`` of columns ``tested`` (indices) in the
    generalized least-squares fit of ``y`` on ``x`` (one pair per recording, at times ``t_s`` [s]) under
    ``noise``. Under the hypothesis that those terms are zero it follows a chi-square law with
    ``len(tested)`` degrees of freedom. (Average long series first, :func:`coarsen`: the covariance of each
    recording is dense.)"""
    pairs = [whitened(xk, yk, tk, noise) for xk, yk, tk in zip(x, y, t_s)]
    xw, yw = np.vstack([p[0] for p in pairs]), np.concatenate([p[1] for p in pairs])
    scale = np.sqrt(np.maximum(np.sum(xw ** 2, axis=0), 1e-300))
    coef, *_ = np.linalg.lstsq(xw / scale, yw, rcond=1e-10)
    cov = np.linalg.pinv((xw / scale).T @ (xw / scale), rcond=1e-10)
    b = coef[tested]
    return float(b @ np.linalg.pinv(cov[np.ix_(tested, tested)], rcond=1e-10) @ b)


def chi2_threshold(dof: int, sigmas: float = 3.0) -> float:
    """The chi-square value a statistic of ``dof`` (1 or 2) degrees of freedom exceeds with the two-sided
    probability of ``sigmas`` standard deviations of a normal law (3: 0.27 %)."""
    p = math.erfc(sigmas / math.sqrt(2.0))
    if dof == 1:
        return sigmas ** 2
    if dof == 2:
        return -2.0 * math.log(p)
    raise ValueError(f"dof: 1 or 2, got {dof}")


__all__ = ["DriftNoise", "MAX_POINTS", "VARIOGRAM_REACH", "chi2_threshold", "coarsen", "fit_drift_noise", "wald_statistic", "whitened"]
