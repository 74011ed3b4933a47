"""What every log reader does with its samples: ordering them by time, matching one stream to another, the recording
returned."""

from __future__ import annotations


import warnings

import numpy as np

from ..errors import DataQualityWarning, InputError, TimeOrderWarning, user_stacklevel
from ..recording import ACCEL_AXES, GYRO_AXES, Recording
from .read_options import ReadOptions
from .tables import keep_finite_rows


def log_recording(
    path,
    options: ReadOptions,
    time_s: np.ndarray,
    gyro_dps: np.ndarray,
    accel_g: np.ndarray | None,
    temperature_degc: np.ndarray | None,
    metadata: dict,
    gyro_axes: tuple[str, ...] = GYRO_AXES,
    first_row: int = 0,
) -> Recording:
    """The :class:`Recording` a log reader returns [s, deg/s, g, degC]; with ``options.drop_nonfinite`` the rows
    holding an empty, NaN or infinite value are dropped first (a warning says how many), as for tables. Rows are
    numbered from ``first_row`` + 1 (a chunk of a longer log: the samples before it)."""
    n = time_s.size
    index = np.arange(n)
    if options.drop_nonfinite:
        index, (time_s, gyro_dps, accel_g, temperature_degc) = keep_finite_rows(
            path, time_s, gyro_dps, accel_g, temperature_degc
        )
    return Recording(
        time_s=time_s,
        gyro_dps=gyro_dps,
        gyro_axes=gyro_axes,
        temperature_degc=temperature_degc,
        accel_g=accel_g,
        accel_axes=ACCEL_AXES if accel_g is not None else (),
        source=str(path),
        row_numbers=index + 1 + first_row,
        metadata={**metadata, "rows_dropped": int(n - index.size)},
    )


def order_by_time(source: str, time_s: np.ndarray, *arrays: np.ndarray | None) -> tuple:
    """Sort samples by time and drop repeated time stamps (the first is kept), saying how many.

    Logs written by autopilots and ROS nodes repeat or reorder a few stamps now and then;
    the recording needs strictly increasing time.
    """
    time_s = np.asarray(time_s, dtype=float)
    if time_s.size < 2 or bool(np.all(time_s[1:] > time_s[:-1])):  # in order, no repeat: nothing to sort or copy
        return (time_s, *(None if a is None else np.asarray(a) for a in arrays))
    order = np.argsort(time_s, kind="stable")
    sorted_t = time_s[order]
    keep = np.ones(sorted_t.size, dtype=bool)
    keep[1:] = np.diff(sorted_t) > 0
    index = order[keep]
    moved = int(np.count_nonzero(order != np.arange(order.size)))
    dropped = int(sorted_t.size - index.size)
    if moved or dropped:
        back = float(np.max(np.maximum.accumulate(time_s)[:-1] - time_s[1:])) if time_s.size > 1 else 0.0
        warnings.warn(time_order_warning(source, moved, dropped, back), stacklevel=user_stacklevel())
    return (time_s[index], *(None if a is None else np.asarray(a)[index] for a in arrays))


def time_order_warning(source: str, moved: int, dropped: int, back_s: float) -> TimeOrderWarning:
    """What :func:`order_by_time` says of ``moved`` samples sorted, ``dropped`` repeated stamps and the time going
    back by up to ``back_s`` [s] (a reader in chunks says it once for the whole file)."""
    return TimeOrderWarning(
        f"{source}: {moved} sample(s) out of time order were sorted and {dropped} repeated time stamp(s) dropped"
        + (f" (the time went back by up to {back_s:.6g} s)" if back_s > 0 else ""),
        moved=moved,
        dropped=dropped,
        largest_back_s=max(back_s, 0.0),
    )


def match_by_time(
    source: str,
    what: str,
    target_time_s: np.ndarray,
    time_s: np.ndarray,
    values: np.ndarray,
    max_gap_s: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Values of another stream at the target times, by linear interpolation.

    Parameters
    ----------
    source, what : str
        File and stream name, for messages.
    target_time_s : array (n,)
        Times to interpolate at [s] (the gyro's).
    time_s : array (m,)
        Times of the other stream [s], increasing.
    values : array (m,) or (m, k)
        The other stream.
    max_gap_s : float, optional
        Target samples farther than this from any sample of the other stream are not matched
        (default: 5 of the other stream's median periods).

    Returns
    -------
    matched : array (n,) or (n, k)
        Interpolated values (NaN where not matched).
    ok : array (n,) of bool
        Where the match is valid.
    """
    time_s = np.asarray(time_s, dtype=float)
    values = np.asarray(values, dtype=float)
    if time_s.size < 2:
        raise InputError(f"{source}: {what} has {time_s.size} sample(s); at least 2 are needed to match it by time")
    if max_gap_s is None:
        max_gap_s = 5.0 * float(np.median(np.diff(time_s)))
    columns = values.reshape(time_s.size, -1)
    matched = np.column_stack([np.interp(target_time_s, time_s, c) for c in columns.T])
    nearest = np.clip(np.searchsorted(time_s, target_time_s), 1, time_s.size - 1)
    distance = np.minimum(np.abs(target_time_s - time_s[nearest - 1]), np.abs(time_s[nearest] - target_time_s))
    ok = (target_time_s >= time_s[0] - max_gap_s) & (target_time_s <= time_s[-1] + max_gap_s) & (distance <= max_gap_s)
    matched[~ok] = np.nan
    return (matched[:, 0] if values.ndim == 1 else matched), ok


def keep_matched(source: str, what: str, ok: np.ndarray) -> np.ndarray:
    """Index of the samples that could be matched; warns how many were left out, refuses if none."""
    if not ok.any():
        raise none_matched(source, what)
    if not ok.all():
        warnings.warn(
            left_out(source, what, int(np.count_nonzero(~ok)), ok.size),
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
    return np.flatnonzero(ok)


def none_matched(source: str, what: str) -> InputError:
    """The refusal of gyro samples none of which lies within the time span of ``what``."""
    return InputError(f"{source}: no gyro sample lies within the time span of {what}; they cannot be matched")


def left_out(source: str, what: str, unmatched: int, total: int) -> str:
    """What :func:`keep_matched` says of ``unmatched`` of ``total`` gyro samples outside the span of ``what``."""
    return f"{source}: {unmatched} of {total} gyro samples lie outside the time span of {what} and were left out"
