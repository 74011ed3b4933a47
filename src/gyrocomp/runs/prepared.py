"""A recording prepared for fitting: what a fit derives from it, each computed once, on first use.

A fit reads the same runs many times: the input checks, the choice of the g-sensitivity stage, the model choice,
the thermal model and the accelerometer's pieces each asked for the still segments of every run and computed
them again, and the thermal model averaged the runs in the blocks the model choice had already averaged (on ten
one-hour chamber runs, three still masks per run and two block means per run and axis: over a third of the fit).
A :class:`PreparedRun` is the recording itself (a :class:`~gyrocomp.recording.Recording`, so every function that
takes one takes it) that keeps what was derived from it: the still mask and the static segments per set of
detection settings, and the block means per axis, block, bin width and pieces. The fitting entry points prepare
their runs once (:func:`prepare`); a function handed a plain recording prepares it itself, and the result is the
same, only not shared.

A prepared run also says which channel a fit of it models (``channel``): the gyro's axes [deg/s], or the
accelerometer's [g] (``PreparedRun.of(run, "accel")``, which shares what was kept from the gyro's view), read by name
with :meth:`~gyrocomp.recording.Recording.signal`; the fitting iterates :func:`fit_axes`.

What is kept lives as long as the prepared run, which a fit drops when it returns, and is read-only; a copy with
other data (``dataclasses.replace``, :meth:`~gyrocomp.recording.Recording.with_gyro`, ``take``) starts with
nothing kept, since what was derived from the old data does not hold for the new.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, fields
from typing import Any, Literal, get_args

import numpy as np

from ..errors import InputError
from ..recording import ACCEL_AXES, Recording
from ..spilled_series import parts
from ..motion.positions import (
    DEFAULT_FACTOR,
    DEFAULT_MIN_DURATION_S,
    DEFAULT_WINDOW_S,
    StaticSegment,
    segments_from_mask,
    still_mask,
)


#: what a fit models: the gyro's axes or the accelerometer's
Channel = Literal["gyro", "accel"]
CHANNELS: tuple[str, ...] = get_args(Channel)


@dataclass(frozen=True)
class RunBlocks:
    """Block means of one run and axis: time [s], temperature [degC], the axis's values (``value``: [deg/s]
    for a gyro axis, [g] for an accelerometer axis), bin-balancing weight, the accelerations [g] when the run has
    the triad, the piece (segment) each block comes from, and the number of samples in each block (its duration,
    for time weights)."""

    time_s: np.ndarray
    temperature_degc: np.ndarray
    value: np.ndarray
    weight: np.ndarray
    accel_g: np.ndarray | None = None
    cluster: np.ndarray | None = None
    samples: np.ndarray | None = None


def prefix_sums_at(
    x: np.ndarray, at: np.ndarray, *, offset: float = 0.0, columns=None, rows: int | None = None
) -> np.ndarray:
    """The running sums ``c[i] = sum(x[:i] - offset)`` at the indices ``at`` (each in 0..n), of the ``columns`` of
    ``x`` (default: all), walked in parts of ``rows`` rows (default: :data:`gyrocomp.spilled_series.PART_ROWS`), so
    that the working memory does not grow with the recording (its columns may be memory-mapped files). The sums are
    ``np.cumsum``'s over the whole column, to the bit: each part's sum starts from the sum before it, in the same
    order of additions."""
    at = np.asarray(at, dtype=np.int64)
    n = x.shape[0]
    shape = x.shape[1:] if columns is None else (len(columns),)
    out = np.zeros((at.size, *shape))
    order = np.argsort(at, kind="stable")
    ordered = at[order]
    carry = np.zeros((1, *shape))
    first = 0  # the first of ``ordered`` not yet given a value
    for start, stop in parts(n, rows=rows):
        chunk = x[start:stop] if columns is None else x[start:stop][:, columns]
        c = np.cumsum(np.concatenate([carry, chunk - offset if offset else chunk]), axis=0)
        last = int(np.searchsorted(ordered, stop, side="right"))
        out[order[first:last]] = c[ordered[first:last] - start]
        first, carry = last, c[-1:]
    return out


def block_means(
    rec: Recording, axis: str, block_s: float, bin_width_degc: float, pieces: Sequence[slice] | None = None
) -> RunBlocks:
    """Means over consecutive blocks of ``block_s`` inside each of ``pieces`` (default: the stretches
    between time gaps; for multi-position runs, the static segments), with bin-balancing weights.
    ``cluster`` numbers the piece each block comes from."""
    t, temp, y = rec.time_s, rec.temperature_for(axis), rec.signal(axis)
    per_block = max(1, int(round(block_s * rec.rate_hz)))
    pieces = rec.contiguous_stretches() if pieces is None else pieces
    starts, ends, cluster = [], [], []
    for k, piece in enumerate(pieces):
        s = np.arange(piece.start, piece.stop, per_block)
        starts.append(s)
        ends.append(np.minimum(s + per_block, piece.stop))
        cluster.append(np.full(s.size, k))
    starts, ends, cluster = np.concatenate(starts), np.concatenate(ends), np.concatenate(cluster)
    counts = ends - starts

    def mean(x, offset=0.0, columns=None):
        c = prefix_sums_at(x, np.concatenate([starts, ends]), offset=offset, columns=columns)
        return (c[starts.size :] - c[: starts.size]) / (counts if c.ndim == 1 else counts[:, None])

    bt, btemp, by = mean(t, offset=t[0]) + t[0], mean(temp), mean(y)
    accel = None
    if rec.accel_g is not None and set(("accel_x", "accel_y", "accel_z")) <= set(rec.accel_axes):
        accel = mean(rec.accel_g, columns=[rec.accel_axes.index(a) for a in ("accel_x", "accel_y", "accel_z")])
    idx = np.floor(btemp / bin_width_degc).astype(np.int64)
    _, inverse, per_bin = np.unique(idx, return_inverse=True, return_counts=True)
    weight = (counts / counts.max()) / per_bin[inverse]
    return RunBlocks(bt, btemp, by, weight, accel, cluster, counts)


def _read_only(blocks: RunBlocks) -> RunBlocks:
    for f in fields(blocks):
        value = getattr(blocks, f.name)
        if isinstance(value, np.ndarray):
            value.flags.writeable = False
    return blocks


@dataclass(frozen=True, eq=False)
class PreparedRun(Recording):
    """A :class:`~gyrocomp.recording.Recording` that keeps what a fit derives from it (see the module), and says
    which channel the fit models: the gyro's axes [deg/s] or the accelerometer's [g] (``fit_axes``)."""

    channel: Channel = "gyro"
    _derived: dict[tuple, Any] = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.channel not in CHANNELS:
            raise InputError(f"channel: {self.channel!r}; use one of {', '.join(CHANNELS)}")

    @classmethod
    def of(cls, recording: Recording, channel: Channel | None = None) -> "PreparedRun":
        """``recording`` prepared: itself when it already is (and models ``channel``, when given), else a prepared
        run sharing its (validated) data and what was kept from it, modelling ``channel`` (default: the gyro)."""
        if isinstance(recording, PreparedRun) and channel in (None, recording.channel):
            return recording
        if channel not in (None, *CHANNELS):
            raise InputError(f"channel: {channel!r}; use one of {', '.join(CHANNELS)}")
        if channel == "accel" and not set(ACCEL_AXES) <= set(recording.accel_axes):
            raise InputError(f"{recording.source}: channel=accel needs accel_x, accel_y and accel_z columns [g]")
        prepared = object.__new__(cls)
        prepared.__dict__.update(recording.__dict__)
        prepared.__dict__["channel"] = channel or "gyro"
        # what was derived from the data holds whichever channel is modelled
        prepared.__dict__["_derived"] = recording._derived if isinstance(recording, PreparedRun) else {}
        return prepared

    @property
    def fit_axes(self) -> tuple[str, ...]:
        """The axes the fit models: the gyro's, or the accelerometer's x, y, z."""
        return self.gyro_axes if self.channel == "gyro" else ACCEL_AXES

    def _once(self, key: tuple, compute):
        if key not in self._derived:
            self._derived[key] = compute()
        return self._derived[key]

    def of_temperature(self, axis: str, name: str, compute):
        """``compute(temperature)`` of the temperature that goes with ``axis`` [degC], computed once per
        temperature column and ``name`` (the axes of one column share it): e.g. its turning-point threshold."""
        column = self.temperature_column_for(axis)
        return self._once(("temperature", column, name), lambda: compute(self.temperature_for(axis)))

    def still_mask(self, *, window_s: float = DEFAULT_WINDOW_S, factor: float = DEFAULT_FACTOR) -> np.ndarray:
        """:func:`gyrocomp.motion.positions.still_mask` (window [s], factor over the median variance), read-only."""

        def compute():
            mask = still_mask(self, window_s=window_s, factor=factor)
            mask.flags.writeable = False
            return mask

        return self._once(("still", float(window_s), float(factor)), compute)

    def static_segments(
        self,
        *,
        window_s: float = DEFAULT_WINDOW_S,
        min_duration_s: float = DEFAULT_MIN_DURATION_S,
        factor: float = DEFAULT_FACTOR,
    ) -> list[StaticSegment]:
        """:func:`gyrocomp.motion.positions.static_segments` (window and shortest segment [s]), from the kept still mask."""

        def compute():
            mask = self.still_mask(window_s=window_s, factor=factor)
            return tuple(segments_from_mask(self, mask, window_s=window_s, min_duration_s=min_duration_s))

        return list(self._once(("segments", float(window_s), float(min_duration_s), float(factor)), compute))

    def block_means(
        self, axis: str, block_s: float, bin_width_degc: float, pieces: Sequence[slice] | None = None
    ) -> RunBlocks:
        """:func:`block_means` of one axis (block [s], bin width [degC], the stretches to use), read-only."""
        key = (
            "blocks",
            axis,
            float(block_s),
            float(bin_width_degc),
            None if pieces is None else tuple((p.start, p.stop, p.step) for p in pieces),
        )
        return self._once(key, lambda: _read_only(block_means(self, axis, block_s, bin_width_degc, pieces)))


def fit_axes(recordings: Sequence[Recording]) -> tuple[str, ...]:
    """The axes a fit of ``recordings`` models (:attr:`PreparedRun.fit_axes` of the first; plain recordings: the
    gyro's)."""
    return PreparedRun.of(recordings[0]).fit_axes


def one_temperature_column(recordings: list[Recording]) -> bool:
    """Whether every recording reads one temperature for all the axes a fit models (one sensor, so one die and one
    lag): one column, or the accelerometer's axes (which all read the mean of the gyro's columns)."""
    return all(
        rec.temperature_degc is None or len({rec.temperature_column_for(a) for a in fit_axes([rec])}) == 1
        for rec in recordings
    )


def prepare(recordings: Iterable[Recording]) -> list[PreparedRun]:
    """Each recording prepared once (:meth:`PreparedRun.of`): a fit's entry point calls this on its runs.
    Anything else in the list is refused, naming its place."""
    out = []
    for k, rec in enumerate(recordings):
        if not isinstance(rec, Recording):
            raise InputError(
                f"recordings[{k}]: expected a Recording (from gyrocomp.read or simulate), got {type(rec).__name__}"
            )
        out.append(PreparedRun.of(rec))
    return out


__all__ = [
    "CHANNELS",
    "Channel",
    "PreparedRun",
    "RunBlocks",
    "block_means",
    "fit_axes",
    "one_temperature_column",
    "prepare",
]
