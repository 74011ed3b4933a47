"""Equivalent degrees of freedom and chi-squared confidence intervals of the Allan-family deviations.

C. Greenhall and W. Riley, "Uncertainty of stability variances based on finite differences", PTTI 2003
(the edf of every difference variance); NIST SP 1065 Table 7 (TOTDEV) and eq. 45 (the bounds).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..errors import InputError
from .estimators import ESTIMATORS, ONE_SIGMA


def _sw(t: np.ndarray, alpha: int) -> np.ndarray:
    """Greenhall's generalized autocovariance sw(t) of the power-law noise (Greenhall 2004, eq. 7)."""
    t = np.abs(np.asarray(t, dtype=float))
    if alpha % 2 == 0:
        return -t if alpha == 2 else t ** (3 - alpha)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(t == 0, 0.0, t ** (3 - alpha) * np.log(np.where(t == 0, 1.0, t)))


def _sx(t: np.ndarray, filter_factor: float, alpha: int) -> np.ndarray:
    if math.isinf(filter_factor):
        return _sw(t, alpha + 2)
    f = filter_factor
    return f * f * (2.0 * _sw(t, alpha) - _sw(t - 1.0 / f, alpha) - _sw(t + 1.0 / f, alpha))


def _sz(t: np.ndarray, filter_factor: float, alpha: int, d: int) -> np.ndarray:
    """Eq. 9: the d-th difference, with binomial weights (-1)^k C(2d, d+k), of sx."""
    t = np.asarray(t, dtype=float)
    total = np.zeros_like(t)
    for k in range(-d, d + 1):
        total += (-1) ** abs(k) * math.comb(2 * d, d + k) * _sx(t + k, filter_factor, alpha)
    return total


def _basic_sum(j_terms: float, m_terms: float, stride: float, filter_factor: float, alpha: int, d: int) -> float:
    """Eq. 10."""
    j = np.arange(1, int(j_terms))
    inner = 2.0 * (1.0 - j / m_terms) * _sz(j / stride, filter_factor, alpha, d) ** 2
    tail = (1.0 - j_terms / m_terms) * _sz(np.array(j_terms / stride), filter_factor, alpha, d) ** 2
    return float(_sz(np.array(0.0), filter_factor, alpha, d) ** 2 + tail + inner.sum())


# Greenhall 2004, tables 1-3: (a0, a1) by alpha = 2, 1, 0, -1, -2, -3, -4 (rows) and d = 1, 2, 3 (columns)
_TABLE1 = [
    [(2 / 3, 1 / 3), (7 / 9, 1 / 2), (22 / 25, 2 / 3)],
    [(0.840, 0.345), (0.997, 0.616), (1.141, 0.843)],
    [(1.079, 0.368), (1.033, 0.607), (1.184, 0.848)],
    [None, (1.048, 0.534), (1.180, 0.816)],
    [None, (1.302, 0.535), (1.175, 0.777)],
    [None, None, (1.194, 0.703)],
    [None, None, (1.489, 0.702)],
]
_TABLE2 = [
    [(3 / 2, 1 / 2), (35 / 18, 1.0), (231 / 100, 3 / 2)],
    [(78.6, 25.2), (790.0, 410.0), (9950.0, 6520.0)],
    [(2 / 3, 1 / 6), (2 / 3, 1 / 3), (7 / 9, 1 / 2)],
    [None, (0.852, 0.375), (0.997, 0.617)],
    [None, (1.079, 0.368), (1.033, 0.607)],
    [None, None, (1.053, 0.553)],
    [None, None, (1.302, 0.535)],
]
_TABLE3 = {1: (6.0, 4.0), 2: (15.23, 12.0), 3: (47.8, 40.0)}
_J_MAX = 100


