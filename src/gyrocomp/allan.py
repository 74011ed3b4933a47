"""Allan deviation of gyro (rate) or angle (phase) data.

The overlapping Allan variance of rate samples y_i taken every tau0 = 1/rate_hz, with phase
x_0 = 0, x_{i+1} = x_i + y_i tau0 (N phase points), at tau = m tau0 is

    sigma^2(tau) = sum_{i=0}^{N-2m-1} (x_{i+2m} - 2 x_{i+m} + x_i)^2 / (2 tau^2 (N - 2m))

(IEEE Std 952-1997 Annex C; W. Riley, *Handbook of Frequency Stability Analysis*, NIST SP 1065, eq. 11).
The sum is evaluated in blocks so that the working memory beyond the phase array stays bounded.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import InputError

KINDS = ("oadev",)
#: Stable32 stops its tau grids at N / STOP_RATIO for overlapping estimators
STOP_RATIO = 4
_BLOCK = 1 << 18


@dataclass(frozen=True)
class AllanResult:
    """Allan deviation at a set of averaging times.

    Attributes
    ----------
    tau : array
        Averaging times [s].
    deviation : array
        Deviation at each tau, in the unit of the input (e.g. [deg/s]).
    n : array of int
        Number of terms in the estimator's sum at each tau.
    kind : str
        The estimator, e.g. ``"oadev"``.
    """

    tau: np.ndarray
    deviation: np.ndarray
    n: np.ndarray
    kind: str = "oadev"

    def minimum(self) -> tuple[float, float]:
        """``(tau_s, deviation)`` at the smallest deviation."""
        i = int(np.nanargmin(self.deviation))
        return float(self.tau[i]), float(self.deviation[i])


def to_phase(rate: np.ndarray, rate_hz: float) -> np.ndarray:
    """Integrate rate samples into N+1 phase points [unit*s], mean removed first (as Stable32 does)."""
    y = np.asarray(rate, dtype=float)
    phase = np.empty(y.size + 1)
    phase[0] = 0.0
    np.cumsum(y - y.mean(), out=phase[1:])
    phase[1:] /= rate_hz
    return phase


def averaging_factors(n_phase: int, taus: str | np.ndarray, rate_hz: float) -> np.ndarray:
    """Averaging factors m for a tau specification, limited to m <= n_phase / STOP_RATIO."""
    m_max = max(1, n_phase // STOP_RATIO)
    if isinstance(taus, str):
        if taus == "octave":
            m = 2 ** np.arange(int(np.floor(np.log2(m_max))) + 1)
        elif taus == "decade":
            decades = 10 ** np.arange(int(np.floor(np.log10(m_max))) + 1)
            m = np.unique(np.concatenate([decades, 2 * decades, 4 * decades]))
        elif taus == "all":
            m = np.arange(1, m_max + 1)
        else:
            raise InputError(f"taus: unknown grid {taus!r}; use octave, decade, all or an array of taus [s]")
        return m[m <= m_max].astype(np.int64)
    m = np.unique(np.round(np.asarray(taus, dtype=float) * rate_hz).astype(np.int64))
    m = m[(m >= 1) & (n_phase - 2 * m >= 1)]
    if m.size == 0:
        raise InputError("taus: no tau fits the data (need 1/rate_hz <= tau < duration / 2)")
    return m


def _oadev_sum(phase: np.ndarray, m: int) -> float:
    n_terms = phase.size - 2 * m
    total = 0.0
    for start in range(0, n_terms, _BLOCK):
        stop = min(start + _BLOCK, n_terms)
        d = phase[start + 2 * m: stop + 2 * m] - 2.0 * phase[start + m: stop + m] + phase[start:stop]
        total += float(np.dot(d, d))
    return total


def allan_deviation(data, rate_hz: float, *, kind: str = "oadev", taus="octave",
                    data_type: str = "rate") -> AllanResult:
    """Allan deviation of ``data`` sampled at ``rate_hz``.

    Parameters
    ----------
    data : array (n,)
        Rate samples (e.g. [deg/s]) or, with ``data_type="phase"``, integrated angle samples (e.g. [deg]).
    rate_hz : float
        Sample rate [Hz].
    kind : {"oadev"}
        Estimator: ``"oadev"``, the fully overlapping Allan deviation.
    taus : {"octave", "decade", "all"} or array
        Averaging times: m = 1, 2, 4, ...; m = 1, 2, 4, 10, 20, 40, ...; every m; or taus [s].
    data_type : {"rate", "phase"}
    """
    if kind not in KINDS:
        raise InputError(f"kind: unknown Allan estimator {kind!r}; use one of {', '.join(KINDS)}")
    if not rate_hz > 0:
        raise InputError(f"rate_hz: must be positive, got {rate_hz}")
    if data_type == "rate":
        phase = to_phase(data, rate_hz)
    elif data_type == "phase":
        phase = np.asarray(data, dtype=float)
    else:
        raise InputError(f"data_type: {data_type!r}; use 'rate' or 'phase'")
    if phase.ndim != 1 or phase.size < 3:
        raise InputError("data: need a one-dimensional series of at least 3 phase points")
    ms = averaging_factors(phase.size, taus, rate_hz)
    tau = ms / rate_hz
    n = phase.size - 2 * ms
    dev = np.array([np.sqrt(_oadev_sum(phase, int(m)) / (2.0 * t * t * k)) for m, t, k in zip(ms, tau, n)])
    return AllanResult(tau=tau, deviation=dev, n=n, kind=kind)
