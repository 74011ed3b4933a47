"""Allan-family estimators of rate (or phase) data: phase integration, tau grids, sums of differences.

The overlapping Allan variance of rate samples y_i taken every tau0 = 1/rate_hz, with phase
x_0 = 0, x_{i+1} = x_i + y_i tau0 (N phase points), at tau = m tau0 is

    sigma^2(tau) = sum_{i=0}^{N-2m-1} (x_{i+2m} - 2 x_{i+m} + x_i)^2 / (2 tau^2 (N - 2m))

(IEEE Std 952-1997 Annex C; W. Riley, *Handbook of Frequency Stability Analysis*, NIST SP 1065, eq. 11).
The other estimators (ADEV, MDEV, TDEV, HDEV, OHDEV, TOTDEV) follow the same handbook.

Every sum is evaluated in blocks or as dot products of views, so the working memory beyond the phase
array stays about 10 MiB. The overlapping Allan sums have two fast paths: octave factors 1, 2, 4, ... in
one cache-resident pass per block, and factors long against the series (N/m <= 128) from lag products.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal, get_args

import numpy as np

from ..errors import InputError

#: two-sided confidence of one standard deviation, erf(1/sqrt(2)) = 0.6827
ONE_SIGMA = math.erf(1.0 / math.sqrt(2.0))
#: the deviations the engine computes (NIST SP 1065 names)
AllanKind = Literal["oadev", "adev", "mdev", "tdev", "hdev", "ohdev", "totdev"]
KINDS: tuple[str, ...] = get_args(AllanKind)
#: the named grids of averaging times: m = 1, 2, 4, ...; 1, 2, 4, 10, 20, 40, ...; every m
TauGrid = Literal["octave", "decade", "all"]
#: what the data are: rate samples, or their integral (phase)
DataType = Literal["rate", "phase"]
#: Stable32 stops its tau grids at N / stop ratio (N phase points)
STOP_RATIO = {"adev": 5, "hdev": 5, "totdev": 2}
DEFAULT_STOP_RATIO = 4


@dataclass(frozen=True)
class _Estimator:
    difference_order: int  # d in Greenhall's notation: 2 Allan, 3 Hadamard
    overlapping: bool
    modified: bool


#: the difference order and the averaging of each estimator, by its name
ESTIMATORS = {
    "adev": _Estimator(2, False, False),
    "oadev": _Estimator(2, True, False),
    "mdev": _Estimator(2, True, True),
    "tdev": _Estimator(2, True, True),
    "hdev": _Estimator(3, False, False),
    "ohdev": _Estimator(3, True, False),
    "totdev": _Estimator(2, True, False),
}
#: samples per block of the block-wise sums (bounds their temporary memory)
BLOCK_SAMPLES = 1 << 16


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
        identified (a series without variation, or fewer than 3 averages at every tau).
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
    noise_method : tuple of str
        What decided each tau's noise type: ``lag-1`` (the lag-1 autocorrelation), ``B1/R(n)`` (below 30
        points), ``R(n) ...`` (R(n) of the whole series overruled a lag-1 phase-noise type found on few points),
        ``carried`` (the next shorter tau's), ``given`` (``noise_alpha``), ``""`` (none).
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
    noise_method: tuple[str, ...] = ()

    def minimum(self) -> AllanMinimum:
        """The smallest deviation and the tau [s] where it lies."""
        i = int(np.nanargmin(self.deviation))
        return AllanMinimum(tau_s=float(self.tau[i]), deviation=float(self.deviation[i]))


def _blocks(count: int, block: int = BLOCK_SAMPLES):
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
        target = out[position + 1 : position + 1 + size]
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


def averaging_factors(
    n_phase: int, taus: TauGrid | np.ndarray, rate_hz: float, kind: AllanKind = "oadev"
) -> np.ndarray:
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


def second_difference_sum(x, m: int, stride: int, count: int, buffer: np.ndarray) -> float:
    """sum over i = 0, stride, ..., of (x[i+2m] - 2 x[i+m] + x[i])^2."""
    total = 0.0
    last = (count - 1) * stride + 1
    step = len(buffer) * stride
    for start in range(0, last, step):
        stop = min(start + step, last)
        d = buffer[: len(range(start, stop, stride))]
        np.add(x[start:stop:stride], x[start + 2 * m : stop + 2 * m : stride], out=d)
        middle = x[start + m : stop + m : stride]
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
        np.subtract(x[start + 3 * m : stop + 3 * m : stride], x[start:stop:stride], out=d)
        np.subtract(x[start + m : stop + m : stride], x[start + 2 * m : stop + 2 * m : stride], out=inner)
        inner *= 3.0
        d += inner
        total += float(np.dot(d, d))
    return total


def _reflected(x, lo: int, hi: int, out: np.ndarray) -> np.ndarray:
    """x*[lo:hi] of the series reflected about both ends (NIST SP 1065 eq. 25): x*[-j] = 2x[0] - x[j],
    x*[n-1+j] = 2x[n-1] - x[n-1-j]."""
    n = len(x)
    out = out[: hi - lo]
    k = 0
    if lo < 0:
        top = min(hi, 0)
        piece = 2.0 * x[0] - np.asarray(x[-lo:-top:-1] if top < 0 else x[-lo:0:-1])
        out[: piece.size] = piece
        k = piece.size
    middle_lo, middle_hi = max(lo, 0), min(hi, n)
    if middle_hi > middle_lo:
        out[k : k + middle_hi - middle_lo] = x[middle_lo:middle_hi]
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
#: the short levels (m up to _OCTAVE_SHORT_MAX_M) go block by block in blocks of _OCTAVE_SHORT_BLOCK, whose two
#: buffers stay in a core's L2 cache; the long ones come from lag products of detrended windows of the phase
#: (_windowed_oadev_sums), whose cost is one pass to detrend a window and one dot product per lag. Measured at
#: 1e7 samples (the octave levels up to 2^16, one process): 0.131 s split at m = 2^13, 0.119 s at 2^12, 0.113 s at
#: 2^11 (the four levels 2^13..2^16 alone: 0.056 s as a chain of windows in 2^19-sample blocks, 0.038 s from lag
#: products).
_OCTAVE_SHORT_MAX_M = 1 << 11
_OCTAVE_SHORT_BLOCK = 1 << 16


def _octave_oadev_sums(x, top: int, block: int | None = None) -> np.ndarray:
    """Overlapping Allan sums for m = 1, 2, 4, ..., top (a power of two): the short factors in small blocks
    (:func:`_octave_level_sums`), the long ones from lag products of detrended windows
    (:func:`_windowed_oadev_sums`); ``block`` forces the block-wise levels for all, in blocks of that size."""
    if block is not None:
        return _octave_level_sums(x, top, block)
    if top <= _OCTAVE_SHORT_MAX_M:
        return _octave_level_sums(x, top, _OCTAVE_SHORT_BLOCK)
    short = _octave_level_sums(x, _OCTAVE_SHORT_MAX_M, _OCTAVE_SHORT_BLOCK)
    long = 2 * _OCTAVE_SHORT_MAX_M << np.arange(top.bit_length() - _OCTAVE_SHORT_MAX_M.bit_length())
    return np.concatenate([short, _windowed_oadev_sums(x, long)])


def _octave_level_sums(x, top: int, block: int) -> np.ndarray:
    """Overlapping Allan sums for m = 1, 2, 4, ..., top (powers of two) in one pass over x.

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
    buffers = np.empty(min(window, n)), np.empty(min(window, n))  # short series: no 3 MiB buffers
    for start in range(0, n - 2, block):
        current, spare = buffers
        w = np.asarray(x[start : min(start + window, n)], dtype=np.float64)
        length = w.size - 1
        u = current[:length]
        np.subtract(w[1:], w[:-1], out=u)
        u -= u[: min(block, length)].mean()
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
            np.add(u[:length], u[m : m + length], out=spare[:length])
            current, spare = spare, current
            u = current[:length]
            doubled = float(np.dot(u[:count], u[:count]))
            sums[level] += 2.0 * (2.0 * squares - edges) - doubled
            known_sum, known_len = doubled, count
            m *= 2
    return sums


