"""A table column's values as numbers: float64 arrays of Arrow columns (and back), numbers stored as text, the time
column in its unit or as dates and times of day, a column of vectors refused saying so."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pyarrow as pa

from ..errors import InputError
from ..units import unit_factor
from .stamps import TICKS_PER_SECOND, ticks_s


def arrow_floats(values: np.ndarray) -> pa.Array:
    """A float64 Arrow array of ``values`` (zero-copy when they are contiguous float64). Unlike ``pa.array``, it
    does not make pyarrow import pandas (a third of a second at start-up)."""
    values = np.ascontiguousarray(values, dtype=np.float64)
    return pa.Array.from_buffers(pa.float64(), values.size, [None, pa.py_buffer(values)])


def arrow_indices(values: np.ndarray) -> pa.Array:
    """An int64 Arrow array of ``values`` (row indices for ``take``), without pandas (see :func:`arrow_floats`)."""
    values = np.ascontiguousarray(values, dtype=np.int64)
    return pa.Array.from_buffers(pa.int64(), values.size, [None, pa.py_buffer(values)])


def arrow_numbers(array: pa.ChunkedArray) -> np.ndarray:
    """The column's numbers as float64 [its unit], nulls as NaN, read from the chunks' buffers: pyarrow's
    ``to_numpy`` imports pandas (a third of a second at start-up)."""
    parts = [_chunk_numbers(chunk) for chunk in array.chunks]
    if not parts:
        return np.empty(0)
    return parts[0] if len(parts) == 1 else np.concatenate(parts)


def _chunk_numbers(chunk: pa.Array) -> np.ndarray:
    kind = chunk.type
    if not (pa.types.is_integer(kind) or pa.types.is_float32(kind) or pa.types.is_float64(kind)):
        return chunk.to_numpy(zero_copy_only=False).astype(float, copy=False)
    validity = chunk.buffers()[0]
    values = _chunk_values(chunk).astype(float, copy=False)
    if chunk.null_count:
        bits = np.unpackbits(np.frombuffer(validity, dtype=np.uint8), bitorder="little")
        valid = bits[chunk.offset : chunk.offset + len(chunk)].astype(bool)
        values = np.where(valid, values, np.nan)
    return values


def _chunk_values(chunk: pa.Array) -> np.ndarray:
    """A numeric chunk's values in their own dtype, read from its data buffer (nulls not masked)."""
    kind = chunk.type
    dtype = np.dtype(
        np.float32 if pa.types.is_float32(kind) else np.float64 if pa.types.is_float64(kind) else kind.to_pandas_dtype()
    )
    return np.frombuffer(chunk.buffers()[1], dtype=dtype, count=len(chunk), offset=chunk.offset * dtype.itemsize)


def numeric_column(
    table: pa.Table, column: str, source: Path, first_row: int = 0, header_line: int = 1, decimal: str = "."
) -> np.ndarray:
    """A column as float64; a value that is no number is one line naming its row in the file (the table's rows
    after ``first_row`` of them) and its line (the line before the first row is ``header_line``, 1-based). A
    column read as text because one value is no number keeps its numbers' ``decimal`` point (a comma), so that
    the message names that value, not the first number."""
    array = table.column(column)
    if pa.types.is_floating(array.type) or pa.types.is_integer(array.type):
        return arrow_numbers(array).astype(float, copy=False)
    if pa.types.is_null(array.type):
        return np.full(len(array), np.nan)
    if pa.types.is_boolean(array.type) or pa.types.is_timestamp(array.type):
        raise InputError(f"{source}: column {column!r} has type {array.type}; expected numbers")
    if pa.types.is_nested(array.type):
        raise InputError(f"{source}: column {column!r} {vector_column(array.type)}")
    try:  # numbers stored as text (quoted, say): one vectorized cast; only on failure find the bad row
        return arrow_numbers(array.cast(pa.float64()))  # pyarrow.compute, loaded only here (70 ms)
    except (pa.ArrowInvalid, pa.ArrowNotImplementedError):
        pass
    values = array.to_pylist()
    out = np.empty(len(values))
    for i, value in enumerate(values):
        if value is None:
            out[i] = np.nan
            continue
        try:
            out[i] = float(value.replace(",", ".", 1) if decimal == "," and isinstance(value, str) else value)
        except (TypeError, ValueError):
            row = first_row + i + 1
            raise InputError(
                f"{source}: row {row} (line {header_line + row}), column {column!r}: {value!r} is not a number"
            ) from None
    return out


