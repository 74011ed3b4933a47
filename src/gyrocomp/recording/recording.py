"""The canonical in-memory recording every reader returns and every model consumes."""

from __future__ import annotations

import copy
import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError, TimeOrderError
from ..spilled_series import parts, streamed_median

GYRO_AXES = ("gyro_x", "gyro_y", "gyro_z")
ACCEL_AXES = ("accel_x", "accel_y", "accel_z")
#: a rate table's commanded angular rate in the sensor frame [deg/s] (optional columns)
REFERENCE_RATE_AXES = ("ref_rate_x", "ref_rate_y", "ref_rate_z")
TEMPERATURE_COLUMN = "temperature"
#: a gap is a time step longer than this many median sample periods
GAP_FACTOR = 2.0


def _temperature_array(src: str, value, n: int, axes: tuple[str, ...]) -> np.ndarray | None:
    """The temperature [degC] as one column (n,) or one per gyro axis (n, axes), shape checked."""
    if value is None:
        return None
    temp = np.asarray(value, dtype=float)
    if temp.ndim == 2 and temp.shape[1] == 1:
        temp = temp[:, 0]
    if temp.shape not in ((n,), (n, len(axes))):
        raise InputError(f"{src}: temperature has shape {temp.shape}; expected ({n},) or ({n}, {len(axes)})")
    return temp


def _accel_array(src: str, value, n: int, accel_axes: tuple[str, ...]) -> np.ndarray | None:
    """The accelerations [g] as (n, accel axes), shape checked."""
    if value is None:
        return None
    accel = np.asarray(value, dtype=float)
    if accel.ndim == 1:
        accel = accel[:, None]
    if accel.shape != (n, len(accel_axes)):
        raise InputError(f"{src}: accelerometer data has shape {accel.shape}, expected ({n}, {len(accel_axes)})")
    return accel


def _reference_array(src: str, value, n: int) -> np.ndarray | None:
    """The rate table's reference rates [deg/s] as (n, 3), shape checked."""
    if value is None:
        return None
    reference = np.asarray(value, dtype=float)
    if reference.shape != (n, 3):
        raise InputError(
            f"{src}: reference rates have shape {reference.shape}, expected ({n}, 3) "
            f"for {', '.join(REFERENCE_RATE_AXES)}"
        )
    return reference


def _temperature_names(gyro_axes: tuple[str, ...], per_axis: bool) -> tuple[str, ...]:
    """Temperature channel names: one shared column, or ``temperature_x`` ... one per gyro axis."""
    if not per_axis:
        return (TEMPERATURE_COLUMN,)
    return tuple(f"{TEMPERATURE_COLUMN}_{axis.split('_')[-1]}" for axis in gyro_axes)


def nominal_rate_hz(period_s: float) -> float:
    """1/period [Hz], snapped to 6 decimals when it is that close (time stamps like k / 100.0)."""
    rate = 1.0 / period_s
    snapped = round(rate, 6)
    return snapped if snapped > 0 and abs(rate - snapped) <= 1e-9 * rate else rate


@dataclass(frozen=True)
class Gap:
    """A stretch with no samples: the step from row ``after_row`` to the next is ``duration_s`` long."""

    after_row: int
    start_s: float
    duration_s: float


