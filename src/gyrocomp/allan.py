"""Allan deviation of gyro (rate) or angle (phase) data, with confidence intervals and noise types.

The overlapping Allan variance of rate samples y_i taken every tau0 = 1/rate_hz, with phase
x_0 = 0, x_{i+1} = x_i + y_i tau0 (N phase points), at tau = m tau0 is

    sigma^2(tau) = sum_{i=0}^{N-2m-1} (x_{i+2m} - 2 x_{i+m} + x_i)^2 / (2 tau^2 (N - 2m))

(IEEE Std 952-1997 Annex C; W. Riley, *Handbook of Frequency Stability Analysis*, NIST SP 1065, eq. 11).
The other estimators (ADEV, MDEV, TDEV, HDEV, OHDEV, TOTDEV) follow the same handbook.

Confidence intervals use the equivalent degrees of freedom of C. Greenhall and W. Riley, "Uncertainty
of stability variances based on finite differences", PTTI 2003 (TOTDEV: NIST SP 1065 Table 7) and
chi-squared bounds (SP 1065 eq. 45). The power-law noise type at each tau comes from the lag-1
autocorrelation (W. Riley and C. Greenhall, "Power law noise identification using the lag 1
autocorrelation", EFTF 2004).

Every sum is evaluated in blocks or as dot products of views, so the working memory beyond the phase
array stays about 10 MiB; ``phase_out`` lets the phase itself live in a memory-mapped file for data larger
than memory. The overlapping Allan sums have two fast paths: octave factors 1, 2, 4, ... in one
cache-resident pass per block, and factors long against the series (N/m <= 128) from lag products.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Iterable

import numpy as np

from .errors import InputError
from .units import STANDARD_GRAVITY_M_PER_S2

#: two-sided confidence of one standard deviation, erf(1/sqrt(2)) = 0.6827
ONE_SIGMA = math.erf(1.0 / math.sqrt(2.0))
KINDS = ("oadev", "adev", "mdev", "tdev", "hdev", "ohdev", "totdev")
#: Stable32 stops its tau grids at N / stop ratio (N phase points)
STOP_RATIO = {"adev": 5, "hdev": 5, "totdev": 2}
DEFAULT_STOP_RATIO = 4
#: fewest decimated points for which the lag-1 autocorrelation identifies a noise type (Riley 2004)
NOISE_ID_MIN_POINTS = 30
#: and the most it uses (a contiguous stretch from the start)
NOISE_ID_MAX_POINTS = 1 << 20


@dataclass(frozen=True)
class _Estimator:
    difference_order: int  # d in Greenhall's notation: 2 Allan, 3 Hadamard
    overlapping: bool
    modified: bool


_ESTIMATORS = {
    "adev": _Estimator(2, False, False),
    "oadev": _Estimator(2, True, False),
    "mdev": _Estimator(2, True, True),
    "tdev": _Estimator(2, True, True),
    "hdev": _Estimator(3, False, False),
    "ohdev": _Estimator(3, True, False),
    "totdev": _Estimator(2, True, False),
}
_BLOCK = 1 << 16


@dataclass(frozen=True)
class AllanMinimum:
    """The smallest deviation of a curve and where it lies."""

    tau_s: float
    deviation: float


@dataclass(frozen=True)
class AllanResult:
    """A deviation curve at a set of averaging times, with 68.3 % confidence intervals.

    Attributes
    ----------
    tau : array
        Averaging times [s].
    deviation : array
        Deviation at each tau, in the unit of the input (e.g. [deg/s]; TDEV in [unit*s]).
    n : array of int
        Number of terms in the estimator's sum at each tau (Stable32's ``#``).
    ci_low, ci_high : array
        Bounds of the confidence interval [unit of ``deviation``]; NaN where no noise type could be
        identified (fewer than 30 points even at the shortest tau).
    alpha : array
        Power-law exponent of the identified noise, S_y(f) ~ f^alpha: 2 white PM (quantization),
        1 flicker PM, 0 white FM (angle random walk), -1 flicker FM (bias instability), -2 random walk
        FM (rate random walk); NaN where none could be identified.
    edf : array
        Equivalent degrees of freedom used for the interval.
    kind : str
        The estimator, e.g. ``"oadev"``.
    confidence : float
        Two-sided confidence of the interval (0.683 by default).
    """

    tau: np.ndarray
    deviation: np.ndarray
    n: np.ndarray
    ci_low: np.ndarray
    ci_high: np.ndarray
    alpha: np.ndarray
    edf: np.ndarray
    kind: str = "oadev"
    confidence: float = ONE_SIGMA

    def minimum(self) -> AllanMinimum:
        """The smallest deviation and the tau [s] where it lies."""
        i = int(np.nanargmin(self.deviation))
        return AllanMinimum(tau_s=float(self.tau[i]), deviation=float(self.deviation[i]))


@dataclass(frozen=True)
class NoiseIdentification:
    """Power-law noise type at one averaging factor, from the lag-1 autocorrelation.

    ``alpha`` is the integer exponent, ``alpha_estimate`` the unrounded value, ``differences`` how
    often the decimated phase was differenced, ``rho`` the lag-1 autocorrelation ratio r1/(1+r1).
    """

    alpha: int
    alpha_estimate: float
    differences: int
    rho: float


def _blocks(count: int, block: int = _BLOCK):
    for start in range(0, count, block):
        yield start, min(start + block, count)


def _mean(data) -> float:
    return float(np.mean(data, dtype=np.float64))


def _running_sum(chunks, mean: float, out: np.ndarray, divisor: float = 1.0) -> np.ndarray:
    """out[0] = 0, out[k] = sum_{i<k} (data[i] - mean) / divisor, chunk by chunk, with a carried total,
    computed in place in ``out`` (no temporary arrays)."""
    out[0] = 0.0
    carry, position = 0.0, 0
    for chunk in chunks:
        size = len(chunk)
        if not size:
            continue
        target = out[position + 1:position + 1 + size]
        np.subtract(chunk, mean, out=target, dtype=np.float64)
        np.cumsum(target, out=target)
        if carry:
            target += carry
        carry = float(target[-1])
        if divisor != 1.0:
            target /= divisor
        position += size
    return out


def to_phase(rate, rate_hz: float, out: np.ndarray | None = None) -> np.ndarray:
    """Integrate rate samples into N+1 phase points [unit*s], mean removed first (as Stable32 does).

    ``rate`` may be any sliceable array, a ``np.memmap`` included; it is read in blocks. ``out``
    (length N+1, e.g. ``np.lib.format.open_memmap(...)``) receives the phase instead of a new array.
    """
    n = len(rate)
    phase = np.empty(n + 1) if out is None else out
    if len(phase) != n + 1:
        raise InputError(f"out: needs {n + 1} elements for {n} rate samples, has {len(phase)}")
    return _running_sum((rate[a:b] for a, b in _blocks(n)), _mean(rate), phase, rate_hz)


def phase_from_chunks(chunks, rate_hz: float, n_samples: int, out: np.ndarray | None = None) -> np.ndarray:
    """Phase [unit*s] of rate data that arrives in chunks (e.g. a Parquet file read row group by row group).

    ``chunks`` is a callable returning a fresh iterator of 1-D arrays; it is called twice, once for the
    mean and once to integrate, so nothing beyond one chunk and ``out`` is held in memory.
    """
    total, count = 0.0, 0
    for chunk in chunks():
        total += float(np.sum(chunk, dtype=np.float64))
        count += len(chunk)
    if count != n_samples:
        raise InputError(f"chunks: delivered {count} samples, expected {n_samples}")
    phase = np.empty(n_samples + 1) if out is None else out
    return _running_sum(chunks(), total / count, phase, rate_hz)


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
    m = m[(m >= 1) & (term_count(kind, n_phase, m) >= 1)]
    if kind == "totdev":
        m = m[m <= n_phase // 2]
    if m.size == 0:
        raise InputError("taus: no tau fits the data (need 1/rate_hz <= tau < duration / 2)")
    return m


def term_count(kind: str, n_phase: int, m):
    """Number of terms in each estimator's sum (Stable32's '#' column)."""
    m = np.asarray(m)
    return {
        "oadev": lambda: n_phase - 2 * m,
        "adev": lambda: (n_phase - 1) // m - 1,
        "mdev": lambda: n_phase - 3 * m + 1,
        "tdev": lambda: n_phase - 3 * m + 1,
        "hdev": lambda: (n_phase - 1) // m - 2,
        "ohdev": lambda: n_phase - 3 * m,
        "totdev": lambda: np.full_like(m, n_phase - 2),
    }[kind]()


# --- sums of squared differences, in blocks -------------------------------------------------------------

def _second_difference_sum(x, m: int, stride: int, count: int, buffer: np.ndarray) -> float:
    """sum over i = 0, stride, ..., of (x[i+2m] - 2 x[i+m] + x[i])^2."""
    total = 0.0
    last = (count - 1) * stride + 1
    step = len(buffer) * stride
    for start in range(0, last, step):
        stop = min(start + step, last)
        d = buffer[:len(range(start, stop, stride))]
        np.add(x[start:stop:stride], x[start + 2 * m:stop + 2 * m:stride], out=d)
        middle = x[start + m:stop + m:stride]
        d -= middle
        d -= middle
        total += float(np.dot(d, d))
    return total


def _third_difference_sum(x, m: int, stride: int, count: int, buffer: np.ndarray, spare: np.ndarray) -> float:
    """sum over i = 0, stride, ..., of (x[i+3m] - 3 x[i+2m] + 3 x[i+m] - x[i])^2."""
    total = 0.0
    last = (count - 1) * stride + 1
    step = len(buffer) * stride
    for start in range(0, last, step):
        stop = min(start + step, last)
        size = len(range(start, stop, stride))
        d, inner = buffer[:size], spare[:size]
        np.subtract(x[start + 3 * m:stop + 3 * m:stride], x[start:stop:stride], out=d)
        np.subtract(x[start + m:stop + m:stride], x[start + 2 * m:stop + 2 * m:stride], out=inner)
        inner *= 3.0
        d += inner
        total += float(np.dot(d, d))
    return total


def _reflected(x, lo: int, hi: int, out: np.ndarray) -> np.ndarray:
    """x*[lo:hi] of the series reflected about both ends (NIST SP 1065 eq. 25): x*[-j] = 2x[0] - x[j],
    x*[n-1+j] = 2x[n-1] - x[n-1-j]."""
    n = len(x)
    out = out[:hi - lo]
    k = 0
    if lo < 0:
        top = min(hi, 0)
        piece = 2.0 * x[0] - np.asarray(x[-lo:-top:-1] if top < 0 else x[-lo:0:-1])
        out[:piece.size] = piece
        k = piece.size
    middle_lo, middle_hi = max(lo, 0), min(hi, n)
    if middle_hi > middle_lo:
        out[k:k + middle_hi - middle_lo] = x[middle_lo:middle_hi]
        k += middle_hi - middle_lo
    if hi > n:
        first = max(lo, n)
        start, stop = 2 * (n - 1) - first, 2 * (n - 1) - hi
        out[k:] = 2.0 * x[n - 1] - np.asarray(x[start:stop:-1] if stop >= 0 else x[start::-1])
    return out


def _total_sum(x, m: int, buffer: np.ndarray, spare: np.ndarray) -> float:
    """sum over i = 1..N-2 of (x*[i-m] - 2 x[i] + x*[i+m])^2 on the doubly reflected series."""
    n = len(x)
    total = 0.0
    for start, stop in _blocks(n - 2, len(buffer)):
        lo, hi = start + 1, stop + 1
        d = _reflected(x, lo - m, hi - m, buffer)
        d += _reflected(x, lo + m, hi + m, spare)
        middle = x[lo:hi]
        d -= middle
        d -= middle
        total += float(np.dot(d, d))
    return total


#: octave levels up to this m are computed together, block by block, from windowed sums kept in cache
_OCTAVE_IN_CACHE_MAX_M = 1 << 16
_OCTAVE_BLOCK = 1 << 19


def _octave_oadev_sums(x, top: int, block: int = _OCTAVE_BLOCK) -> np.ndarray:
    """Overlapping Allan sums for m = 1, 2, 4, ..., top (a power of two) in one pass over x.

    With u_m(i) = x[i+m] - x[i] the second difference is D_m(i) = u_m(i+m) - u_m(i), and the windows
    double by u_2m(i) = u_m(i) + u_m(i+m), so each block of x is read once for every level. Within a
    block, u_1 is centred on its mean (D does not change). The parallelogram law
    sum D_m(i)^2 + sum u_2m(i)^2 = 2 sum u_m(i)^2 + 2 sum u_m(i+m)^2 (i < count) gives each level's sum
    from one BLAS dot product of the next level's window, sum u_2m^2, which is also the next level's
    sum of squares (extended by the few terms past the block); the top level uses
    sum D^2 = sum u(i+m)^2 + sum u(i)^2 - 2 sum u(i) u(i+m). The centring keeps the cancellation in these
    identities at (block / m)^2 rounding units at most.
    """
    n = len(x)
    levels = top.bit_length()
    sums = np.zeros(levels)
    window = block + 2 * top
    first, second = np.empty(min(window, n)), np.empty(min(window, n))  # short series: no 3 MiB buffers
    for start in range(0, n - 2, block):
        current, spare = first, second
        w = np.asarray(x[start:min(start + window, n)], dtype=np.float64)
        length = w.size - 1
        u = current[:length]
        np.subtract(w[1:], w[:-1], out=u)
        u -= u[:min(block, length)].mean()
        known_sum, known_len = 0.0, 0  # sum of u[:known_len]^2, carried from the level before
        m = 1
        for level in range(levels):
            count = min(block, n - 2 * m - start)
            if count <= 0:
                break
            need = count + m
            extra = u[known_len:need]
            squares = known_sum + float(np.dot(extra, extra))
            head, tail = u[:m], u[count:need]
            edges = float(np.dot(head, head)) + float(np.dot(tail, tail))
            last = level + 1 == levels or min(block, n - 4 * m - start) <= 0
            if last:
                sums[level] += 2.0 * squares - edges - 2.0 * float(np.dot(u[:count], u[m:need]))
                break
            length -= m
            np.add(u[:length], u[m:m + length], out=spare[:length])
            current, spare = spare, current
            u = current[:length]
            doubled = float(np.dot(u[:count], u[:count]))
            sums[level] += 2.0 * (2.0 * squares - edges) - doubled
            known_sum, known_len = doubled, count
            m *= 2
    return sums


#: averaging factors with n_phase / m at most this use lag products of the phase (see _lagged_oadev_sums)
_LAGGED_MAX_SPANS = 128


def _prefix_dots(x, lag: int, cuts: list[int]) -> dict[int, float]:
    """P(c) = sum_{j<c} x[j] x[j+lag] at each cut c (sorted, within 0..len(x)-lag), one dot per segment."""
    prefix, total, previous = {}, 0.0, 0
    for cut in cuts:
        if cut > previous:
            total += float(np.dot(x[previous:cut], x[previous + lag:cut + lag]))
            previous = cut
        prefix[cut] = total
    return prefix


def _lagged_oadev_sums(x, ms: np.ndarray) -> np.ndarray:
    """Overlapping Allan sums for long averaging factors from lag products of the phase alone.

    With N = len(x), c = N - 2m, Q(a, b) = sum_{a<=j<b} x_j^2 and L_k(a, b) = sum_{a<=j<b} x_j x_{j+k},
    sum_{i<c} (x_{i+2m} - 2 x_{i+m} + x_i)^2 = Q(2m, N) + 4 Q(m, N-m) + Q(0, c)
                                             - 4 L_m(m, N-m) - 4 L_m(0, c) + 2 L_2m(0, c),
    so each distinct lag (m and 2m; octave factors share them) costs one BLAS dot product over the series,
    with no temporary array. The terms are of the order of N x^2 while the result is of the order of
    N D_m^2; on a phase dominated by a drift that ratio grows like (N/m)^4 / 12, which is why only
    factors with N/m <= _LAGGED_MAX_SPANS come here (relative rounding below ~1e-8).
    """
    n = len(x)
    ms = [int(m) for m in ms]
    squares = _prefix_dots(x, 0, sorted({0, n} | {c for m in ms for c in (m, 2 * m, n - 2 * m, n - m)}))
    cuts: dict[int, set[int]] = {}
    for m in ms:
        cuts.setdefault(m, set()).update((0, m, n - 2 * m, n - m))
        cuts.setdefault(2 * m, set()).update((0, n - 2 * m))
    lagged = {k: _prefix_dots(x, k, sorted(c)) for k, c in cuts.items()}
    sums = np.empty(len(ms))
    for j, m in enumerate(ms):
        c, q, lm, l2m = n - 2 * m, squares, lagged[m], lagged[2 * m]
        sums[j] = ((q[n] - q[2 * m]) + 4.0 * (q[n - m] - q[m]) + q[c]
                   - 4.0 * (lm[n - m] - lm[m]) - 4.0 * lm[c] + 2.0 * l2m[c])
    return sums


def _cumulated(phase) -> np.ndarray:
    """X[k] = sum_{i<k} (x[i] - mean(x)), the running sum the modified variance differences."""
    return _running_sum((phase[a:b] for a, b in _blocks(len(phase))), _mean(phase), np.empty(len(phase) + 1))


def _one_sum(kind: str, phase, cumulated, m: int, count: int) -> float:
    buffer, spare = np.empty(_BLOCK), np.empty(_BLOCK)
    if kind in ("oadev", "adev"):
        return _second_difference_sum(phase, m, 1 if kind == "oadev" else m, count, buffer)
    if kind in ("hdev", "ohdev"):
        return _third_difference_sum(phase, m, 1 if kind == "ohdev" else m, count, buffer, spare)
    if kind == "totdev":
        return _total_sum(phase, m, buffer, spare)
    # sum_{i=j}^{j+m-1} (x[i+2m] - 2x[i+m] + x[i]) is the third difference at stride m of the
    # cumulated phase, so no per-tau O(N) array is needed
    return _third_difference_sum(cumulated, m, 1, count, buffer, spare)


def _octave_chain(ms: np.ndarray, n_phase: int) -> int:
    """How many of ms (sorted) are 1, 2, 4, ... in a row, up to the in-cache limit and short of the
    factors the lag products take."""
    length = 0
    while (length < len(ms) and ms[length] == 1 << length and ms[length] <= _OCTAVE_IN_CACHE_MAX_M
           and ms[length] * _LAGGED_MAX_SPANS < n_phase):
        length += 1
    return length


def _variance_sums(kind: str, phase, ms: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """The sum of squared differences behind each estimator, before its normalization.

    OADEV: octave factors 1, 2, 4, ... in one block-wise pass (_octave_oadev_sums), factors long against
    the series from lag products (_lagged_oadev_sums); everything else term by term in blocks.
    """
    cumulated = _cumulated(phase) if kind in ("mdev", "tdev") else None
    sums = np.zeros(len(ms))
    rest = np.flatnonzero(counts >= 1)
    if kind == "oadev":
        chain = _octave_chain(ms, len(phase))
        if chain >= 2:
            sums[:chain] = _octave_oadev_sums(phase, int(ms[chain - 1]))
            rest = rest[rest >= chain]
        lagged = rest[ms[rest] * _LAGGED_MAX_SPANS >= len(phase)]
        if lagged.size:
            sums[lagged] = np.maximum(_lagged_oadev_sums(phase, ms[lagged]), 0.0)  # rounding below 0 is 0
        rest = np.setdiff1d(rest, lagged)
    for j in rest:
        sums[j] = _one_sum(kind, phase, cumulated, int(ms[j]), int(counts[j]))
    return sums


def _normalize(kind: str, sums: np.ndarray, ms: np.ndarray, tau: np.ndarray, counts: np.ndarray,
               phase_scale: float) -> np.ndarray:
    """Deviations from the sums; ``phase_scale`` is what the phase was multiplied by (rate_hz for rate
    data integrated in samples, see _as_phase)."""
    scaled_tau = tau * phase_scale
    with np.errstate(invalid="ignore", divide="ignore"):
        if kind in ("oadev", "adev", "totdev"):
            var = sums / (2.0 * scaled_tau ** 2 * counts)
        elif kind in ("hdev", "ohdev"):
            var = sums / (6.0 * scaled_tau ** 2 * counts)
        else:
            var = sums / (2.0 * ms.astype(float) ** 2 * scaled_tau ** 2 * counts)
        dev = np.sqrt(np.where(counts > 0, var, np.nan))
    if kind == "tdev":
        dev = tau * dev / np.sqrt(3.0)  # time deviation [unit*s]: tau / sqrt(3) * MDEV
    return dev


# --- noise identification ------------------------------------------------------------------------------

def _trend_gram(length: int) -> np.ndarray:
    """sum_k u^(p+q), p, q = 0..2, for u = 2k/(L-1) - 1, k = 0..L-1 (exact power sums of k, then rescaled)."""
    n = length
    power_sums = [n, n * (n - 1) // 2, (n - 1) * n * (2 * n - 1) // 6, (n * (n - 1) // 2) ** 2,
                  (n - 1) * n * (2 * n - 1) * (3 * (n - 1) ** 2 + 3 * (n - 1) - 1) // 30]
    scale = 2.0 / (n - 1)
    u_sums = [sum(math.comb(p, j) * scale ** j * (-1.0) ** (p - j) * power_sums[j]
                  for j in range(p + 1)) for p in range(5)]
    return np.array([[u_sums[p + q] for q in range(3)] for p in range(3)])


def _quadratic_trend(x) -> np.ndarray:
    """Least-squares coefficients of c0 + c1 u + c2 u^2, u = 2k/(L-1) - 1, fitted to x[k], in blocks."""
    length = len(x)
    moments = np.zeros(3)
    scale = 2.0 / (length - 1)
    steps = np.arange(_BLOCK) * scale
    for start, stop in _blocks(length):
        block = np.asarray(x[start:stop], dtype=np.float64)
        u = steps[:stop - start] + (start * scale - 1.0)
        ux = u * block
        moments += (block.sum(), ux.sum(), np.dot(u, ux))
    return np.linalg.solve(_trend_gram(length), moments)


def _lag1_autocorrelations(x, trend: np.ndarray, max_differences: int) -> list[float]:
    """Lag-1 autocorrelation of the residual of x about its quadratic trend, differenced 0..max times."""
    length = len(x)
    scale = 2.0 / (length - 1)
    steps = np.arange(_BLOCK + max_differences + 1) * scale
    sums = np.zeros((max_differences + 1, 5))  # per d: sum, sum of squares, lag-1 products, first, last
    for start, stop in _blocks(length):
        hi = min(stop + max_differences + 1, length)  # overlap, to pair and difference across blocks
        u = steps[:hi - start] + (start * scale - 1.0)
        z = np.asarray(x[start:hi], dtype=np.float64) - (trend[0] + u * (trend[1] + u * trend[2]))
        for d in range(max_differences + 1):
            size = length - d
            own = z[:min(stop, size) - start]
            if own.size:
                paired = z[:min(stop + 1, size) - start]
                row = sums[d]
                row[0] += own.sum()
                row[1] += np.dot(own, own)
                row[2] += np.dot(paired[:-1], paired[1:])
                if start == 0:
                    row[3] = own[0]
                row[4] = own[-1]
            z = z[1:] - z[:-1]
    result = []
    for d, (s1, s2, pairs, first, last) in enumerate(sums):
        size = length - d
        mean = s1 / size
        numerator = pairs - mean * (2.0 * s1 - first - last) + (size - 1) * mean * mean
        denominator = s2 - size * mean * mean
        result.append(numerator / denominator if denominator > 0 else math.nan)
    return result


def identify_noise(phase, m: int, *, max_differences: int = 2) -> NoiseIdentification | None:
    """Power-law noise type of phase data at averaging factor m, by the lag-1 autocorrelation.

    The phase is decimated by m, its quadratic trend removed, and it is differenced until the
    autocorrelation ratio rho = r1 / (1 + r1) falls below 0.25 (or ``max_differences`` is reached);
    then alpha = 2 - 2 (rho + d), rounded (Riley and Greenhall 2004). Returns None with fewer than
    30 decimated points. At most the first 2^20 decimated points are used: the lag-1 estimate's
    standard error there (1e-3) is far inside the rounding margin, and no reference series is longer.
    """
    x = phase[:NOISE_ID_MAX_POINTS * m:m]
    if len(x) < NOISE_ID_MIN_POINTS:
        return None
    correlations = _lag1_autocorrelations(x, _quadratic_trend(x), max_differences)
    for d, r1 in enumerate(correlations):
        if math.isnan(r1):
            return None  # a constant (or exactly polynomial) series has no noise type
        rho = r1 / (1.0 + r1)
        if rho < 0.25 or d == max_differences:
            break
    estimate = 2.0 - 2.0 * (rho + d)
    return NoiseIdentification(alpha=int(2 - np.round(2.0 * rho) - 2 * d), alpha_estimate=estimate,
                               differences=d, rho=rho)


# --- equivalent degrees of freedom and intervals ----------------------------------------------------------

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
_TABLE1 = [[(2 / 3, 1 / 3), (7 / 9, 1 / 2), (22 / 25, 2 / 3)],
           [(0.840, 0.345), (0.997, 0.616), (1.141, 0.843)],
           [(1.079, 0.368), (1.033, 0.607), (1.184, 0.848)],
           [None, (1.048, 0.534), (1.180, 0.816)],
           [None, (1.302, 0.535), (1.175, 0.777)],
           [None, None, (1.194, 0.703)],
           [None, None, (1.489, 0.702)]]
_TABLE2 = [[(3 / 2, 1 / 2), (35 / 18, 1.0), (231 / 100, 3 / 2)],
           [(78.6, 25.2), (790.0, 410.0), (9950.0, 6520.0)],
           [(2 / 3, 1 / 6), (2 / 3, 1 / 3), (7 / 9, 1 / 2)],
           [None, (0.852, 0.375), (0.997, 0.617)],
           [None, (1.079, 0.368), (1.033, 0.607)],
           [None, None, (1.053, 0.553)],
           [None, None, (1.302, 0.535)]]
_TABLE3 = {1: (6.0, 4.0), 2: (15.23, 12.0), 3: (47.8, 40.0)}
_J_MAX = 100


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
    spec = _ESTIMATORS[kind]
    return edf_greenhall(alpha, spec.difference_order, m, n_phase,
                         overlapping=spec.overlapping, modified=spec.modified)


def _noise_types(kind: str, phase, ms: np.ndarray) -> np.ndarray:
    """alpha at each m; where too few points remain, the last identified type is carried forward."""
    spec = _ESTIMATORS[kind]
    lowest = 2 - 2 * spec.difference_order  # alpha + 2d > 1
    found = [identify_noise(phase, int(m), max_differences=spec.difference_order) for m in ms]
    alphas = np.full(len(ms), np.nan)
    current = math.nan
    for j, identified in enumerate(found):
        if identified is not None:
            current = float(min(2, max(lowest, identified.alpha)))
        alphas[j] = current
    return alphas


def _degrees_of_freedom(kind: str, alphas: np.ndarray, ms: np.ndarray, n_phase: int) -> np.ndarray:
    return np.array([math.nan if math.isnan(a) else _edf(kind, int(a), int(m), n_phase)
                     for a, m in zip(alphas, ms)])


def _check(kind: str, rate_hz: float, data_type: str) -> None:
    if kind not in KINDS:
        raise InputError(f"kind: unknown Allan estimator {kind!r}; use one of {', '.join(KINDS)}")
    if not rate_hz > 0:
        raise InputError(f"rate_hz: must be positive, got {rate_hz}")
    if data_type not in ("rate", "phase"):
        raise InputError(f"data_type: {data_type!r}; use 'rate' or 'phase'")


def _as_phase(data, rate_hz: float, data_type: str, phase_out) -> tuple[np.ndarray, float]:
    """The phase and the factor it carries: rate data is summed without the division by rate_hz (one
    pass fewer over the data; the deviations do not depend on it), so its phase is in [unit*samples]."""
    if data_type == "rate":
        if np.ndim(data) != 1:
            raise InputError("data: need a one-dimensional series")
        phase, scale = to_phase(data, 1.0, out=phase_out), rate_hz
    else:
        phase, scale = (data if isinstance(data, np.ndarray) else np.asarray(data, dtype=float)), 1.0
    if phase.ndim != 1 or phase.size < 3:
        raise InputError("data: need a one-dimensional series of at least 3 phase points")
    return phase, scale


def allan_deviation(data, rate_hz: float, *, kind: str = "oadev", taus="octave", data_type: str = "rate",
                    confidence: float | None = ONE_SIGMA, phase_out: np.ndarray | None = None) -> AllanResult:
    """Allan deviation of ``data`` sampled at ``rate_hz``, with confidence intervals.

    Parameters
    ----------
    data : array (n,)
        Rate samples (e.g. [deg/s]) or, with ``data_type="phase"``, integrated angle samples (e.g. [deg]).
        A ``np.memmap`` is read in blocks.
    rate_hz : float
        Sample rate [Hz].
    kind : {"oadev", "adev", "mdev", "tdev", "hdev", "ohdev", "totdev"}
        Estimator: overlapping Allan (default), Allan, modified Allan, time deviation (tau/sqrt(3) MDEV,
        in [unit*s]), Hadamard, overlapping Hadamard, total deviation (NIST SP 1065, section 5.2).
    taus : {"octave", "decade", "all"} or array
        Averaging times: m = 1, 2, 4, ...; m = 1, 2, 4, 10, 20, 40, ...; every m; or taus [s].
    data_type : {"rate", "phase"}
    confidence : float or None
        Two-sided confidence of ``ci_low``/``ci_high`` (default one sigma, 0.683). None skips the noise
        identification and the intervals (``ci_low``, ``ci_high``, ``alpha``, ``edf`` are NaN).
    phase_out : array (n+1,), optional
        Where to put the integrated rate data, e.g. a memory-mapped file for data larger than memory; by
        default a new array. It receives the running sum of the rate minus its mean [unit*samples], i.e.
        the phase times ``rate_hz``.
    """
    _check(kind, rate_hz, data_type)
    phase, scale = _as_phase(data, rate_hz, data_type, phase_out)
    ms = averaging_factors(phase.size, taus, rate_hz, kind)
    tau = ms / rate_hz
    counts = term_count(kind, phase.size, ms)
    deviation = _normalize(kind, _variance_sums(kind, phase, ms, counts), ms, tau, counts, scale)
    if confidence is None:
        alphas = np.full(len(ms), np.nan)
        edf = alphas.copy()
    else:
        alphas = _noise_types(kind, phase, ms)
        edf = _degrees_of_freedom(kind, alphas, ms, phase.size)
    low, high = confidence_interval(deviation, edf, ONE_SIGMA if confidence is None else confidence)
    return AllanResult(tau=tau, deviation=deviation, n=counts, ci_low=low, ci_high=high, alpha=alphas,
                       edf=edf, kind=kind, confidence=math.nan if confidence is None else confidence)


def allan_deviation_segments(segments: Iterable, rate_hz: float, *, kind: str = "oadev", taus="octave",
                             data_type: str = "rate", confidence: float | None = ONE_SIGMA) -> AllanResult:
    """One deviation curve from several contiguous stretches of data separated by gaps.

    The sums of squared differences and their term counts are pooled over the stretches, so no term
    spans a gap; the degrees of freedom add. The noise type comes from the longest stretch. The named
    tau grids follow the longest stretch. TOTDEV's reflected series has no pooled form. ``confidence``
    None skips the noise identification and the intervals, as in :func:`allan_deviation`.
    """
    _check(kind, rate_hz, data_type)
    if kind == "totdev":
        raise InputError("kind: totdev cannot pool stretches separated by gaps; use oadev, or one stretch")
    shortest = 3 if data_type == "phase" else 2
    integrated = [_as_phase(s, rate_hz, data_type, None) for s in segments if len(s) >= shortest]
    if not integrated:
        raise InputError("data: no stretch has enough samples")
    phases, scale = [phase for phase, _ in integrated], integrated[0][1]
    longest = max(phases, key=len)
    ms = averaging_factors(longest.size, taus, rate_hz, kind)
    tau = ms / rate_hz
    sums, counts, edf = np.zeros(len(ms)), np.zeros(len(ms), dtype=np.int64), np.zeros(len(ms))
    alphas = _noise_types(kind, longest, ms) if confidence is not None else np.full(len(ms), np.nan)
    for phase in phases:
        own = np.maximum(term_count(kind, phase.size, ms), 0)
        sums += _variance_sums(kind, phase, ms, own)
        counts += own
        if confidence is not None:
            own_edf = _degrees_of_freedom(kind, alphas, ms, phase.size)
            edf += np.where((own > 0) & np.isfinite(own_edf), own_edf, 0.0)
    edf = np.where(np.isnan(alphas), np.nan, edf)
    deviation = _normalize(kind, sums, ms, tau, counts, scale)
    low, high = confidence_interval(deviation, edf, ONE_SIGMA if confidence is None else confidence)
    return AllanResult(tau=tau, deviation=deviation, n=counts, ci_low=low, ci_high=high, alpha=alphas,
                       edf=edf, kind=kind, confidence=math.nan if confidence is None else confidence)


# --- IEEE Std 952 noise terms ----------------------------------------------------------------------------

#: the flicker (bias instability) floor of the Allan deviation is B sqrt(2 ln2 / pi) = 0.664 B
BIAS_INSTABILITY_FACTOR = math.sqrt(2.0 * math.log(2.0) / math.pi)
#: how far a local log-log slope may be from -1/2 (or +1/2) for a read-off on that line
READOFF_SLOPE_TOLERANCE = 0.25
#: relative uncertainty in variance below which no point of the curve is weighted in the noise fit
MODEL_UNCERTAINTY = 0.1


@dataclass(frozen=True)
class NoiseTerms:
    """The five IEEE Std 952 (Annex C) terms in the unit u of the data (u = deg/s for gyros, g for
    accelerometers), and the read-offs users compare them with.

    Attributes
    ----------
    quantization : float
        Q [u*s], from 3 Q^2 / tau^2.
    white_noise_density : float
        N [u/sqrt(Hz)] (= u*sqrt(s)), from N^2 / tau.
    bias_instability : float
        B [u]: the Allan minimum / 0.664 (the definition the thesis and datasheets use).
    integration_time_s : float
        tau at that minimum [s].
    random_walk : float
        K [u*sqrt(Hz)] (= u/sqrt(s)), from K^2 tau / 3.
    ramp : float
        R [u/s], from R^2 tau^2 / 2.
    bias_instability_fit : float
        B [u] from the weighted least-squares fit of the five-term model.
    white_noise_readoff, random_walk_readoff : float or None
        N read on the -1/2 line at tau = 1 s and K on the +1/2 line at tau = 3 s, through the point whose
        local slope is closest to the line's (None when no slope is within 0.25 of it).
    floor_reached : bool
        False when the smallest deviation is at the longest tau, so B is only an upper bound.
    fit_rms_log_residual : float
        RMS of ln(model deviation / measured deviation) over the fitted taus: 0.1 is a 10 % misfit.
    """

    quantization: float
    white_noise_density: float
    bias_instability: float
    integration_time_s: float
    random_walk: float
    ramp: float
    bias_instability_fit: float
    white_noise_readoff: float | None
    random_walk_readoff: float | None
    floor_reached: bool
    fit_rms_log_residual: float

    def model_deviation(self, tau_s) -> np.ndarray:
        """The fitted five-term model's deviation at ``tau_s`` [s], in the data's unit."""
        coefficients = np.array([self.quantization, self.white_noise_density, self.bias_instability_fit,
                                 self.random_walk, self.ramp]) ** 2
        return np.sqrt(_model_basis(np.asarray(tau_s, dtype=float)) @ coefficients)


@dataclass(frozen=True)
class GyroNoise:
    """Gyro noise parameters in the units they are quoted in (see :class:`NoiseTerms`)."""

    noise_density_dps_per_sqrt_hz: float
    arw_deg_per_sqrt_h: float
    bias_instability_deg_per_h: float
    integration_time_s: float
    rrw_deg_per_h_per_sqrt_h: float
    rrw_dps_sqrt_hz: float
    quantization_deg: float
    rate_ramp_deg_per_h2: float
    bias_instability_fit_deg_per_h: float
    noise_density_readoff_dps_per_sqrt_hz: float | None
    rrw_readoff_deg_per_h_per_sqrt_h: float | None
    floor_reached: bool
    fit_rms_log_residual: float

    #: the keys of ``gyrocomp allan --json``
    SUMMARY_KEYS = ("noise_density_dps_per_sqrt_hz", "arw_deg_per_sqrt_h", "bias_instability_deg_per_h",
                    "integration_time_s", "rrw_deg_per_h_per_sqrt_h", "quantization_deg", "rate_ramp_deg_per_h2")

    @classmethod
    def from_terms(cls, t: NoiseTerms) -> "GyroNoise":
        """Convert terms of [deg/s] data."""
        readoff_k = None if t.random_walk_readoff is None else t.random_walk_readoff * 216000.0
        return cls(
            noise_density_dps_per_sqrt_hz=t.white_noise_density,
            arw_deg_per_sqrt_h=t.white_noise_density * 60.0,
            bias_instability_deg_per_h=t.bias_instability * 3600.0,
            integration_time_s=t.integration_time_s,
            rrw_deg_per_h_per_sqrt_h=t.random_walk * 216000.0,  # 3600 [deg/h per deg/s] * 60 [sqrt(s/h)]
            rrw_dps_sqrt_hz=t.random_walk,
            quantization_deg=t.quantization,
            rate_ramp_deg_per_h2=t.ramp * 3600.0 ** 2,
            bias_instability_fit_deg_per_h=t.bias_instability_fit * 3600.0,
            noise_density_readoff_dps_per_sqrt_hz=t.white_noise_readoff,
            rrw_readoff_deg_per_h_per_sqrt_h=readoff_k,
            floor_reached=t.floor_reached,
            fit_rms_log_residual=t.fit_rms_log_residual,
        )

    def summary(self) -> dict:
        return {k: getattr(self, k) for k in self.SUMMARY_KEYS}


@dataclass(frozen=True)
class AccelNoise:
    """Accelerometer noise parameters in the units they are quoted in (see :class:`NoiseTerms`)."""

    noise_density_g_per_sqrt_hz: float
    vrw_m_per_s_per_sqrt_h: float
    bias_instability_micro_g: float
    integration_time_s: float
    random_walk_m_per_s3_per_sqrt_hz: float
    quantization_m_per_s: float
    ramp_m_per_s3: float
    bias_instability_fit_micro_g: float
    noise_density_readoff_g_per_sqrt_hz: float | None
    random_walk_readoff_m_per_s3_per_sqrt_hz: float | None
    floor_reached: bool
    fit_rms_log_residual: float

    SUMMARY_KEYS = ("noise_density_g_per_sqrt_hz", "vrw_m_per_s_per_sqrt_h", "bias_instability_micro_g",
                    "integration_time_s", "random_walk_m_per_s3_per_sqrt_hz", "quantization_m_per_s",
                    "ramp_m_per_s3")

    @classmethod
    def from_terms(cls, t: NoiseTerms) -> "AccelNoise":
        """Convert terms of [g] data."""
        g = STANDARD_GRAVITY_M_PER_S2
        return cls(
            noise_density_g_per_sqrt_hz=t.white_noise_density,
            vrw_m_per_s_per_sqrt_h=t.white_noise_density * g * 60.0,
            bias_instability_micro_g=t.bias_instability * 1e6,
            integration_time_s=t.integration_time_s,
            random_walk_m_per_s3_per_sqrt_hz=t.random_walk * g,
            quantization_m_per_s=t.quantization * g,
            ramp_m_per_s3=t.ramp * g,
            bias_instability_fit_micro_g=t.bias_instability_fit * 1e6,
            noise_density_readoff_g_per_sqrt_hz=t.white_noise_readoff,
            random_walk_readoff_m_per_s3_per_sqrt_hz=None if t.random_walk_readoff is None
            else t.random_walk_readoff * g,
            floor_reached=t.floor_reached,
            fit_rms_log_residual=t.fit_rms_log_residual,
        )

    def summary(self) -> dict:
        return {k: getattr(self, k) for k in self.SUMMARY_KEYS}


def _model_basis(tau: np.ndarray) -> np.ndarray:
    """Columns of sigma^2(tau) = 3Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2."""
    return np.stack([3.0 / tau ** 2, 1.0 / tau, np.full_like(tau, BIAS_INSTABILITY_FACTOR ** 2),
                     tau / 3.0, tau ** 2 / 2.0], axis=1)


def _readoff(tau: np.ndarray, dev: np.ndarray, slope: float) -> tuple[float, float] | None:
    """(tau, deviation) of the point whose local log-log slope is closest to ``slope``."""
    if tau.size < 3:
        return None
    log_tau, log_dev = np.log(tau), np.log(dev)
    local = np.gradient(log_dev, log_tau)
    i = int(np.argmin(np.abs(local - slope)))
    if abs(local[i] - slope) > READOFF_SLOPE_TOLERANCE:
        return None
    return float(tau[i]), float(dev[i])


def noise_terms(result: AllanResult, fit_taus_s: tuple[float, float] | None = None) -> NoiseTerms:
    """IEEE Std 952 noise terms of an overlapping (or plain) Allan deviation curve.

    The five-term model sigma^2(tau) = 3Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2
    is fitted with non-negative coefficients by weighted least squares (scipy NNLS), each point weighted
    by the half-width of its confidence interval in variance (IEEE Std 952-1997, Annex C; the thesis,
    section 2). B itself is the minimum deviation / 0.664, at the integration time where it lies.

    ``fit_taus_s = (low, high)`` [s] restricts the fit (not the minimum or the read-offs) to those taus,
    e.g. to leave out the short taus an anti-alias filter has flattened.
    """
    if result.kind not in ("oadev", "adev"):
        raise InputError(f"kind: noise terms need an Allan deviation (oadev or adev), not {result.kind}")
    finite = np.isfinite(result.deviation) & (result.n >= 1)
    if finite.sum() >= 2 and not np.any(result.deviation[finite] > 0):
        return NoiseTerms(0.0, 0.0, 0.0, float(result.tau[finite][0]), 0.0, 0.0, 0.0, None, None, False, 0.0)
    good = finite & (result.deviation > 0)
    if good.sum() < 2:
        raise InputError("data: too short for noise terms; need at least two averaging times")
    fitted = good.copy()
    if fit_taus_s is not None:
        fitted &= (result.tau >= fit_taus_s[0]) & (result.tau <= fit_taus_s[1])
        if fitted.sum() < 2:
            raise InputError(f"fit_taus_s: fewer than two taus between {fit_taus_s[0]:g} and {fit_taus_s[1]:g} s")
    tau, dev = result.tau[fitted], result.deviation[fitted]
    variance = dev ** 2
    half_width = (result.ci_high[fitted] ** 2 - result.ci_low[fitted] ** 2) / 2.0
    fallback = variance * np.sqrt(2.0 / np.maximum(result.n[fitted], 1))
    half_width = np.where(np.isfinite(half_width) & (half_width > 0), half_width, fallback)
    # the five-term model is itself an idealization (anti-alias filters, the flicker floor's shape), so no
    # point is trusted beyond MODEL_UNCERTAINTY in variance; otherwise the tightest short-tau points
    # would dictate the whole fit
    half_width = np.maximum(half_width, MODEL_UNCERTAINTY * variance)
    basis = _model_basis(tau) / half_width[:, None]
    scale = np.linalg.norm(basis, axis=0)
    from scipy.optimize import nnls  # scipy.optimize is slow to import; only the noise terms need it

    solution, _ = nnls(basis / scale, variance / half_width)
    q2, n2, b2, k2, r2 = coefficients = solution / scale
    with np.errstate(divide="ignore"):
        misfit = float(np.sqrt(np.mean(np.log(_model_basis(tau) @ coefficients / variance) ** 2)) / 2.0)
    tau, dev = result.tau[good], result.deviation[good]
    lowest = int(np.argmin(dev))
    white = _readoff(tau, dev, -0.5)
    walk = _readoff(tau, dev, 0.5)
    return NoiseTerms(
        quantization=math.sqrt(q2),
        white_noise_density=math.sqrt(n2),
        bias_instability=float(dev[lowest]) / BIAS_INSTABILITY_FACTOR,
        integration_time_s=float(tau[lowest]),
        random_walk=math.sqrt(k2),
        ramp=math.sqrt(r2),
        bias_instability_fit=math.sqrt(b2),
        white_noise_readoff=None if white is None else white[1] * math.sqrt(white[0]),
        random_walk_readoff=None if walk is None else walk[1] * math.sqrt(3.0 / walk[0]),
        floor_reached=lowest < tau.size - 1,
        fit_rms_log_residual=misfit,
    )


def noise_parameters(result: AllanResult, sensor: str = "gyro",
                     fit_taus_s: tuple[float, float] | None = None) -> GyroNoise | AccelNoise:
    """Noise parameters of a gyro curve in [deg/s] (``sensor="gyro"``) or an accelerometer curve in [g]."""
    terms = noise_terms(result, fit_taus_s)
    if sensor == "gyro":
        return GyroNoise.from_terms(terms)
    if sensor == "accel":
        return AccelNoise.from_terms(terms)
    raise InputError(f"sensor: {sensor!r}; use 'gyro' or 'accel'")