#: averaging factors with n_phase / m at most this use lag products of the phase (see _lagged_oadev_sums)
_LAGGED_MAX_SPANS = 128


def _prefix_dots(x, cuts: dict[int, set[int]], block: int = BLOCK_SAMPLES) -> dict[int, dict[int, float]]:
    """P_k(c) = sum_{j<c} x[j] x[j+k] at each cut c (within 0..len(x)-k) of each lag k, in one pass over x in
    blocks: a block of x stays in cache while each lag's partner streams past it (measured at 1e7 points and 7
    lags: 0.022 s, against 0.031 s for one dot product per lag over the whole series)."""
    n = len(x)
    ordered = {k: sorted(c) for k, c in cuts.items()}
    prefix: dict[int, dict[int, float]] = {k: {} for k in cuts}
    totals, next_cut = dict.fromkeys(cuts, 0.0), dict.fromkeys(cuts, 0)
    for a in range(0, n, block):
        for k, cs in ordered.items():
            start, end, i = a, min(a + block, n - k), next_cut[k]
            while start < end:
                while i < len(cs) and cs[i] <= start:
                    prefix[k][cs[i]] = totals[k]
                    i += 1
                stop = min(end, cs[i]) if i < len(cs) else end
                totals[k] += float(np.dot(x[start:stop], x[start + k : stop + k]))
                start = stop
            next_cut[k] = i
    for k, cs in ordered.items():
        for c in cs[next_cut[k] :]:
            prefix[k][c] = totals[k]
    return prefix


