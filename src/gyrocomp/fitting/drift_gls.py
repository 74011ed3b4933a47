"""Least squares under slow drift: a white plus power-law drift model of the residual, estimated from its
variogram, and the Wald statistic of a group of terms under that model (generalized least squares).

Block residuals of a gyro's bias are not independent: a slow drift (rate random walk, flicker, and the drift of
real parts that follows the temperature only partly and differs from run to run) makes neighbouring blocks alike
and far ones apart. A term that only separates two stretches of time (one heating leg from one cooling leg) then
fits the drift by chance, and ordinary least squares calls it significant. Under the model

    r(t_i) = w_i + D(t_i),   var(w_i) = a,   D a fractional Brownian motion from the run's start:
    cov(D(t_i), D(t_j)) = (c / 2) (t_i^alpha + t_j^alpha - |t_i - t_j|^alpha),   0 < alpha < 2

the variogram of the residual is ``E[(r(t + dt) - r(t))^2] = 2 a + c dt^alpha`` (:func:`fit_drift_noise`), and
generalized least squares with that covariance weighs a term by how much more than a drift of that size it
explains (:func:`wald_statistic`). ``alpha = 1`` is the random walk (``c = K^2``); flicker (bias instability)
grows more slowly than a walk with the lag (a small alpha over the lags seen), and the smooth drift of real parts
faster (alpha up to 2): a walk fitted to either misjudges the variance between two legs far apart, which is what
a test of heating against cooling terms rests on (measured on a real one-cycle chamber log, tofupilot: the walk
fitted at short lags put the variogram at 500-1000 s at half what the residual showed).

References: N. El-Sheimy, H. Hou, X. Niu, "Analysis and modeling of inertial sensors using Allan variance", IEEE
TIM 57(1), 2008 (rate random walk); B. B. Mandelbrot, J. W. Van Ness, "Fractional Brownian motions, fractional
noises and applications", SIAM Review 10(4), 1968; T. W. Anderson, *The Statistical Analysis of Time Series*,
1971 (GLS).
"""

from __future__ import annotations

import functools
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


#: drift exponents alpha tried by :func:`fit_drift_noise` (0 < alpha < 2; 1 is the random walk)
DRIFT_EXPONENTS = tuple(round(float(a), 2) for a in np.arange(0.2, 1.81, 0.1))


@dataclass(frozen=True)
class DriftNoise:
    """White plus power-law drift model of a residual: ``white_var`` a per point [unit^2], ``walk_var_per_s`` the
    drift's coefficient c [unit^2/s^exponent] and ``exponent`` alpha [dimensionless], so that the variogram is
    ``2 a + c dt^alpha``; with ``exponent`` 1, c is the random walk's K^2 [unit^2/s]."""

    white_var: float
    walk_var_per_s: float
    exponent: float = 1.0

    def variogram(self, dt_s: np.ndarray) -> np.ndarray:
        """``E[(r(t + dt) - r(t))^2]`` at lags ``dt_s`` [s] [unit^2]."""
        return 2.0 * self.white_var + self.walk_var_per_s * np.asarray(dt_s, dtype=float) ** self.exponent


def coarsen(values: np.ndarray, factor: int) -> np.ndarray:
    """Means over consecutive groups of ``factor`` rows of ``values`` (n, ...) (the last group may be shorter)."""
    if factor <= 1:
        return values
    n = values.shape[0]
    edges = np.arange(0, n, factor)
    sums = np.add.reduceat(values, edges, axis=0)
    counts = np.diff(np.append(edges, n)).reshape((-1,) + (1,) * (values.ndim - 1))
    return sums / counts