#: seconds per unit of Arrow's timestamps and times of day
_CLOCK_UNIT_S = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}

#: a time of day as text: hours, minutes, seconds and a fraction (12:00:01.250)
_TIME_OF_DAY = re.compile(r"\s*\d{1,2}:\d{2}:\d{2}(\.\d+)?\s*")


def vector_column(kind: pa.DataType) -> str:
    """What a column of vectors (an Arrow list or struct per row, as pandas' arrays and ROS conversions write a
    3-axis rate) holds, and that gyrocomp reads a column per axis."""
    width = f"{kind.list_size} numbers" if pa.types.is_fixed_size_list(kind) else "numbers"
    held = f"fields {', '.join(f.name for f in kind)}" if pa.types.is_struct(kind) else f"a list of {width}"
    return f"holds {held} in each row (a vector); gyrocomp reads one column per axis: split it into x, y and z first"


def time_column_s(
    table: pa.Table,
    column: str,
    time_unit: str,
    source: Path,
    first_row: int = 0,
    header_line: int = 1,
    decimal: str = ".",
    after_s: float | None = None,
) -> np.ndarray:
    """The time column [s]: numbers in ``time_unit``; dates with times (ISO 8601 such as ``2024-05-01
    12:00:00.010`` or ``...T12:00:00.010Z``, which pyarrow reads as timestamps; Parquet's timestamps) as seconds
    since 1970-01-01 UTC; times of day (``12:00:00.010``) as seconds since the first day's midnight, running on
    past midnight (``after_s``: the time of the row before, for a chunk after another [s]). A column of dates and
    times has its unit in it: a ``time_unit`` other than s is refused for it. Messages name the row and line as
    :func:`numeric_column`'s."""
    array = table.column(column)
    clock = _clock_s(array, source, column, first_row, header_line, after_s)
    if clock is None:
        per_second = next((n for u, n in TICKS_PER_SECOND.items() if _same_unit(time_unit, u)), None)
        if per_second is not None and pa.types.is_integer(array.type) and not array.null_count:
            return ticks_s(_integers(array), per_second)  # whole ticks since an epoch: exactly, as a bag's stamps
        return numeric_column(table, column, source, first_row, header_line, decimal) * unit_factor(
            "time", time_unit, "time_unit"
        )
    if unit_factor("time", time_unit, "time_unit") != 1.0:
        raise InputError(
            f"{source}: column {column!r} holds dates or times of day, whose unit is their own; time_unit="
            f"{time_unit!r} is for a column of numbers"
        )
    return clock


def _same_unit(time_unit: str, unit: str) -> bool:
    """Whether ``time_unit`` (as the options spell it) is ``unit`` exactly."""
    return unit_factor("time", time_unit, "time_unit") == unit_factor("time", unit, "time_unit")


def _integers(array: pa.ChunkedArray) -> np.ndarray:
    """An integer column without nulls as int64, from its chunks' buffers."""
    parts = [_chunk_values(chunk) for chunk in array.chunks]  # the buffers: pyarrow's to_numpy imports pandas
    return np.concatenate(parts).astype(np.int64, copy=False) if parts else np.empty(0, dtype=np.int64)