def _lag_combination_sums(x, ms: list[int], counts: list[int]) -> np.ndarray:
    """sum_{i<c} (x_{i+2m} - 2 x_{i+m} + x_i)^2 for each m in ms and its count c (c <= len(x) - 2m; c <= 0
    gives 0) from lag products of x: with Q(a, b) = sum_{a<=j<b} x_j^2 and L_k(a, b) = sum_{a<=j<b} x_j x_{j+k},
    the sum is Q(2m, c+2m) + 4 Q(m, c+m) + Q(0, c) - 4 L_m(m, c+m) - 4 L_m(0, c) + 2 L_2m(0, c), so each
    distinct lag (m and 2m; octave factors share them) costs one BLAS dot product over x (all lags in one pass,
    :func:`_prefix_dots`), with no temporary array. The terms are of the order of c x^2 while the result is of
    the order of c D_m^2: the caller keeps that ratio small."""
    cuts: dict[int, set[int]] = {0: {0}}
    for m, c in zip(ms, counts):
        if c > 0:
            cuts[0].update((0, m, 2 * m, c, c + m, c + 2 * m))
            cuts.setdefault(m, set()).update((0, m, c, c + m))
            cuts.setdefault(2 * m, set()).update((0, c))
    lagged = _prefix_dots(x, cuts)
    sums = np.zeros(len(ms))
    for j, (m, c) in enumerate(zip(ms, counts)):
        if c > 0:
            q, lm, l2m = lagged[0], lagged[m], lagged[2 * m]
            sums[j] = (
                (q[c + 2 * m] - q[2 * m])
                + 4.0 * (q[c + m] - q[m])
                + q[c]
                - 4.0 * (lm[c + m] - lm[m])
                - 4.0 * lm[c]
                + 2.0 * l2m[c]
            )
    return sums


def _lagged_oadev_sums(x, ms: np.ndarray) -> np.ndarray:
    """Overlapping Allan sums for long averaging factors from lag products of the whole phase
    (:func:`_lag_combination_sums`, c = N - 2m). The terms are of the order of N x^2 while the result is of the
    order of N D_m^2; on a phase dominated by a drift that ratio grows like (N/m)^4 / 12, which is why only
    factors with N/m <= _LAGGED_MAX_SPANS come here (relative rounding below ~1e-8)."""
    ms = [int(m) for m in ms]
    return _lag_combination_sums(x, ms, [len(x) - 2 * m for m in ms])


#: the windows of _windowed_oadev_sums hold this many starting points i (plus 2m past them)
_WINDOW_BLOCK = 1 << 19