class Gaps(Sequence):
    """A recording's gaps, a sequence of :class:`Gap` kept as three arrays: a log whose stamps come in bursts has
    a gap every few samples (millions in a day), and one object each would cost hundreds of MB and seconds.
    Equal to any sequence of the same gaps (``recording.gaps == ()`` when there is none).

    Parameters
    ----------
    after_rows : ndarray of int
        The row after which each gap falls.
    starts_s : ndarray of float
        The time of that row [s].
    durations_s : ndarray of float
        The step from that row to the next [s].
    """

    __slots__ = ("after_rows", "starts_s", "durations_s")

    def __init__(self, after_rows=(), starts_s=(), durations_s=()):
        self.after_rows = np.asarray(after_rows, dtype=np.int64)
        self.starts_s = np.asarray(starts_s, dtype=float)
        self.durations_s = np.asarray(durations_s, dtype=float)

    def __len__(self) -> int:
        return self.after_rows.size

    def __getitem__(self, index):
        if isinstance(index, slice):
            return Gaps(self.after_rows[index], self.starts_s[index], self.durations_s[index])
        return Gap(int(self.after_rows[index]), float(self.starts_s[index]), float(self.durations_s[index]))

    def __eq__(self, other) -> bool:
        if isinstance(other, Gaps):
            return bool(
                np.array_equal(self.after_rows, other.after_rows)
                and np.array_equal(self.starts_s, other.starts_s)
                and np.array_equal(self.durations_s, other.durations_s)
            )
        if isinstance(other, Sequence) and not isinstance(other, str):
            return len(self) == len(other) and all(a == b for a, b in zip(self, other))
        return NotImplemented

    __hash__ = None  # type: ignore[assignment] - equal to tuples, which hash otherwise

    def __repr__(self) -> str:
        shown = ", ".join(map(repr, self[:3]))
        return f"Gaps({shown}{', ...' if len(self) > 3 else ''}; {len(self)} in all)"

    def __reduce__(self):
        return Gaps, (self.after_rows, self.starts_s, self.durations_s)

    def longest(self) -> Gap | None:
        """The longest gap (the first of equals), None when there is none."""
        return self[int(np.argmax(self.durations_s))] if len(self) else None


def _require_finite(src: str, rows: np.ndarray, channels) -> None:
    """Refuse the first non-finite value of any channel, naming its row and column; ``channels`` holds
    (column names, (n,) or (n, k) array or None) pairs."""
    for names, arr in channels:
        if arr is None:
            continue
        for start, table in _row_chunks(arr):
            bad = ~np.isfinite(table)
            if bad.any():
                at = int(np.flatnonzero(bad.any(axis=1))[0])
                column = names[int(np.flatnonzero(bad[at])[0])]
                raise InputError(
                    f"{src}: row {rows[start + at]}, column {column!r}: {table[at][bad[at]][0]} "
                    "is not a finite number; fix the file or drop such rows explicitly (drop_nonfinite=True)"
                )


#: values no sensor's output can be, in any unit it was taken in (raw 16-bit counts stay within 65536): a gyro or an
#: accelerometer beyond 1e6, a temperature below absolute zero or above 1e4 degC; what a damaged binary file gives
#: (1e36..1e302) is refused here, naming its row; within these, :mod:`gyrocomp.measures.plausibility` warns about
#: values beyond what sensors report (5000 deg/s, 1000 g, -100..200 degC)
POSSIBLE = {"gyro": (-1e6, 1e6, "deg/s"), "accel": (-1e6, 1e6, "g"), "temperature": (-273.15, 1e4, "degC")}


def _require_possible(src: str, rows: np.ndarray, channels) -> None:
    """Refuse the first value no sensor can give (:data:`POSSIBLE`), naming its row and column; ``channels``
    holds (kind, column names, array or None)."""
    for kind, names, arr in channels:
        if arr is None:
            continue
        lo, hi, unit = POSSIBLE[kind]
        for start, table in _row_chunks(arr):
            bad = (table < lo) | (table > hi)
            if bad.any():
                at = int(np.flatnonzero(bad.any(axis=1))[0])
                column = names[int(np.flatnonzero(bad[at])[0])]
                value = table[at][bad[at]][0]
                raise InputError(
                    f"{src}: row {rows[start + at]}, column {column!r}: {value:.6g} {unit} is beyond what any "
                    f"sensor gives ({lo:g}..{hi:g} {unit}): a damaged file, or a column in another unit "
                    "than the one given?"
                )


