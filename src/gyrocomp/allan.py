"""Allan deviation of gyro (rate) or angle (phase) data.

The overlapping Allan variance of rate samples y_i taken every tau0 = 1/rate_hz, with phase
x_0 = 0, x_{i+1} = x_i + y_i tau0 (N phase points), at tau = m tau0 is

    sigma^2(tau) = sum_{i=0}^{N-2m-1} (x_{i+2m} - 2 x_{i+m} + x_i)^2 / (2 tau^2 (N - 2m))

(IEEE Std 952-1997 Annex C; W. Riley, *Handbook of Frequency Stability Analysis*, NIST SP 1065, eq. 11).
The other estimators (ADEV, MDEV, TDEV, HDEV, OHDEV) follow the same handbook. Every sum is
evaluated in blocks so that the working memory beyond the phase array stays bounded.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import InputError

KINDS = ("oadev", "adev", "mdev", "tdev", "hdev", "ohdev")
#: Stable32 stops its tau grids at N / stop ratio (N phase points)
STOP_RATIO = {"adev": 5, "hdev": 5}
DEFAULT_STOP_RATIO = 4
_BLOCK = 1 << 18
_SECOND = (1.0, -2.0, 1.0)
_THIRD = (-1.0, 3.0, -3.0, 1.0)


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


def averaging_factors(n_phase: int, taus: str | np.ndarray, rate_hz: float, kind: str = "oadev") -> np.ndarray:
    """Averaging factors m for a tau specification; the named grids stop at n_phase / stop ratio (as Stable32)."""
    m_max = max(1, n_phase // STOP_RATIO.get(kind, DEFAULT_STOP_RATIO))
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
    m = m[(m >= 1) & (_term_count(kind, n_phase, m) >= 1)]
    if m.size == 0:
        raise InputError("taus: no tau fits the data (need 1/rate_hz <= tau < duration / 2)")
    return m


def _term_count(kind: str, n_phase: int, m):
    """Number of terms in each estimator's sum (Stable32's '#' column)."""
    return {
        "oadev": lambda: n_phase - 2 * m,
        "adev": lambda: (n_phase - 1) // m - 1,
        "mdev": lambda: n_phase - 3 * m + 1,
        "tdev": lambda: n_phase - 3 * m + 1,
        "hdev": lambda: (n_phase - 1) // m - 2,
        "ohdev": lambda: n_phase - 3 * m,
    }[kind]()


def _difference_sum(series: np.ndarray, m: int, coefs: tuple[float, ...], stride: int, count: int) -> float:
    """Sum over i = 0, stride, ..., (count-1)*stride of (sum_k coefs[k] series[i + k m])^2, in blocks."""
    total = 0.0
    block = max(1, _BLOCK // stride) * stride
    last = (count - 1) * stride + 1
    for start in range(0, last, block):
        stop = min(start + block, last)
        d = coefs[0] * series[start:stop:stride]
        for k, c in enumerate(coefs[1:], start=1):
            d += c * series[start + k * m: stop + k * m: stride]
        total += float(np.dot(d, d))
    return total


def _variance(kind: str, phase: np.ndarray, cumulated: np.ndarray | None, m: int, tau: float, n: int) -> float:
    if kind in ("oadev", "adev"):
        return _difference_sum(phase, m, _SECOND, 1 if kind == "oadev" else m, n) / (2.0 * tau * tau * n)
    if kind in ("hdev", "ohdev"):
        return _difference_sum(phase, m, _THIRD, 1 if kind == "ohdev" else m, n) / (6.0 * tau * tau * n)
    # mdev: sum_{i=j}^{j+m-1} (x[i+2m] - 2x[i+m] + x[i]) is the third difference at stride m of the
    # cumulated phase X[k] = sum_{i<k} x[i], so no per-tau O(N) array is needed
    return _difference_sum(cumulated, m, _THIRD, 1, n) / (2.0 * m * m * tau * tau * n)


def allan_deviation(data, rate_hz: float, *, kind: str = "oadev", taus="octave",
                    data_type: str = "rate") -> AllanResult:
    """Allan deviation of ``data`` sampled at ``rate_hz``.

    Parameters
    ----------
    data : array (n,)
        Rate samples (e.g. [deg/s]) or, with ``data_type="phase"``, integrated angle samples (e.g. [deg]).
    rate_hz : float
        Sample rate [Hz].
    kind : {"oadev", "adev", "mdev", "tdev", "hdev", "ohdev"}
        Estimator: overlapping Allan (default), Allan, modified Allan, time deviation (tau/sqrt(3) MDEV,
        in [unit*s]), Hadamard and overlapping Hadamard deviation (Riley, NIST SP 1065, sections 5.2).
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
    ms = averaging_factors(phase.size, taus, rate_hz, kind)
    tau = ms / rate_hz
    n = _term_count(kind, phase.size, ms)
    cumulated = None
    if kind in ("mdev", "tdev"):
        cumulated = np.empty(phase.size + 1)
        cumulated[0] = 0.0
        np.cumsum(phase - phase.mean(), out=cumulated[1:])
    var = np.array([_variance("mdev" if kind == "tdev" else kind, phase, cumulated, int(m), t, int(k))
                    for m, t, k in zip(ms, tau, n)])
    dev = np.sqrt(var)
    if kind == "tdev":
        dev = tau * dev / np.sqrt(3.0)  # time deviation [unit*s]: tau / sqrt(3) * MDEV
    return AllanResult(tau=tau, deviation=dev, n=n, kind=kind)