def _windowed_oadev_sums(x, ms: np.ndarray, block: int = _WINDOW_BLOCK) -> np.ndarray:
    """Overlapping Allan sums for long averaging factors from lag products of the phase, window by window.

    The sum over i of D_m(i)^2 = (x_{i+2m} - 2 x_{i+m} + x_i)^2 is taken ``block`` starting points at a time;
    a block's terms read the window x[a : a + block + 2 max(ms)], from which its straight line through the
    first and last points is removed first (D does not change: a second difference annihilates a line), and
    the block's sum comes from lag products of that window (:func:`_lag_combination_sums`). The detrended
    window is what keeps the cancellation there small: a drift that is quadratic within the window leaves
    terms of the order of (W/m)^4 / 64 times the result (W the window's length), a random walk of the rate
    (W/m)^3. With block = 2^19 and the octave factors 2^12..2^16 (W/m <= 160) that was at most 3.3e-9
    relative on 1e7 samples of drifts (ramp, quadratic, cubic, sine, step) over tiny noise, 7e-12 on a random
    walk of the rate, and 8e-9 over 3000 random shorter cases with W/m <= 144: the order of the 1e-8 the lag
    products of the whole phase allow. One pass detrends the window; each lag is then one dot product.
    """
    n = len(x)
    ms = [int(m) for m in ms]
    size = min(block + 2 * max(ms), n)
    ramp, detrended = np.arange(size, dtype=np.float64), np.empty(size)
    sums = np.zeros(len(ms))
    for start in range(0, n - 2 * min(ms), block):
        window = np.asarray(x[start : min(start + size, n)], dtype=np.float64)
        length = window.size
        w = detrended[:length]
        np.multiply(ramp[:length], (window[-1] - window[0]) / (length - 1), out=w)
        np.subtract(window, w, out=w)
        w -= window[0]
        sums += _lag_combination_sums(w, ms, [min(block, n - 2 * m - start) for m in ms])
    return sums


#: phases longer than this have their running sum read by slices (_LazyCumulated) instead of held whole
_CUMULATED_IN_MEMORY_MAX = 1 << 22
#: points between the checkpoints of a _LazyCumulated
_CHECKPOINT = 1 << 16