# Over 60 lines on purpose: Greenhall and Riley's algorithm, case by case as the paper gives it (its docstring
# is half of it), so that each step can be read against the paper.
def edf_greenhall(alpha: int, d: int, m: int, n_phase: int, *, overlapping: bool, modified: bool) -> float:
    """Equivalent degrees of freedom of a difference variance (Greenhall and Riley 2003, "edf").

    Parameters
    ----------
    alpha : int
        Power-law noise exponent, 2 to -4, with alpha + 2d > 1.
    d : int
        Difference order: 2 for Allan (ADEV, OADEV, MDEV, TDEV), 3 for Hadamard (HDEV, OHDEV).
    m : int
        Averaging factor (tau = m / rate_hz).
    n_phase : int
        Number of phase points.
    overlapping, modified : bool
        The estimator's stride (tau0 rather than tau) and whether it is a modified variance.
    """
    alpha, d, m = int(alpha), int(d), int(m)
    if not alpha + 2 * d > 1 or not -4 <= alpha <= 2:
        raise InputError(f"alpha: {alpha} is outside the range the difference order {d} can estimate")
    filter_factor = 1 if modified else m
    stride = m if overlapping else 1
    length = m / filter_factor + m * d
    m_terms = 1 + math.floor(stride * (n_phase - length) / m)
    if m_terms < 1:
        return math.nan
    j_terms = min(m_terms, (d + 1) * stride)
    r = m_terms / stride
    row = 2 - alpha

    def exact(normalization: float, j: float, mm: float, s: float, f: float) -> float:
        return normalization * mm / _basic_sum(j, mm, s, f, alpha, d)

    if modified:
        sz0 = float(_sz(np.array(0.0), 1, alpha, d)) ** 2
        if j_terms <= _J_MAX:
            return exact(sz0, j_terms, m_terms, stride, 1)
        if r > d + 1:
            a0, a1 = _TABLE1[row][d - 1]
            return r / (a0 - a1 / r)
        return exact(sz0, _J_MAX, _J_MAX, _J_MAX / r, 1)
    if alpha <= 0:
        if j_terms <= _J_MAX:
            f = m if m * (d + 1) <= _J_MAX else math.inf
            return exact(float(_sz(np.array(0.0), f, alpha, d)) ** 2, j_terms, m_terms, stride, f)
        if r > d + 1:
            a0, a1 = _TABLE2[row][d - 1]
            return r / (a0 - a1 / r)
        return exact(float(_sz(np.array(0.0), math.inf, alpha, d)) ** 2, _J_MAX, _J_MAX, _J_MAX / r, math.inf)
    if alpha == 1:
        if j_terms <= _J_MAX:
            return exact(float(_sz(np.array(0.0), m, 1, d)) ** 2, j_terms, m_terms, stride, m)
        b0, b1 = _TABLE3[d]
        normalization = (b0 + b1 * math.log(m)) ** 2
        if r > d + 1:
            a0, a1 = _TABLE2[row][d - 1]
            return normalization * r / (a0 - a1 / r)
        return exact(normalization, _J_MAX, _J_MAX, _J_MAX / r, _J_MAX / r)
    # alpha == 2, unmodified
    if math.ceil(r) <= d:
        return exact(float(_sz(np.array(0.0), m, 2, d)) ** 2, j_terms, m_terms, stride, m)
    a0 = math.comb(4 * d, 2 * d) / math.comb(2 * d, d) ** 2
    return m_terms / (a0 - (d / 2.0) / r)


#: NIST SP 1065 Table 7: TOTVAR edf = b T/tau - c, for white, flicker and random walk FM
_TOTDEV_EDF = {0: (1.50, 0.0), -1: (1.17, 0.22), -2: (0.93, 0.36)}


def edf_totdev(alpha: int, m: int, n_phase: int) -> float:
    """Equivalent degrees of freedom of the total deviation, as Stable32 computes them.

    White, flicker and random walk FM (alpha 0, -1, -2): b (N-1)/m - c (NIST SP 1065, Table 7). White
    and flicker PM (alpha 2, 1), where that table has no entry: the simple overlapping-Allan formulas of
    SP 1065 Table 5, (N+1)(N-2m) / (2(N-m)) and exp(sqrt(ln((N-1)/2m) ln((2m+1)(N-1)/4))).
    """
    n = n_phase
    if alpha in _TOTDEV_EDF:
        b, c = _TOTDEV_EDF[alpha]
        return b * (n - 1) / m - c
    if alpha == 2:
        return (n + 1) * (n - 2 * m) / (2.0 * (n - m))
    if alpha == 1:
        return math.exp(math.sqrt(math.log((n - 1) / (2.0 * m)) * math.log((2 * m + 1) * (n - 1) / 4.0)))
    raise InputError(f"alpha: {alpha} has no total-deviation degrees of freedom; use 2 to -2")


def confidence_interval(deviation, edf, confidence: float = ONE_SIGMA) -> tuple[np.ndarray, np.ndarray]:
    """Chi-squared bounds (low, high) of a deviation with ``edf`` degrees of freedom (NIST SP 1065 eq. 45)."""
    deviation = np.asarray(deviation, dtype=float)
    edf = np.asarray(edf, dtype=float)
    tail = (1.0 - confidence) / 2.0
    from scipy.special import gammaincinv  # scipy.special is slow to import; only the intervals need it

    with np.errstate(invalid="ignore", divide="ignore"):
        # chi-squared quantile: chi2.ppf(q, edf) = 2 * gammaincinv(edf / 2, q)
        low = deviation * np.sqrt(edf / (2.0 * gammaincinv(edf / 2.0, 1.0 - tail)))
        high = deviation * np.sqrt(edf / (2.0 * gammaincinv(edf / 2.0, tail)))
    return low, high


@functools.lru_cache(maxsize=4096)
def _edf(kind: str, alpha: int, m: int, n_phase: int) -> float:
    """Equivalent degrees of freedom (cached: stretches of one length between gaps repeat the same terms)."""
    if kind == "totdev":
        return edf_totdev(alpha, m, n_phase)
    spec = ESTIMATORS[kind]
    return edf_greenhall(alpha, spec.difference_order, m, n_phase, overlapping=spec.overlapping, modified=spec.modified)


def degrees_of_freedom(kind: str, alphas: np.ndarray, ms: np.ndarray, n_phase: int) -> np.ndarray:
    """Equivalent degrees of freedom of estimator ``kind`` at each averaging factor (NaN where alpha is)."""
    return np.array([math.nan if math.isnan(a) else _edf(kind, int(a), int(m), n_phase) for a, m in zip(alphas, ms)])
