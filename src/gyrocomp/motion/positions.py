"""Static segments: where a unit is still during a multi-position test, and its orientation there.

A sample is still when, over a window of ``window_s`` around it, the summed variance of the gyro
axes and (if present) of the accelerometer axes stays below ``factor`` times its median over the
recording (the noise level, as long as the unit is still most of the time). Turning the unit
raises the gyro variance at the start and end of a move and the accelerometer variance while
gravity sweeps across the axes. Runs of still samples of at least ``min_duration_s``, shortened
by half a window at each end and never spanning a time gap, are the segments; each reports the
mean specific force (the gravity vector in the body frame, [g]) and temperature.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..recording import Recording
from ..spilled_series import SpillArray, WindowSums, block_median, parts

DEFAULT_WINDOW_S = 1.0
DEFAULT_MIN_DURATION_S = 10.0
DEFAULT_FACTOR = 4.0
#: specific-force vectors closer than this are the same orientation [g]
SAME_ORIENTATION_G = 0.05


@dataclass(frozen=True)
class StaticSegment:
    """One still stretch of a recording.

    Attributes
    ----------
    start, stop : int
        Sample indices [start, stop).
    start_s, duration_s : float
        Start time and length [s].
    gravity_g : array (3,) or None
        Mean specific force along the accelerometer axes [g], None without an accelerometer.
    temperature_degc : float or None
        Mean temperature [degC].
    """

    start: int
    stop: int
    start_s: float
    duration_s: float
    gravity_g: np.ndarray | None
    temperature_degc: float | None


def _moving_variance_parts(x: np.ndarray, w: int, rows: int | None = None):
    """The summed moving variance of :func:`_moving_variance`, in consecutive parts, ``rows`` rows of ``x`` read
    at a time (default: :data:`gyrocomp.spilled_series.PART_ROWS`; ``x`` may be a memory-mapped file): each
    column's running sums are carried from one part to the next, in the same order of additions as over the whole
    column, so the parts joined are its result to the bit."""
    n, k = x.shape
    if n < w:
        yield np.full(n, np.var(x, axis=0).sum())
        return
    means = x.mean(axis=0)
    # each column's window sums of the centred values and of their squares
    sums = [(WindowSums(w), WindowSums(w)) for _ in range(k)]
    started = False
    for start, stop in parts(n, rows=rows):
        total = None
        for j, (values, squares) in enumerate(sums):
            column = x[start:stop, j] - means[j]
            s1 = values.add(column) / w
            s2 = squares.add(column * column) / w
            if s1.size:
                var = np.maximum(s2 - s1 * s1, 0.0)  # window k covers [k, k + w)
                total = var if total is None else np.add(total, var, out=total)
        if total is None:
            continue
        if not started:  # the first samples take the first full window's
            yield np.full(w // 2, total[0])
            started = True
        yield total
        last = total[-1]
    yield np.full(w - 1 - w // 2, last)  # and the last samples the last one's


def _moving_variance(x: np.ndarray, w: int, rows: int | None = None) -> np.ndarray:
    """Variance over a centred window of w samples (edges: the nearest full window), summed over columns.

    Column by column and ``rows`` rows at a time (:func:`_moving_variance_parts`), so that the working memory is a
    few columns of a part, not copies of ``x``: the sums are those of the whole array's, to the bit."""
    return np.concatenate(list(_moving_variance_parts(x, w, rows)))


def _variance_series(recording: Recording, data: np.ndarray, w: int) -> SpillArray:
    """The moving variance of ``data`` (:func:`_moving_variance`) inside each stretch between time gaps, in a
    series held in memory while small and in a temporary file beyond (:class:`gyrocomp.spilled_series.SpillArray`)."""
    series = SpillArray()
    for piece in recording.contiguous_stretches():
        for part in _moving_variance_parts(data[piece], w):
            series.append(part)
    return series