class PhaseGrids:
    """The running sum X of a phase about its mean on grids of step g (X at 0, g, 2g, ..., n // g blocks), each
    made once: from the phase in one pass, or, where a finer grid whose step divides g was made before, as every
    (g / step)-th point of it, with no pass over the phase (the octave factors' grids are nested). R(n)'s modified
    variance reads them (:func:`gyrocomp.allan.noise_id.modified_variance_on_grid`), and so do the checkpoints of
    :class:`_LazyCumulated`."""

    def __init__(self, phase):
        self.phase = phase
        self._mean: float | None = None
        self._grids: dict[int, np.ndarray] = {}

    @property
    def mean(self) -> float:
        """The phase's mean [phase unit], that X is about."""
        if self._mean is None:
            self._mean = _mean(self.phase)
        return self._mean

    def running_sum(self, g: int) -> np.ndarray:
        """X at 0, g, 2g, ... (n // g + 1 points) [phase unit x samples]."""
        if g not in self._grids:
            finer = [h for h in self._grids if g % h == 0]
            self._grids[g] = self._grids[max(finer)][:: g // max(finer)] if finer else self._from_phase(g)
        return self._grids[g]

    def _from_phase(self, g: int) -> np.ndarray:
        phase, mean = self.phase, self.mean
        blocks = len(phase) // g
        sums = np.empty(blocks)
        step = max(g, (BLOCK_SAMPLES // g) * g)
        for start in range(0, blocks * g, step):
            stop = min(start + step, blocks * g)
            chunk = np.asarray(phase[start:stop], dtype=np.float64) - mean
            sums[start // g : stop // g] = chunk.reshape(-1, g).sum(axis=1)
        return np.concatenate([[0.0], np.cumsum(sums)])


def _cumulated(phase, in_memory_max: int | None = None):
    """X[k] = sum_{i<k} (x[i] - mean(x)), the running sum the modified variance differences: an array, or for a
    phase longer than ``in_memory_max`` points (default ``_CUMULATED_IN_MEMORY_MAX``; a memory-mapped file, say)
    a :class:`_LazyCumulated` that computes the slices the sums read, so the working memory stays at a few
    blocks."""
    if len(phase) > (_CUMULATED_IN_MEMORY_MAX if in_memory_max is None else in_memory_max):
        return _LazyCumulated(phase)
    return _running_sum((phase[a:b] for a, b in _blocks(len(phase))), _mean(phase), np.empty(len(phase) + 1))


class _LazyCumulated:
    """The running sum X of ``x`` about its mean, N+1 points, read by contiguous slices: X is kept at every
    ``_CHECKPOINT``-th point (one pass, :class:`PhaseGrids`), and a slice is its checkpoint plus the running sum of the points from
    it, so no array of X's length is ever made. Equal to the array form to rounding."""

    def __init__(self, x):
        self.x = x
        grids = PhaseGrids(x)
        self.mean = grids.mean
        self.checkpoints = grids.running_sum(_CHECKPOINT)  # X at 0, _CHECKPOINT, ... (every start a slice can have)
        self.length = len(x) + 1

    def __len__(self) -> int:
        return self.length

    def __getitem__(self, where: slice) -> np.ndarray:
        start, stop, step = where.indices(self.length)
        if step != 1:
            raise InputError("cumulated: only contiguous slices are read")
        if stop <= start:
            return np.empty(0)
        base = start // _CHECKPOINT * _CHECKPOINT
        out = np.empty(stop - base)
        out[0] = self.checkpoints[base // _CHECKPOINT]
        if stop - base > 1:
            np.subtract(self.x[base : stop - 1], self.mean, out=out[1:], dtype=np.float64)
            np.cumsum(out[1:], out=out[1:])
            out[1:] += out[0]
        return out[start - base :]


def _one_sum(kind: str, phase, cumulated, m: int, count: int) -> float:
    buffer, spare = np.empty(BLOCK_SAMPLES), np.empty(BLOCK_SAMPLES)
    if kind in ("oadev", "adev"):
        return second_difference_sum(phase, m, 1 if kind == "oadev" else m, count, buffer)
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
    while (
        length < len(ms)
        and ms[length] == 1 << length
        and ms[length] <= _OCTAVE_IN_CACHE_MAX_M
        and ms[length] * _LAGGED_MAX_SPANS < n_phase
    ):
        length += 1
    return length


def variance_sums(kind: str, phase, ms: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """The sum of squared differences behind each estimator, before its normalization
    (:func:`deviations_from_sums`).

    ``kind`` names the estimator (a key of :data:`ESTIMATORS`); ``phase`` is the integrated series; ``ms`` the
    averaging factors [samples] and ``counts`` the number of terms at each.

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


def deviations_from_sums(
    kind: str, sums: np.ndarray, ms: np.ndarray, tau: np.ndarray, counts: np.ndarray, phase_scale: float
) -> np.ndarray:
    """The deviations of estimator ``kind`` from its sums of squared differences (:func:`variance_sums`).

    Parameters
    ----------
    kind : str
        The estimator (a key of :data:`ESTIMATORS`).
    sums, ms, counts : array (k,)
        The sums, the averaging factors [samples] and the number of terms at each.
    tau : array (k,)
        The averaging times [s].
    phase_scale : float
        What the phase was multiplied by (the rate [Hz] for rate data integrated in samples).

    Returns
    -------
    array (k,)
        The deviation at each tau [the data's unit; TDEV in unit x s]; NaN where no term was summed.
    """
    scaled_tau = tau * phase_scale
    with np.errstate(invalid="ignore", divide="ignore"):
        if kind in ("oadev", "adev", "totdev"):
            var = sums / (2.0 * scaled_tau**2 * counts)
        elif kind in ("hdev", "ohdev"):
            var = sums / (6.0 * scaled_tau**2 * counts)
        else:
            var = sums / (2.0 * ms.astype(float) ** 2 * scaled_tau**2 * counts)
        dev = np.sqrt(np.where(counts > 0, var, np.nan))
    if kind == "tdev":
        dev = tau * dev / np.sqrt(3.0)  # time deviation [unit*s]: tau / sqrt(3) * MDEV
    return dev