def _row_chunks(arr: np.ndarray):
    """(first row, rows as a 2-D table) of ``arr``, a part at a time (:func:`gyrocomp.spilled_series.parts`): a
    recording's checks need no copy of its columns, which may be memory-mapped files."""
    table = arr.reshape(arr.shape[0], -1)
    for start, stop in parts(table.shape[0]):
        yield start, table[start:stop]


def _time_steps(time_s: np.ndarray):
    """(index of the first step, the steps [s]) of ``time_s``, a part at a time."""
    for start, stop in parts(time_s.size, overlap=1):
        yield start, np.diff(time_s[start:stop])


def _require_increasing(src: str, rows: np.ndarray, time_s: np.ndarray) -> None:
    """Refuse the first row whose time repeats or goes backwards."""
    for start, dt in _time_steps(time_s):
        bad_steps = np.flatnonzero(dt <= 0)
        if bad_steps.size:
            i = start + int(bad_steps[0]) + 1
            repeated = bool(dt[bad_steps[0]] == 0)
            raise TimeOrderError(
                f"{src}: row {rows[i]}: time {'repeats' if repeated else 'goes backwards'} ({time_s[i]:.9g} s after "
                f"{time_s[i - 1]:.9g} s); time must strictly increase",
                int(rows[i]),
                repeated,
            )


def _gaps(rows: np.ndarray, time_s: np.ndarray) -> tuple[float, Gaps]:
    """(the median sample period [s], the gaps: steps longer than ``GAP_FACTOR`` of it), the steps read a part at a
    time, their median exact (:func:`gyrocomp.spilled_series.streamed_median`)."""
    period = streamed_median(dt for _, dt in _time_steps(time_s))
    after, starts, durations = [], [], []
    for start, dt in _time_steps(time_s):
        at = np.flatnonzero(dt > GAP_FACTOR * period)
        after.append(rows[start + at])
        starts.append(time_s[start + at])
        durations.append(dt[at])
    if not after:
        return period, Gaps()
    return period, Gaps(np.concatenate(after), np.concatenate(starts), np.concatenate(durations))