def holds_clock(array: pa.ChunkedArray | pa.Array) -> bool:
    """Whether a column holds dates with times or times of day (:func:`time_column_s`), not numbers: an Arrow
    timestamp or time, or text whose first value is a time of day."""
    kind = array.type
    if pa.types.is_timestamp(kind) or pa.types.is_time(kind):
        return True
    if not (pa.types.is_string(kind) or pa.types.is_large_string(kind)):
        return False
    chunks = array.chunks if isinstance(array, pa.ChunkedArray) else [array]
    first = next((v for chunk in chunks for v in chunk.drop_null().slice(0, 1).to_pylist()), None)
    return first is not None and _TIME_OF_DAY.fullmatch(first) is not None


def _clock_s(
    array: pa.ChunkedArray, source: Path, column: str, first_row: int, header_line: int, after_s: float | None = None
) -> np.ndarray | None:
    """A column of timestamps [s since 1970-01-01 UTC] or times of day [s since midnight, run on past it:
    :func:`_past_midnight`]; None for any other."""
    kind = array.type
    if pa.types.is_timestamp(kind):
        return ticks_s(_integers(array.cast(pa.int64())), TICKS_PER_SECOND[kind.unit])
    if pa.types.is_time(kind):
        whole = pa.int64() if kind.bit_width == 64 else pa.int32()
        return _past_midnight(arrow_numbers(array.cast(whole)) * _CLOCK_UNIT_S[kind.unit], after_s)
    if not holds_clock(array):
        return None
    return _past_midnight(_times_of_day(array, source, column, first_row, header_line), after_s)


def _times_of_day(array: pa.ChunkedArray, source: Path, column: str, first_row: int, header_line: int) -> np.ndarray:
    """Text times of day (``hh:mm:ss.fff``) as seconds since midnight [s] (nulls NaN): split and converted by Arrow
    at once, value by value only where that fails, to name the row that is no time of day."""
    import pyarrow.compute as pc  # loaded only for a column of times of day (70 ms)

    parts = pc.split_pattern(array, ":")
    if pc.all(pc.equal(pc.list_value_length(parts), 3)).as_py() is not False:
        try:
            hms = arrow_numbers(pc.list_flatten(parts).cast(pa.float64())).reshape(-1, 3)
        except (pa.ArrowInvalid, pa.ArrowNotImplementedError):
            hms = None
        if hms is not None and np.all(hms[:, :2] == np.round(hms[:, :2])):
            out = np.full(len(array), np.nan)
            out[arrow_numbers(pc.is_valid(array).cast(pa.int8())).astype(bool)] = hms @ np.array([3600.0, 60.0, 1.0])
            return out
    texts = array.to_pylist()
    out = np.full(len(texts), np.nan)
    for i, text in enumerate(texts):
        if text is None:
            continue
        if not _TIME_OF_DAY.fullmatch(text):
            row = first_row + i + 1
            raise InputError(
                f"{source}: row {row} (line {header_line + row}), column {column!r}: {text!r} is not a time of day "
                "(hh:mm:ss.fff, as the first row's)"
            )
        hours, minutes, seconds = text.split(":")
        out[i] = 3600.0 * int(hours) + 60.0 * int(minutes) + float(seconds)
    return out


#: seconds in a day [s]
DAY_S = 86_400.0


def _past_midnight(time_of_day_s: np.ndarray, after_s: float | None = None) -> np.ndarray:
    """Times of day [s] run on past midnight: a step back of more than half a day is the next day's (a log across
    midnight, or longer than a day). ``after_s``: the time of the row before them [s], already run on (a chunk's
    rows after the chunk before)."""
    if time_of_day_s.size == 0:
        return time_of_day_s
    start = 0.0 if after_s is None else DAY_S * np.floor(after_s / DAY_S)
    before = time_of_day_s[0] if after_s is None else after_s - start
    days = np.cumsum(np.diff(time_of_day_s, prepend=before) < -DAY_S / 2)
    return start + time_of_day_s + DAY_S * days


__all__ = [
    "DAY_S",
    "arrow_floats",
    "arrow_indices",
    "arrow_numbers",
    "holds_clock",
    "numeric_column",
    "time_column_s",
    "vector_column",
]
