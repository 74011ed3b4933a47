"""The online learner's refit: the weighted least-squares design on its points, solved by Cholesky as the C code
solves it (step 8 of :mod:`gyrocomp.fitting.online`)."""

from __future__ import annotations

import math

import numpy as np

from ...errors import InputError
from .settings import MIN_TILT_G, POINTS_PER_TILT, T_REF_DEGC, T_SCALE_DEGC, RIDGE


def xyz_rows(values, rows: int, name: str) -> np.ndarray:
    """``values`` as a float array of shape (rows, 3) (x, y, z per time), or one line naming ``name``."""
    try:
        out = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected numbers, got {type(values).__name__}") from None
    if out.ndim == 1 and rows == 1 and out.size == 3:
        out = out.reshape(1, 3)
    if out.shape != (rows, 3):
        raise InputError(f"{name}: expected shape ({rows}, 3) (x, y, z for each time), got {out.shape}")
    return out


def shape_curve(coef: np.ndarray, degree: int, t_range: tuple[float, float], temperature) -> np.ndarray:
    """The shape sum_k c_k u^k per axis [deg/s] (..., 3) at ``temperature`` [degC], continued along its tangent
    past ``t_range`` (as :class:`PolynomialCurve` with ``extrapolation="linear"``)."""
    t = np.asarray(temperature, dtype=float)
    clipped = np.clip(t, *t_range)
    u = np.expand_dims((clipped - T_REF_DEGC) / T_SCALE_DEGC, -1)
    beyond = np.expand_dims((t - clipped) / T_SCALE_DEGC, -1)
    out = np.zeros(np.shape(t) + (3,))
    slope = np.zeros(np.shape(t) + (3,))
    for k in range(degree - 1, -1, -1):
        out = (out + coef[:, k]) * u
        slope = slope * u + (k + 1) * coef[:, k]
    return out + slope * beyond


def tilted_axes(accel: np.ndarray, point_sessions: np.ndarray, sessions: np.ndarray, spare: int) -> np.ndarray:
    """Which accelerometer axes the points excite enough to fit their g-sensitivity: a range of MIN_TILT_G within
    one power-on (an attitude that changes only from one power-on to the next cannot be told from the power-ons'
    constants), POINTS_PER_TILT of the ``spare`` points (beyond the other unknowns) for each."""
    out = np.zeros(3, dtype=bool)
    for k in range(3):
        span = max(float(np.ptp(accel[point_sessions == q, k])) for q in sessions)
        if spare >= POINTS_PER_TILT and span >= MIN_TILT_G:
            out[k] = True
            spare -= POINTS_PER_TILT
    return out


def design_matrix(
    temps: np.ndarray,
    accel: np.ndarray,
    tilted: np.ndarray,
    bin_sessions: np.ndarray,
    sessions: np.ndarray,
    degree: int,
) -> np.ndarray:
    """The refit's columns per point: u^1..u^degree of the scaled temperature, the tilted accelerometer axes [g]
    and one indicator per power-on (``sessions``)."""
    u = (temps - T_REF_DEGC) / T_SCALE_DEGC
    columns = [u**k for k in range(1, degree + 1)]
    columns += [accel[:, k] for k in range(3) if tilted[k]]
    columns += [(bin_sessions == s).astype(float) for s in sessions]
    return np.column_stack(columns)


def weighted_fit(temps, accel, tilted, bin_sessions, sessions, bias, weights, degree):
    """The learner's weighted least squares (step 7 of :mod:`gyrocomp.fitting.online`), by Cholesky on the normal
    equations in the C code's order of operations.

    Parameters
    ----------
    temps : array (n,)
        The points' temperatures [degC].
    accel, tilted, bin_sessions, sessions
        The points' specific force (n, 3) [g], the accelerometer axes fitted (:func:`tilted_axes`), each point's
        power-on and the power-ons (:func:`design_matrix`).
    bias : array (n, 3)
        The points' mean rates [deg/s].
    weights : array (n,)
    degree : int
        The temperature curve's degree.

    Returns
    -------
    tuple or None
        (coefficients (degree, 3), g-sensitivities (tilted axes, 3) [deg/s/g], constants (sessions, 3) [deg/s],
        residual RMS (3,) [deg/s], the Cholesky factor, the residual scale, the weighted residual sum of squares);
        None when the system is not positive definite.
    """
    x = design_matrix(temps, accel, tilted, bin_sessions, sessions, degree)
    n, p = x.shape
    # sums over the points in their order, each term w (x_r x_c): a reduction over the first axis of a contiguous
    # array adds the points one after the other, as the C code does
    w = np.asarray(weights, dtype=float)[:, None, None]
    a = np.ascontiguousarray(w * (x[:, :, None] * x[:, None, :])).sum(axis=0)
    b = np.ascontiguousarray(w * (x[:, :, None] * np.asarray(bias, dtype=float)[:, None, :])).sum(axis=0)
    for i in range(p):
        a[i, i] *= 1.0 + RIDGE
    lower = _cholesky(a)
    if lower is None:
        return None
    beta = _cholesky_solve(lower, b)
    residual = bias - x @ beta
    dof = n - p
    rms = np.zeros(3)
    if dof > 0:
        rms = np.sqrt((weights @ (residual * residual)) / weights.sum() * n / dof)
    g_end = degree + int(tilted.sum())
    scale2 = rms * rms * weights.sum() / n
    ssr = float(np.sum(weights @ (residual * residual)))
    return beta[:degree], beta[degree:g_end], beta[g_end:], rms, lower, scale2, ssr


def _cholesky(a: np.ndarray) -> np.ndarray | None:
    p = a.shape[0]
    lower = np.zeros_like(a)
    for i in range(p):
        for j in range(i + 1):
            total = a[i, j]
            for k in range(j):
                total -= lower[i, k] * lower[j, k]
            if i == j:
                if not total > 0:
                    return None
                lower[i, i] = math.sqrt(total)
            else:
                lower[i, j] = total / lower[j, j]
    return lower


def forward_substitute(lower: np.ndarray, x: np.ndarray) -> np.ndarray:
    """L^-1 x by forward substitution."""
    p = lower.shape[0]
    y = np.zeros(p)
    for i in range(p):
        total = x[i]
        for k in range(i):
            total -= lower[i, k] * y[k]
        y[i] = total / lower[i, i]
    return y


def _cholesky_solve(lower: np.ndarray, b: np.ndarray) -> np.ndarray:
    p = lower.shape[0]
    y = np.zeros_like(b)
    for i in range(p):
        total = b[i].copy()
        for k in range(i):
            total -= lower[i, k] * y[k]
        y[i] = total / lower[i, i]
    x = np.zeros_like(b)
    for i in range(p - 1, -1, -1):
        total = y[i].copy()
        for k in range(i + 1, p):
            total -= lower[k, i] * x[k]
        x[i] = total / lower[i, i]
    return x


__all__ = ["xyz_rows", "shape_curve", "tilted_axes", "design_matrix", "weighted_fit", "forward_substitute"]