def still_mask(
    recording: Recording, *, window_s: float = DEFAULT_WINDOW_S, factor: float = DEFAULT_FACTOR
) -> np.ndarray:
    """True where the unit is still (see the module doc).

    The moving variances are read in parts and kept in a series that goes to a temporary file when long, their
    medians taken block by block (:func:`gyrocomp.spilled_series.block_median`): the working memory is the mask
    and a few parts, whatever the recording's length."""
    if not window_s > 0 or not factor > 1:
        raise InputError(f"static detection: window {window_s} s must be positive and factor {factor} above 1")
    w = max(5, int(round(window_s * recording.rate_hz)))
    with _variance_series(recording, recording.gyro_dps, w) as gyro:
        gyro_var = gyro.finish()
        gyro_limit = factor * block_median(gyro_var)
        still = np.empty(recording.n_samples, dtype=bool)
        for start, stop in parts(still.size):
            np.less_equal(gyro_var[start:stop], gyro_limit, out=still[start:stop])
    if recording.accel_g is not None:
        with _variance_series(recording, recording.accel_g, w) as accel:
            accel_var = accel.finish()
            accel_limit = factor * max(block_median(accel_var), 1e-30)
            for start, stop in parts(still.size):
                still[start:stop] &= accel_var[start:stop] <= accel_limit
    return still


def static_segments(
    recording: Recording,
    *,
    window_s: float = DEFAULT_WINDOW_S,
    min_duration_s: float = DEFAULT_MIN_DURATION_S,
    factor: float = DEFAULT_FACTOR,
) -> list[StaticSegment]:
    """The still stretches of a recording, in time order (see the module doc)."""
    return segments_from_mask(
        recording,
        still_mask(recording, window_s=window_s, factor=factor),
        window_s=window_s,
        min_duration_s=min_duration_s,
    )


def segments_from_mask(
    recording: Recording,
    still: np.ndarray,
    *,
    window_s: float = DEFAULT_WINDOW_S,
    min_duration_s: float = DEFAULT_MIN_DURATION_S,
) -> list[StaticSegment]:
    """The static segments of ``recording`` from its still mask (:func:`still_mask` with the same ``window_s``
    [s]): runs of still samples, trimmed by half a window where they border motion, of at least
    ``min_duration_s`` [s]."""
    trim = max(1, int(round(window_s * recording.rate_hz)) // 2)
    out = []
    for piece in recording.contiguous_stretches():
        s = still[piece]
        bound = np.zeros(1, dtype=np.int8)  # one byte a sample: a mask of ten hours at 1 kHz is 36 MB
        edges = np.flatnonzero(np.diff(np.concatenate([bound, np.asarray(s, dtype=bool).view(np.int8), bound])))
        for a, b in zip(edges[::2], edges[1::2]):
            a, b = piece.start + a, piece.start + b
            if a > piece.start:
                a += trim
            if b < piece.stop:
                b -= trim
            if b <= a or recording.time_s[b - 1] - recording.time_s[a] < min_duration_s:
                continue
            grav = None if recording.accel_g is None else recording.accel_g[a:b].mean(axis=0)
            temp = None if recording.temperature_degc is None else float(np.mean(recording.temperature_degc[a:b]))
            out.append(
                StaticSegment(
                    int(a),
                    int(b),
                    float(recording.time_s[a]),
                    float(recording.time_s[b - 1] - recording.time_s[a]),
                    grav,
                    temp,
                )
            )
    return out


def segment_mask(n_samples: int, segments: list[StaticSegment]) -> np.ndarray:
    """Boolean mask of the samples inside the segments."""
    mask = np.zeros(n_samples, dtype=bool)
    for seg in segments:
        mask[seg.start : seg.stop] = True
    return mask


def orientations(segments: list[StaticSegment]) -> list[tuple[np.ndarray, int]]:
    """Distinct gravity vectors among the segments (within ``SAME_ORIENTATION_G``) and how many segments each."""
    found: list[list] = []
    for seg in segments:
        if seg.gravity_g is None:
            continue
        for entry in found:
            if np.linalg.norm(entry[0] - seg.gravity_g) < SAME_ORIENTATION_G:
                entry[1] += 1
                break
        else:
            found.append([seg.gravity_g, 1])
    return [(g, k) for g, k in found]


__all__ = ["segments_from_mask", "StaticSegment", "orientations", "segment_mask", "static_segments", "still_mask"]
