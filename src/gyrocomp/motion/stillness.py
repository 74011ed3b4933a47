"""Stillness in any log: the moments a vehicle stands still, found from its own noise, batch or streaming alike.

The log is cut into blocks of ``block_s`` seconds (at least ``MIN_BLOCK_SAMPLES`` samples; counted in samples from
its first sample; a time gap closes a
block early, and a block with a gap in it never counts as still). Each block keeps the mean and variance of every
gyro and accelerometer axis and its mean temperature (:class:`BlockStats`). A block is still when:

1. on every axis its variance about a straight line (a bias drifting with temperature within a block is not
   motion) is within the chi-square range of the sensor's noise: v <= s^2 chi2_{1-a}(w-2) / (w-2), w the block's
   samples, a = ``alpha``, the noise level s^2 estimated from the log itself as its quietest blocks' variance,
   s^2 = Q_q(v) (w-2) / chi2_q(w-2) (Q_q the ``quantile`` q of the blocks' variances: at least that fraction of
   the log must be still);
2. its means agree with its neighbours' (when they exist, without a gap): |m_b - m_(b+-1)| <= z d on every axis,
   z the two-sided normal quantile, d the spread of that difference: sqrt(2 s^2 / w) for white noise, or, when
   slow noise (flicker) moves the means more, the robust spread (median |difference| / 0.6745) over neighbouring
   blocks that both pass test 1. A vehicle turning smoothly keeps a small variance but moves the gravity
   direction (the accelerometer's means) and changes its rate between blocks.

The probability ``alpha`` is shared between the tests of a block (Bonferroni: alpha / axes each), so a still
block is rejected by chance about ``alpha`` of the time.

The noise level is the log's own, so a log that is never still would lend its quietest moving blocks the part of
noise. One physical bound guards that: no MEMS sensor at rest is noisier than ``MAX_GYRO_NOISE_DENSITY`` or
``MAX_ACCEL_NOISE_DENSITY`` (about 20 times the noisiest consumer parts' data sheets; per sample, a variance of
N^2 times the rate); a log whose quietest blocks are noisier than that has no still block (a vehicle whose motor
runs throughout, a log never still for ``quantile`` of its time).

Runs of consecutive still blocks, less one block at each end (the edges of a move), of at least ``min_duration_s``
are the still segments. The thresholds come from the data, not from fixed numbers, so the same code serves a
consumer part at 1 kHz and a tactical one at 10 Hz.

Streaming: :class:`StillnessState` takes the samples in chunks of any size (``update``) and gives the same blocks,
hence the same segments, as one call on the whole log (:func:`detect_still`, which is that state fed once).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..recording import Recording
from ..spilled_series import parts

BLOCK_S = 1.0
MIN_DURATION_S = 20.0
#: a log still less than this fraction of its time is a field log (``still_only="auto"``)
AUTO_STILL_FRACTION = 0.5
#: ``"auto"`` judges only logs of at least this many blocks (a short run is used whole)
AUTO_MIN_BLOCKS = 60
QUANTILE = 0.05
ALPHA = 1e-3
#: a step between samples beyond this many nominal periods is a gap
GAP_PERIODS = 1.5
#: fewest samples in a block (a slow log's blocks are longer than ``block_s``): a variance of fewer samples is too
#: uncertain to test
MIN_BLOCK_SAMPLES = 10
#: no MEMS gyro or accelerometer at rest is noisier than this [deg/s/sqrt(Hz)], [g/sqrt(Hz)] (consumer parts'
#: data sheets: about 0.005-0.01 deg/s/sqrt(Hz) and 100-400 ug/sqrt(Hz))
MAX_GYRO_NOISE_DENSITY = 0.2
MAX_ACCEL_NOISE_DENSITY = 0.005
#: median |x| / 0.6745 estimates the standard deviation of a zero-mean normal x
_MAD_TO_SIGMA = 0.6745


@dataclass(frozen=True)
class BlockStats:
    """Statistics of consecutive blocks (``n`` blocks, ``k`` gyro axes).

    ``start_s``/``stop_s`` [s] the first and last sample's time, ``first`` the first sample's index, ``count`` the
    samples, ``whole`` whether the block is full and has no gap, ``after_gap`` whether a gap precedes it;
    ``gyro_mean_dps``/``gyro_var_dps2`` (n, k) [deg/s, (deg/s)^2] (the variance about the block's line); ``accel_mean_g``/``accel_var_g2`` (n, 3) or None;
    ``temperature_degc`` (n,) or None.
    """

    start_s: np.ndarray
    stop_s: np.ndarray
    first: np.ndarray
    count: np.ndarray
    whole: np.ndarray
    after_gap: np.ndarray
    gyro_mean_dps: np.ndarray
    gyro_var_dps2: np.ndarray
    accel_mean_g: np.ndarray | None
    accel_var_g2: np.ndarray | None
    temperature_degc: np.ndarray | None
    block_samples: int


@dataclass(frozen=True)
class StillSegment:
    """One still stretch: samples [start, stop), its times [s], its mean rate per gyro axis [deg/s] (the bias
    there), mean specific force [g] (None without an accelerometer) and temperature [degC] (mean, min, max)."""

    start: int
    stop: int
    start_s: float
    stop_s: float
    gyro_mean_dps: np.ndarray
    accel_mean_g: np.ndarray | None
    temperature_degc: float | None
    temperature_min_degc: float | None
    temperature_max_degc: float | None

    @property
    def duration_s(self) -> float:
        return self.stop_s - self.start_s


@dataclass(frozen=True)
class StillDetection:
    """The still segments of a log, the per-block decision, and the noise levels the thresholds came from:
    ``gyro_noise_dps2`` (k,) and ``accel_noise_g2`` (3,) or None, block variances of still blocks [(deg/s)^2, g^2]."""

    segments: list[StillSegment]
    still_blocks: np.ndarray
    blocks: BlockStats
    gyro_noise_dps2: np.ndarray
    accel_noise_g2: np.ndarray | None

    @property
    def still_s(self) -> float:
        """Total still time in the segments [s]."""
        return float(sum(s.duration_s for s in self.segments))

    def mask(self, n_samples: int) -> np.ndarray:
        """Boolean mask of the samples inside a still segment."""
        out = np.zeros(n_samples, dtype=bool)
        for s in self.segments:
            out[s.start : s.stop] = True
        return out


@dataclass
class StillnessState:
    """Block statistics of a log fed in chunks (see the module). ``rate_hz`` [Hz] fixes the block length in
    samples and the gap threshold; ``update`` takes each chunk (times [s], gyro [deg/s] (m, k), accelerometer [g]
    (m, 3) or None, temperature [degC] or None), ``blocks()`` the blocks completed so far (``final=True``: the
    last, partial one too)."""

    rate_hz: float
    block_s: float = BLOCK_S
    _pending: list = field(default_factory=list, repr=False)
    _done: list = field(default_factory=list, repr=False)
    _seen: int = 0
    _last_time: float | None = None

    def __post_init__(self) -> None:
        if not self.rate_hz > 0:
            raise InputError(f"rate_hz: must be positive, got {self.rate_hz}")
        if not self.block_s > 0:
            raise InputError(f"block_s: must be positive, got {self.block_s}")
        self.block_samples = max(MIN_BLOCK_SAMPLES, int(round(self.block_s * self.rate_hz)))

    def update(
        self,
        time_s: np.ndarray,
        gyro_dps: np.ndarray,
        accel_g: np.ndarray | None = None,
        temperature_degc: np.ndarray | None = None,
    ) -> None:
        time_s = np.asarray(time_s, dtype=float)
        columns = [np.asarray(gyro_dps, dtype=float).reshape(time_s.size, -1)]
        columns.append(None if accel_g is None else np.asarray(accel_g, dtype=float).reshape(time_s.size, 3))
        columns.append(None if temperature_degc is None else np.asarray(temperature_degc, dtype=float))
        if time_s.size == 0:
            return
        # where a block must end: every block_samples samples since the last block began, or before a gap
        previous = self._last_time if self._last_time is not None else time_s[0]
        steps = np.diff(np.concatenate([[previous], time_s]))
        gaps = steps > GAP_PERIODS / self.rate_hz
        self._pending.append((time_s, *columns, gaps))
        self._last_time = float(time_s[-1])
        self._cut(final=False)

    def _cut(self, final: bool) -> None:
        if not self._pending:
            return
        time_s, gyro, accel, temperature, gaps = (  # one chunk pending (a whole log): used as it is, not copied
            None if part[0] is None else part[0] if len(part) == 1 else np.concatenate(part)
            for part in zip(*self._pending)
        )
        w = self.block_samples
        n = time_s.size
        # a block ends every w samples from the last block's start, or early, before a gap
        ends = np.append(np.flatnonzero(gaps[1:]) + 1, n)
        start = 0
        for end in ends:
            if start >= end:
                continue
            whole = (end - start) // w  # full blocks, all at once
            if whole:
                self._done.append(_blocks(time_s, gyro, accel, temperature, start, whole, w, self._seen, gaps, w))
                start += whole * w
            if start < end:  # a short block: closed by the gap, or the log's end when final
                if end == n and not final:
                    break
                self._done.append(_blocks(time_s, gyro, accel, temperature, start, 1, end - start, self._seen, gaps, w))
                start = end
        self._seen += start
        rest = slice(start, None)
        self._pending = (
            []
            if start >= n
            else [
                (
                    time_s[rest],
                    gyro[rest],
                    None if accel is None else accel[rest],
                    None if temperature is None else temperature[rest],
                    gaps[rest],
                )
            ]
        )

    def blocks(self, final: bool = True) -> BlockStats:
        if final:
            self._cut(final=True)
        return _stack(self._done, self.block_samples)


#: samples per group of blocks whose statistics are computed together (a few MiB of temporaries)
_GROUP_SAMPLES = 1 << 17


def _block_means(x: np.ndarray) -> np.ndarray:
    """The mean of each column of each block of ``x`` (blocks, m, k): a sum over the samples of each block as one
    contraction (numpy's mean along the middle axis adds rows of k values, ten times slower on a day's data)."""
    return np.einsum("j,bjk->bk", np.ones(x.shape[1]), x) / x.shape[1]


def _detrended_variance(x: np.ndarray) -> np.ndarray:
    """Variance of each column of each block of ``x`` (blocks, m, k) about its least-squares line in the sample
    index, m - 2 degrees of freedom (inf for m < 3): a bias drifting with temperature within a block is not
    noise."""
    m = x.shape[1]
    if m < 3:
        return np.full((x.shape[0], x.shape[2]), np.inf)
    i = np.arange(m) - (m - 1) / 2
    out = np.empty((x.shape[0], x.shape[2]))
    group = max(1, _GROUP_SAMPLES // m)  # blocks at a time: the centred copy stays small (no day-long temporary)
    for start in range(0, x.shape[0], group):
        part = x[start : start + group]
        e = part - _block_means(part)[:, None, :]
        slope = np.einsum("j,bjk->bk", i, e) / (i @ i)
        out[start : start + group] = np.maximum(np.einsum("bjk,bjk->bk", e, e) - slope**2 * (i @ i), 0.0) / (m - 2)
    return out


def _blocks(
    time_s, gyro, accel, temperature, start: int, count: int, length: int, seen: int, gaps: np.ndarray, w: int
) -> dict:
    """Statistics of ``count`` consecutive blocks of ``length`` samples from ``start`` (``w``: a full block's
    length; ``seen``: samples before this buffer)."""
    sl = slice(start, start + count * length)

    def blocked(x):
        return x[sl].reshape(count, length, -1)

    firsts = np.arange(count) * length + start
    temps = None if temperature is None else blocked(temperature).reshape(count, -1)
    return {
        "start_s": time_s[firsts],
        "stop_s": time_s[firsts + length - 1],
        "first": seen + firsts,
        "count": np.full(count, length),
        "whole": np.full(count, length == w),
        "after_gap": gaps[firsts] & (seen + firsts > 0),
        "gyro_mean": _block_means(blocked(gyro)),
        "gyro_var": _detrended_variance(blocked(gyro)),
        "accel_mean": None if accel is None else _block_means(blocked(accel)),
        "accel_var": None if accel is None else _detrended_variance(blocked(accel)),
        "temperature": None
        if temps is None
        else np.column_stack([temps.mean(axis=1), temps.min(axis=1), temps.max(axis=1)]),
    }


def _stack(done: list[dict], w: int) -> BlockStats:
    if not done:
        empty = np.zeros(0)
        return BlockStats(
            empty,
            empty,
            empty.astype(int),
            empty.astype(int),
            empty.astype(bool),
            empty.astype(bool),
            np.zeros((0, 1)),
            np.zeros((0, 1)),
            None,
            None,
            None,
            w,
        )

    def joined(key):
        return None if done[0][key] is None else np.concatenate([d[key] for d in done])

    return BlockStats(
        joined("start_s"),
        joined("stop_s"),
        joined("first"),
        joined("count"),
        joined("whole"),
        joined("after_gap"),
        joined("gyro_mean"),
        joined("gyro_var"),
        joined("accel_mean"),
        joined("accel_var"),
        joined("temperature"),
        w,
    )


def _noise_level(variance: np.ndarray, usable: np.ndarray, w: int, quantile: float) -> np.ndarray:
    """s^2 per axis from the quietest blocks (see the module)."""
    from scipy.special import chdtri  # chi2.ppf(q, k) = chdtri(k, 1 - q); scipy.stats takes 0.5 s to import

    low = np.quantile(variance[usable], quantile, axis=0)
    return low * (w - 2) / chdtri(w - 2, 1.0 - quantile)


def classify_blocks(
    blocks: BlockStats, *, quantile: float = QUANTILE, alpha: float = ALPHA
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """Which blocks are still (see the module), and the noise levels: (still (n,), gyro s^2 (k,), accel s^2 (3,)
    or None)."""
    if not 0 < quantile < 0.5:
        raise InputError(f"quantile: must lie in (0, 0.5), got {quantile}")
    if not 0 < alpha < 0.5:
        raise InputError(f"alpha: must lie in (0, 0.5), got {alpha}")
    w = blocks.block_samples
    usable = blocks.whole
    if usable.sum() < 2:
        return np.zeros(blocks.whole.size, dtype=bool), np.full(blocks.gyro_var_dps2.shape[1], np.nan), None
    channels = [
        (m, v)
        for m, v in ((blocks.gyro_mean_dps, blocks.gyro_var_dps2), (blocks.accel_mean_g, blocks.accel_var_g2))
        if m is not None
    ]
    tests = sum(m.shape[1] for m, _ in channels)
    per_test = alpha / tests  # Bonferroni: about ``alpha`` false alarms per still block in all
    from scipy.special import chdtri, ndtri  # the chi-square and normal quantiles, without scipy.stats' import

    bound = chdtri(w - 2, per_test) / (w - 2)
    z = ndtri(1 - per_test / 2)
    quiet = usable.copy()
    levels = []
    rate_hz = _rate(blocks)
    for (_, var), ceiling in zip(channels, (MAX_GYRO_NOISE_DENSITY, MAX_ACCEL_NOISE_DENSITY)):
        levels.append(_noise_level(var, usable, w, quantile))
        # an axis without noise (synthetic data, a coarse LSB at rest) tells nothing: it is not tested
        informative = levels[-1] > 0
        quiet &= np.all((var <= levels[-1] * bound) | ~informative, axis=1)
        if np.any(levels[-1] > ceiling**2 * rate_hz):  # the quietest blocks are not a sensor at rest
            quiet[:] = False
    still = quiet.copy()
    joined = ~blocks.after_gap[1:]  # neighbours with no gap between them
    for (mean, _), level in zip(channels, levels):
        step = np.diff(mean, axis=0)
        scale = np.sqrt(2 * level / w)
        pairs = joined & quiet[1:] & quiet[:-1]
        if pairs.sum() >= 10:  # slow noise (flicker) moves the means more than white noise: measure it
            scale = np.maximum(scale, np.median(np.abs(step[pairs]), axis=0) / _MAD_TO_SIGMA)
        agree = np.all((np.abs(step) <= z * scale) | ~(level > 0), axis=1) | ~joined
        still[1:] &= agree
        still[:-1] &= agree
    if blocks.accel_mean_g is None:
        levels.append(None)
    return still, levels[0], levels[1]


def still_segments(
    blocks: BlockStats, still: np.ndarray, *, min_duration_s: float = MIN_DURATION_S
) -> list[StillSegment]:
    """Runs of still blocks (no gap inside), one block trimmed at each end, at least ``min_duration_s`` [s] long."""
    segments = []
    n = still.size
    b = 0
    while b < n:
        if not still[b]:
            b += 1
            continue
        e = b
        while e + 1 < n and still[e + 1] and not blocks.after_gap[e + 1]:
            e += 1
        first, last = b + 1, e - 1  # the edges of the neighbouring moves
        if last >= first and blocks.stop_s[last] - blocks.start_s[first] + 1.0 / _rate(blocks) >= min_duration_s:
            segments.append(_segment(blocks, first, last))
        b = e + 1
    return segments


def _rate(blocks: BlockStats) -> float:
    whole = np.flatnonzero(blocks.whole)
    if whole.size == 0:
        return math.inf
    i = whole[0]
    return (blocks.count[i] - 1) / max(blocks.stop_s[i] - blocks.start_s[i], 1e-12)


def _segment(blocks: BlockStats, first: int, last: int) -> StillSegment:
    sel = slice(first, last + 1)
    weights = blocks.count[sel].astype(float)
    temps = blocks.temperature_degc
    return StillSegment(
        start=int(blocks.first[first]),
        stop=int(blocks.first[last] + blocks.count[last]),
        start_s=float(blocks.start_s[first]),
        stop_s=float(blocks.stop_s[last] + 1.0 / _rate(blocks)),
        gyro_mean_dps=np.average(blocks.gyro_mean_dps[sel], axis=0, weights=weights),
        accel_mean_g=None
        if blocks.accel_mean_g is None
        else np.average(blocks.accel_mean_g[sel], axis=0, weights=weights),
        temperature_degc=None if temps is None else float(np.average(temps[sel, 0], weights=weights)),
        temperature_min_degc=None if temps is None else float(temps[sel, 1].min()),
        temperature_max_degc=None if temps is None else float(temps[sel, 2].max()),
    )


def moves_most_of_the_time(found: StillDetection) -> bool:
    """Whether a log moves most of the time: enough whole blocks to judge, and fewer than AUTO_STILL_FRACTION of
    them still."""
    whole = found.blocks.whole
    return int(whole.sum()) >= AUTO_MIN_BLOCKS and found.still_blocks[whole].mean() < AUTO_STILL_FRACTION


def detect_still(
    recording: Recording,
    *,
    block_s: float = BLOCK_S,
    min_duration_s: float = MIN_DURATION_S,
    quantile: float = QUANTILE,
    alpha: float = ALPHA,
) -> StillDetection:
    """The still segments of a log (see the module).

    Parameters
    ----------
    recording : Recording
        Any log [s, deg/s, g, degC]; with an accelerometer, smooth rotations are told from stillness.
    block_s : float
        Block length [s].
    min_duration_s : float
        Shortest still segment kept [s].
    quantile : float
        Fraction of the quietest blocks that sets the noise level (at least that much of the log must be still).
    alpha : float
        False-alarm probability of each block test.
    """
    state = StillnessState(recording.rate_hz, block_s)
    accel, temperature = recording.accel_g, recording.temperature_degc
    for a, b in parts(recording.n_samples):  # a part at a time: no temporary as long as the log
        state.update(
            recording.time_s[a:b],
            recording.gyro_dps[a:b],
            None if accel is None else accel[a:b],
            None if temperature is None else temperature[a:b],
        )
    return detection(state.blocks(), min_duration_s=min_duration_s, quantile=quantile, alpha=alpha)


def detection(
    blocks: BlockStats, *, min_duration_s: float = MIN_DURATION_S, quantile: float = QUANTILE, alpha: float = ALPHA
) -> StillDetection:
    """The still segments of blocks a :class:`StillnessState` gathered (streaming) or :func:`detect_still` made."""
    still, gyro_level, accel_level = classify_blocks(blocks, quantile=quantile, alpha=alpha)
    return StillDetection(
        still_segments(blocks, still, min_duration_s=min_duration_s), still, blocks, gyro_level, accel_level
    )


__all__ = [
    "ALPHA",
    "AUTO_MIN_BLOCKS",
    "AUTO_STILL_FRACTION",
    "BLOCK_S",
    "BlockStats",
    "MAX_ACCEL_NOISE_DENSITY",
    "MAX_GYRO_NOISE_DENSITY",
    "MIN_DURATION_S",
    "QUANTILE",
    "StillDetection",
    "StillSegment",
    "StillnessState",
    "classify_blocks",
    "detect_still",
    "detection",
    "moves_most_of_the_time",
    "still_segments",
]