@dataclass(frozen=True, eq=False)
class Recording:
    """Time series of one power-on of a gyro, in gyrocomp's internal units.

    Parameters
    ----------
    time_s : array (n,)
        Sample times [s], strictly increasing.
    gyro_dps : array (n, k)
        Angular rate [deg/s] of the k gyro axes named in ``gyro_axes``.
    gyro_axes : tuple of str
        Names of the gyro columns, a subset of ``("gyro_x", "gyro_y", "gyro_z")``.
    temperature_degc : array (n,) or (n, k), optional
        Sensor temperature [degC]: one column for all axes, or one per gyro axis.
    accel_g : array (n, 3), optional
        Specific force [g] along ``accel_axes``.
    accel_axes : tuple of str
        Names of the accelerometer columns.
    source : str
        Where the data came from (a file name), used in messages.
    row_numbers : array (n,) of int, optional
        1-based data-row numbers in the source, used in messages and to write results back.
        Defaults to 1..n.
    metadata : dict
        Free-form provenance (file hash, reader options).
    reference_rate_dps : array (n, 3), optional
        The angular rate a rate table applied, in the sensor frame (``ref_rate_x/_y/_z``) [deg/s]:
        the reference for scale-factor and misalignment calibration.

    Validation happens once, here: shapes agree, values are finite (readers drop
    non-finite rows only when asked to) and within what a sensor can give (:data:`POSSIBLE`), time strictly
    increases. Gaps longer than
    ``GAP_FACTOR`` median sample periods are found and kept in ``gaps`` (:class:`Gaps`); nothing is
    interpolated.
    """

    time_s: np.ndarray
    gyro_dps: np.ndarray
    gyro_axes: tuple[str, ...]
    temperature_degc: np.ndarray | None = None
    accel_g: np.ndarray | None = None
    accel_axes: tuple[str, ...] = ()
    source: str = "<memory>"
    row_numbers: np.ndarray | None = None
    metadata: dict[str, Any] = field(default_factory=dict)
    reference_rate_dps: np.ndarray | None = None
    rate_hz: float = field(init=False)
    gaps: Gaps = field(init=False)

    def __post_init__(self) -> None:
        src = self.source
        time_s = np.ascontiguousarray(self.time_s, dtype=float)
        gyro = np.asarray(self.gyro_dps, dtype=float)
        if gyro.ndim == 1:
            gyro = gyro[:, None]
        n = time_s.shape[0]
        if time_s.ndim != 1:
            raise InputError(f"{src}: time must be one-dimensional")
        if n < 2:
            raise InputError(f"{src}: {n} sample(s); a recording needs at least 2 rows of data")
        axes = tuple(self.gyro_axes)
        if gyro.shape != (n, len(axes)) or not axes:
            raise InputError(f"{src}: gyro data has shape {gyro.shape}, expected ({n}, {len(axes)}) for axes {axes}")
        rows = np.arange(1, n + 1) if self.row_numbers is None else np.asarray(self.row_numbers)
        temp = _temperature_array(src, self.temperature_degc, n, axes)
        accel = _accel_array(src, self.accel_g, n, tuple(self.accel_axes))
        reference = _reference_array(src, self.reference_rate_dps, n)
        temp_names = _temperature_names(axes, temp is not None and temp.ndim == 2)
        _require_finite(
            src,
            rows,
            (
                (("time",), time_s),
                (axes, gyro),
                (temp_names, temp),
                (tuple(self.accel_axes), accel),
                (REFERENCE_RATE_AXES, reference),
            ),
        )
        _require_possible(
            src,
            rows,
            (("gyro", axes, gyro), ("temperature", temp_names, temp), ("accel", tuple(self.accel_axes), accel)),
        )
        _require_increasing(src, rows, time_s)
        period, gaps = _gaps(rows, time_s)
        set_ = object.__setattr__
        set_(self, "time_s", time_s)
        set_(self, "gyro_dps", gyro)
        set_(self, "gyro_axes", axes)
        set_(self, "temperature_degc", temp)
        set_(self, "accel_g", accel)
        set_(self, "accel_axes", tuple(self.accel_axes))
        set_(self, "reference_rate_dps", reference)
        set_(self, "row_numbers", rows)
        set_(self, "rate_hz", nominal_rate_hz(period))
        set_(self, "gaps", gaps)

    # -- convenience -------------------------------------------------------------
    @property
    def n_samples(self) -> int:
        return self.time_s.shape[0]

    @property
    def duration_s(self) -> float:
        """Time from the first to the last sample [s]."""
        return float(self.time_s[-1] - self.time_s[0])

    @property
    def mean_rate_hz(self) -> float:
        """The samples' mean rate, steps over the time they span [Hz] (gaps included; :attr:`rate_hz` is the
        median step's)."""
        return (self.n_samples - 1) / self.duration_s

    @property
    def temperature_columns(self) -> tuple[str, ...]:
        if self.temperature_degc is None:
            return ()
        return _temperature_names(self.gyro_axes, self.temperature_degc.ndim == 2)

    def temperature_column_for(self, axis: str) -> str:
        """Name of the temperature channel that goes with a gyro axis (an accelerometer axis: ``temperature``,
        the mean of the columns when there is one per gyro axis; see :meth:`temperature_for`)."""
        columns = self.temperature_columns
        if len(columns) == 1:
            return columns[0]
        return TEMPERATURE_COLUMN if axis in self.accel_axes else columns[self._axis_index(axis)]

    def gyro(self, axis: str) -> np.ndarray:
        """Angular rate of one axis [deg/s]."""
        return self.gyro_dps[:, self._axis_index(axis)]

    def signal(self, axis: str) -> np.ndarray:
        """The column of a gyro axis [deg/s] or of an accelerometer axis [g], by its name."""
        if axis in self.accel_axes and axis not in self.gyro_axes:
            return self.accel_g[:, self.accel_axes.index(axis)]
        return self.gyro(axis)

    def unit_of(self, axis: str) -> str:
        """The unit of an axis's values: ``deg/s`` for a gyro axis, ``g`` for an accelerometer axis."""
        return "g" if axis in self.accel_axes and axis not in self.gyro_axes else "deg/s"

    @property
    def die_temperature_degc(self) -> np.ndarray | None:
        """The temperature of the die [degC]: the one column, or the mean of one per axis (None without a
        temperature)."""
        t = self.temperature_degc
        return t if t is None or t.ndim == 1 else t.mean(axis=1)

    def temperature_for(self, axis: str) -> np.ndarray:
        """Temperature [degC] that goes with an axis: a gyro axis's own column when there is one per axis; for an
        accelerometer axis (one die, whatever the gyro's columns) their mean, as the compensation reads it."""
        if self.temperature_degc is None:
            raise InputError(
                f"{self.source}: no temperature column; a temperature model needs one "
                "(map it with columns={'temperature': 'NAME'})"
            )
        if self.temperature_degc.ndim == 1:
            return self.temperature_degc
        if axis in self.accel_axes and axis not in self.gyro_axes:
            return self.die_temperature_degc
        return self.temperature_degc[:, self._axis_index(axis)]

    def _axis_index(self, axis: str) -> int:
        try:
            return self.gyro_axes.index(axis)
        except ValueError:
            raise InputError(
                f"{self.source}: no gyro axis {axis!r}; this recording has {', '.join(self.gyro_axes)}"
            ) from None

    def contiguous_stretches(self) -> list[slice]:
        """Sample ranges between the recording's time gaps, in order (one slice when there is no gap)."""
        starts = [0] + (np.searchsorted(self.row_numbers, self.gaps.after_rows) + 1).tolist()
        bounds = starts + [self.n_samples]
        return [slice(a, b) for a, b in zip(bounds[:-1], bounds[1:])]

    def with_gyro(self, gyro_dps: np.ndarray) -> "Recording":
        """A copy with the gyro data replaced (same axes, same shape) [deg/s]: only the new data is checked (its
        shape, finite values); the time, its gaps and rate are this recording's, checked when it was made. What a
        subclass keeps derived from the data (a field it makes fresh, not given) starts empty again."""
        gyro = np.asarray(gyro_dps, dtype=float)
        if gyro.ndim == 1:
            gyro = gyro[:, None]
        if gyro.shape != self.gyro_dps.shape:
            raise InputError(
                f"{self.source}: gyro data has shape {gyro.shape}, expected {self.gyro_dps.shape} for "
                f"axes {self.gyro_axes}"
            )
        _require_finite(self.source, self.row_numbers, ((self.gyro_axes, gyro),))
        copied = copy.copy(self)
        object.__setattr__(copied, "gyro_dps", gyro)
        for f in dataclasses.fields(copied):
            if not f.init and f.default_factory is not dataclasses.MISSING:
                object.__setattr__(copied, f.name, f.default_factory())
        return copied

    def take(self, index: slice | np.ndarray) -> "Recording":
        """The rows selected by a slice, boolean mask or index array, as a new recording."""
        pick = lambda a: None if a is None else a[index]  # noqa: E731
        return dataclasses.replace(
            self,
            time_s=self.time_s[index],
            gyro_dps=self.gyro_dps[index],
            temperature_degc=pick(self.temperature_degc),
            accel_g=pick(self.accel_g),
            reference_rate_dps=pick(self.reference_rate_dps),
            row_numbers=self.row_numbers[index],
        )


__all__ = [
    "ACCEL_AXES",
    "GAP_FACTOR",
    "GYRO_AXES",
    "Gap",
    "Gaps",
    "POSSIBLE",
    "REFERENCE_RATE_AXES",
    "Recording",
    "TEMPERATURE_COLUMN",
    "nominal_rate_hz",
]