def empirical_variogram(
    residuals: list[np.ndarray], times_s: list[np.ndarray], reach: int = VARIOGRAM_REACH, lags: int = VARIOGRAM_LAGS
) -> tuple[np.ndarray, np.ndarray]:
    """(dt [s], V [unit^2]): ``V(L) = mean_i (r_{i+L} - r_i)^2`` of each residual (one array per recording, at
    times ``times_s`` [s]) at ``lags`` log-spaced lags L up to 1/``reach`` of the recording, dt(L) the mean time
    they span."""
    rows, values = [], []
    for r, t in zip(residuals, times_s):
        n = r.size
        if n < 4:
            continue
        for lag in np.unique(np.round(np.geomspace(1, max(1, n // reach), lags)).astype(int)):
            d = r[lag:] - r[:-lag]
            rows.append(float(np.mean(t[lag:] - t[:-lag])))
            values.append(float(np.mean(d**2)))
    return np.asarray(rows), np.asarray(values)


def _fit_at(dt: np.ndarray, v: np.ndarray, w: np.ndarray, exponent: float) -> tuple[float, float, float]:
    """(a, c, weighted squared misfit) of ``V = 2 a + c dt^exponent``, a and c non-negative, weights ``w``."""
    x = np.column_stack([np.full(dt.size, 2.0), dt**exponent]) * w[:, None]
    (a, c), *_ = np.linalg.lstsq(x, v * w, rcond=None)
    if c < 0:
        a, c = float(np.sum(w * w * v) / np.sum(w * w * 2.0)), 0.0
    elif a < 0:
        p = dt**exponent
        a, c = 0.0, float(np.sum(w * w * v * p) / np.sum(w * w * p * p))
    a, c = max(float(a), 0.0), max(float(c), 0.0)
    return a, c, float(np.sum((w * (2.0 * a + c * dt**exponent - v)) ** 2))


def fit_drift_noise(
    residuals: list[np.ndarray],
    times_s: list[np.ndarray],
    exponents: tuple[float, ...] = DRIFT_EXPONENTS,
    reach: int = VARIOGRAM_REACH,
) -> DriftNoise:
    """The white variance ``a`` [unit^2], drift coefficient ``c`` [unit^2/s^alpha] and exponent ``alpha`` of
    residuals (one array per recording, at times ``times_s`` [s]), from a non-negative least-squares fit of

        V(L) = mean_i (r_{i+L} - r_i)^2 = 2 a + c dt(L)^alpha

    over log-spaced lags L up to 1/``reach`` of the recording (:func:`empirical_variogram`), each lag weighted by
    1 / V(L)^2 (a relative fit), alpha the one of ``exponents`` of least misfit (``(1.0,)``: the white plus
    random-walk model)."""
    dt, v = empirical_variogram(residuals, times_s, reach=reach)
    if not dt.size:
        return DriftNoise(0.0, 0.0)
    w = 1.0 / np.maximum(v, 1e-300)
    best = min((_fit_at(dt, v, w, e) + (e,) for e in exponents), key=lambda fit: fit[2])
    return DriftNoise(best[0], best[1], float(best[3]))


def covariance(t_s: np.ndarray, noise: DriftNoise) -> np.ndarray:
    """The covariance (n, n) [unit^2] of one recording's residual at times ``t_s`` [s] under ``noise``:
    ``a I + (c / 2) (tau_i^alpha + tau_j^alpha - |tau_i - tau_j|^alpha)``, tau the time since the first point.

    ``a`` is at least ``c dt^alpha / 3`` (dt the median spacing of the points [s]): the mean of the drift over a
    point's span scatters about that much about the drift (without it, a pure walk pins the first point
    exactly)."""
    tau = t_s - t_s[0]
    e = noise.exponent
    powered = tau**e
    cov = np.add.outer(powered, powered)
    cov -= _lag_powers(tau, e)
    cov *= 0.5 * noise.walk_var_per_s
    spacing = float(np.median(np.diff(t_s))) if t_s.size > 1 else 0.0
    floor = max(noise.walk_var_per_s * spacing**e / 3.0, 1e-12 * max(float(np.max(np.diag(cov))), 1e-300))
    cov[np.diag_indices_from(cov)] += max(noise.white_var, floor)
    return cov


def _lag_powers(tau: np.ndarray, exponent: float) -> np.ndarray:
    """``|tau_i - tau_j|^exponent`` (n, n) [s^exponent]. Over the evenly spaced points that begin the series (all
    but the last, shorter block of a coarsened run, often) the matrix is Toeplitz, built from their lags alone;
    the rows and columns of the other points are computed in full."""
    import scipy.linalg  # slow to import (0.1 s with scipy's array API layer): not at every command's start

    steps = np.diff(tau)
    even = np.abs(steps - steps[0]) <= 1e-12 * abs(steps[0]) if steps.size else np.zeros(0, dtype=bool)
    m = 1 + (int(np.argmin(even)) if not even.all() else even.size)  # the evenly spaced points that begin it
    if m < 3:
        return np.abs(np.subtract.outer(tau, tau)) ** exponent
    out = np.empty((tau.size, tau.size))
    out[:m, :m] = scipy.linalg.toeplitz(np.abs(tau[:m] - tau[0]) ** exponent)
    rest = np.abs(np.subtract.outer(tau[m:], tau)) ** exponent
    out[m:, :] = rest
    out[:m, m:] = rest[:, :m].T
    return out


@functools.lru_cache(maxsize=4)
def _lower_factor(t_bytes: bytes, noise: DriftNoise) -> np.ndarray:
    """The lower Cholesky factor of :func:`covariance` at the times whose float64 bytes are ``t_bytes`` (kept:
    the tests of one axis whiten several designs under one drift model at the same times)."""
    import scipy.linalg  # slow to import: not at every command's start

    t_s = np.frombuffer(t_bytes, dtype=float)
    chol = scipy.linalg.cholesky(covariance(t_s, noise), lower=True, overwrite_a=True, check_finite=False)
    chol.setflags(write=False)
    return chol


def whitened(x: np.ndarray, y: np.ndarray, t_s: np.ndarray, noise: DriftNoise) -> tuple[np.ndarray, np.ndarray]:
    """``x`` (n, p) and ``y`` (n,) of one recording multiplied by the inverse Cholesky factor of its
    :func:`covariance`: ordinary least squares on the result is GLS."""
    import scipy.linalg  # slow to import: not at every command's start

    chol = _lower_factor(np.ascontiguousarray(t_s, dtype=float).tobytes(), noise)
    from_left = scipy.linalg.solve_triangular(chol, np.column_stack([x, y]), lower=True, check_finite=False)
    return from_left[:, :-1], from_left[:, -1]


def wald_statistic(
    x: list[np.ndarray], y: list[np.ndarray], t_s: list[np.ndarray], noise: DriftNoise, tested: np.ndarray
) -> float:
    """The Wald statistic ``b' cov(b)^-1 b`` of the coefficients ``b`` of columns ``tested`` (indices) in the
    generalized least-squares fit of ``y`` on ``x`` (one pair per recording, at times ``t_s`` [s]) under
    ``noise``. Under the hypothesis that those terms are zero it follows a chi-square law with
    ``len(tested)`` degrees of freedom. (Average long series first, :func:`coarsen`: the covariance of each
    recording is dense.)"""
    pairs = [whitened(xk, yk, tk, noise) for xk, yk, tk in zip(x, y, t_s)]
    xw, yw = np.vstack([p[0] for p in pairs]), np.concatenate([p[1] for p in pairs])
    scale = np.sqrt(np.maximum(np.sum(xw**2, axis=0), 1e-300))
    coef, *_ = np.linalg.lstsq(xw / scale, yw, rcond=1e-10)
    cov = np.linalg.pinv((xw / scale).T @ (xw / scale), rcond=1e-10)
    b = coef[tested]
    return float(b @ np.linalg.pinv(cov[np.ix_(tested, tested)], rcond=1e-10) @ b)


def chi2_threshold(dof: int, sigmas: float = 3.0) -> float:
    """The chi-square value a statistic of ``dof`` (1 or 2) degrees of freedom exceeds with the two-sided
    probability of ``sigmas`` standard deviations of a normal law (3: 0.27 %)."""
    p = math.erfc(sigmas / math.sqrt(2.0))
    if dof == 1:
        return sigmas**2
    if dof == 2:
        return -2.0 * math.log(p)
    raise ValueError(f"dof: 1 or 2, got {dof}")


__all__ = [
    "DRIFT_EXPONENTS",
    "DriftNoise",
    "MAX_POINTS",
    "VARIOGRAM_REACH",
    "chi2_threshold",
    "coarsen",
    "covariance",
    "empirical_variogram",
    "fit_drift_noise",
    "wald_statistic",
    "whitened",
]
