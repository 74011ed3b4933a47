"""Helpers every log reader shares: optional imports, time matching, ordering, progress."""

from __future__ import annotations

import contextlib
import math
import importlib
import io
import os
import sys
import tempfile
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from types import ModuleType

import numpy as np

from ..errors import DataQualityWarning, InputError, MissingDependencyError, TimeOrderWarning, install_hint, printable
from ..recording import ACCEL_AXES, GYRO_AXES, Recording
from ..option_spelling import Spelling, spelled
from .layout import TableLayout
from .tables import keep_finite_rows

#: ``progress(fraction_done)``, fraction in [0, 1]; readers call it now and then on long files
ProgressCallback = Callable[[float], None]


def parse_instance(text: str) -> int | str:
    """``--instance``'s text: a whole number >= 0, or ``all`` (every instance: ``gyrocomp fit`` alone takes it)."""
    if text.strip().lower() == "all":
        return "all"
    return _whole_number(text, "instance")


def _whole_number(text: str, name: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise InputError(f"{name}: {text!r}: give a whole number >= 0") from None
    if value < 0:
        raise InputError(f"{name}: {value}: give a whole number >= 0")
    return value


def parse_time_range(text: str) -> tuple[float | None, float | None]:
    """``--time A:B`` -> (A, B) [s from the file's first sample]; an empty side is open."""
    parts = text.split(":")
    try:
        if len(parts) != 2:
            raise ValueError
        bounds = tuple(None if p.strip() == "" else float(p) for p in parts)
    except ValueError:
        raise InputError(
            f"time_range_s: {text!r}: give A:B in seconds from the file's start (A: or :B for an open end)"
        ) from None
    if any(b is not None and not math.isfinite(b) for b in bounds) or bounds == (None, None):
        raise InputError(f"time_range_s: {text!r}: give finite seconds on at least one side")
    return bounds


@dataclass(frozen=True)
class ReadOptions:
    """What to read from a file, beyond its format. Each field is an option of every command that reads data,
    spelled on the command line as its metadata says (:mod:`gyrocomp.option_spelling`).

    Parameters
    ----------
    layout : TableLayout
        Column (or dataset) mapping and units, for tables and HDF5/NetCDF files.
    drop_nonfinite : bool
        Drop rows with NaN or infinite values instead of refusing the file.
    instance : int, optional
        Sensor instance in autopilot logs (PX4 ``multi_id``, ArduPilot ``I`` / IMU2 / IMU3; default 0), or in a ROS
        bag the index of its ``sensor_msgs/Imu`` topic in name order.
    device_id : int, optional
        PX4 device id of the gyro to read (instead of ``instance``).
    imu_topic, temperature_topic : str, optional
        ROS topics of the ``sensor_msgs/Imu`` and ``sensor_msgs/Temperature`` messages
        (default: the only topic of that type in the bag).
    record : str, optional
        ArduPilot DataFlash record to read: ``"IMU"`` (default) or ``"TCLR"`` (the onboard
        temperature-learning records).
    channels : tuple of str, optional
        Tables: read only these channels' columns (``time`` always), e.g. ``("gyro_x", "gyro_z")``; a command
        that uses three of eight columns then neither converts nor holds the others. Default: every channel.
    time_range_s : (float or None, float or None), optional
        Keep only the samples from A to B seconds after the file's first one, [A, B) [s]; None for an open end.
    """

    layout: TableLayout = field(default_factory=TableLayout)
    drop_nonfinite: bool = spelled(
        Spelling(
            "--drop-nan", "Drop rows with empty/NaN values (says how many) instead of refusing the file.", switch=True
        ),
        default=False,
    )
    instance: int | None = spelled(
        Spelling(
            "--instance",
            "Sensor instance in PX4/ArduPilot logs (uORB multi_id, IMU number from 0; default 0) or ROS "
            "bags (the IMU topic's index in name order); fit: all fits every instance, one model file each.",
            metavar="N",
            parse=parse_instance,
        ),
        default=None,
    )
    device_id: int | None = spelled(
        Spelling(
            "--device-id",
            "PX4 device id of the gyro to read.",
            metavar="ID",
            parse=lambda text: _whole_number(text, "device_id"),
        ),
        default=None,
    )
    imu_topic: str | None = spelled(
        Spelling("--imu-topic", "ROS bag: the sensor_msgs/Imu topic (default: the only one)."), default=None
    )
    temperature_topic: str | None = spelled(
        Spelling("--temperature-topic", "ROS bag: the sensor_msgs/Temperature topic (default: the only one)."),
        default=None,
    )
    record: str | None = spelled(
        Spelling("--record", "ArduPilot log: IMU (default) or TCLR (onboard learning records)."), default=None
    )
    channels: tuple[str, ...] | None = None
    time_range_s: tuple[float | None, float | None] | None = spelled(
        Spelling(
            "--time",
            "Only the samples from A to B seconds after the file's first ([A, B); A: or :B open).",
            metavar="A:B",
            parse=parse_time_range,
        ),
        default=None,
    )

    def __post_init__(self) -> None:
        if self.instance == "all":
            raise InputError("instance: all is for gyrocomp fit (one model per instance); give a number here")
        for name in ("instance", "device_id"):
            value = getattr(self, name)
            if value is not None and (isinstance(value, bool) or not isinstance(value, int) or value < 0):
                raise InputError(f"{name}: {value!r}: give a whole number >= 0")


def require(module: str, extra: str, what: str) -> ModuleType:
    """Import an optional dependency, or raise one line that names the extra to install."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingDependencyError(
            f"{what} needs the optional package {module.split('.')[0]}; install it with: {install_hint(extra)}"
        ) from None


@contextlib.contextmanager
def _descriptor_into(fd: int, sink) -> Iterator[None]:
    """Point file descriptor ``fd`` at ``sink`` for the block (what C extensions write goes there too); a
    descriptor that is not open is left alone."""
    try:
        saved = os.dup(fd)
    except OSError:
        yield
        return
    try:
        os.dup2(sink.fileno(), fd)
        yield
    finally:
        os.dup2(saved, fd)
        os.close(saved)


@contextlib.contextmanager
def foreign_output(source: str, library: str) -> Iterator[None]:
    """Capture what a foreign reader (pyulog, pymavlink and its C indexer) prints to stdout or stderr while it
    reads, and say it in one :class:`DataQualityWarning`: how many lines, the first with control characters
    escaped. The descriptors are process-wide, so this is meant around a reader's own call only."""
    captured = io.StringIO()
    with tempfile.TemporaryFile() as sink:
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                stream.flush()
        with (
            _descriptor_into(1, sink),
            _descriptor_into(2, sink),
            contextlib.redirect_stdout(captured),
            contextlib.redirect_stderr(captured),
        ):
            yield
        sink.seek(0)
        text = captured.getvalue() + sink.read().decode("utf-8", "replace")
    lines = [line for line in text.splitlines() if line.strip()]
    if lines:
        first = printable(lines[0].strip())[:120]
        warnings.warn(
            f"{source}: {library} reported {len(lines)} line(s) while reading, the first: {first!r}; "
            "the log is probably damaged in places",
            DataQualityWarning,
            stacklevel=3,
        )


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
        warnings.warn(time_order_warning(source, moved, dropped, back), stacklevel=3)
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
        warnings.warn(left_out(source, what, int(np.count_nonzero(~ok)), ok.size), DataQualityWarning, stacklevel=3)
    return np.flatnonzero(ok)


def none_matched(source: str, what: str) -> InputError:
    """The refusal of gyro samples none of which lies within the time span of ``what``."""
    return InputError(f"{source}: no gyro sample lies within the time span of {what}; they cannot be matched")


def left_out(source: str, what: str, unmatched: int, total: int) -> str:
    """What :func:`keep_matched` says of ``unmatched`` of ``total`` gyro samples outside the span of ``what``."""
    return f"{source}: {unmatched} of {total} gyro samples lie outside the time span of {what} and were left out"
