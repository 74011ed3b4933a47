"""CSV and Parquet tables: the default layout, column mappings, unit conversion, write-back (a text table's format:
:mod:`gyrocomp.io.text_format`; a column's values: :mod:`gyrocomp.io.columns`)."""

from __future__ import annotations

import contextlib
import os
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.csv as pacsv
import pyarrow.parquet as pq

from ..errors import DataQualityWarning, InputError, LayoutError, TimeOrderError, user_stacklevel
from ..recording import ACCEL_AXES, GYRO_AXES, REFERENCE_RATE_AXES, TEMPERATURE_COLUMN, Recording
from ..units import unit_factor
from .digest import file_sha256
from .atomic import arrow_source, atomic_path, require_unchanged
from .resource_limits import PARQUET_MEMORY_FACTOR, address_space_left, estimated_table_bytes, require_memory
from .serial import looks_headerless, read_headerless

from .layout import NOMINAL_TIME, TIME_COLUMN, TableLayout, parse_column_mapping
from .columns import arrow_floats, arrow_indices, numeric_column, time_column_s
from .text_format import (
    COMPRESSED_SUFFIXES,
    DECOMPRESS_ERRORS,
    TEXT_TABLE_SUFFIXES,
    TextFormat,
    csv_source,
    csv_write_options,
    csv_codec,
    header_line,
    output_text_format,
    read_error,
    spaced_as_fields,
    text_head,
    text_sink,
    with_decimal,
)


@dataclass(frozen=True, eq=False)
class TableData:
    """A table as read, with the recording built from it and what is needed to write results back (the field
    separator and decimal point of a text table, ``text_format``; None for Parquet or a log)."""

    recording: Recording
    table: pa.Table
    layout: TableLayout
    resolved_columns: dict[str, str]
    kept_rows: np.ndarray  # 0-based indices of table rows that are in the recording
    path: Path
    text_format: "TextFormat | None" = None


#: the largest Parquet footer (the file's metadata) read [bytes]: 16 MB is 15,000 row groups of 8 columns; a file
#: of 100,000 one-row groups has 35 MB, which pyarrow turns into gigabytes before a row is read
PARQUET_FOOTER_MAX_BYTES = 16 << 20


def check_parquet_footer(path: Path) -> None:
    """Refuse in one line a Parquet file whose metadata is larger than :data:`PARQUET_FOOTER_MAX_BYTES` (very many
    small row groups), before pyarrow parses it; its length is the 4 bytes before the closing ``PAR1``."""
    try:
        with open(path, "rb") as fh:
            fh.seek(0, os.SEEK_END)
            if fh.tell() < 12:
                return  # too short to be Parquet: pyarrow says so
            fh.seek(-8, os.SEEK_END)
            tail = fh.read(8)
    except OSError:
        return
    footer = int.from_bytes(tail[:4], "little")
    if tail[4:] == PARQUET_MAGIC and footer > PARQUET_FOOTER_MAX_BYTES:
        raise InputError(
            f"{path}: its metadata takes {footer / 1e6:.0f} MB (over {PARQUET_FOOTER_MAX_BYTES >> 20} MB: "
            "very many small row groups), which would take gigabytes to read; rewrite it with larger "
            "row groups, e.g. pyarrow.parquet.write_table(table, path, row_group_size=1_000_000)"
        )


def read_arrow(path: Path, fmt: str, layout: TableLayout, select=None) -> tuple[pa.Table, TextFormat | None]:
    """A table file as pyarrow reads it.

    Parameters
    ----------
    path : Path
        The file.
    fmt : {"csv", "parquet"}
        Its format (a text table of any separator, compressed or not; or Parquet).
    layout : TableLayout
        How to read it (a table without a header line, ``layout.names``, is read by
        :func:`gyrocomp.io.serial.read_headerless`).
    select : callable, optional
        A function of the header's names giving the names to read; None reads every column.

    Returns
    -------
    table : pyarrow.Table
    text_format : TextFormat or None
        A text table's separator, decimal point, preamble and encoding; None for Parquet.
    """
    if not path.exists():
        raise InputError(f"{path}: no such file")
    if path.is_dir():
        raise InputError(f"{path}: is a folder, not a file")
    if layout.names is not None:
        if fmt != "csv":
            raise InputError(f"{path}: names: for a text table without a header line; a {fmt} file names its columns")
        table = read_headerless(path, layout.names, layout.rate_hz)
        return (table if select is None else table.select(select(table.column_names))), TextFormat()
    if fmt == "csv":
        if address_space_left() is not None:  # under a limit only: the estimate opens the file once more
            require_memory(path, estimated_table_bytes(path, csv_codec(path) is not None))
        source, head = csv_source(path)
        if not head.strip():
            raise InputError(f"{path}: the file is empty; expected a header such as time,gyro_z,temperature")
        text = TextFormat.found(head[:4096], layout)
        source = text.source(path, source)
        parse = text.parse_options()
        convert = pacsv.ConvertOptions(strings_can_be_null=True, decimal_point=text.decimal)
        try:
            if select is not None:  # the header's names, from its line
                convert.include_columns = select(header_names(head, text))
            return pacsv.read_csv(
                source, read_options=text.read_options(), parse_options=parse, convert_options=convert
            ), text
        except DECOMPRESS_ERRORS as exc:
            raise read_error(path, exc, head) from None
    check_parquet_footer(path)
    try:
        if address_space_left() is not None:  # the columns' uncompressed size, from the metadata
            meta = pq.read_metadata(arrow_source(path))
            require_memory(
                path, PARQUET_MEMORY_FACTOR * sum(meta.row_group(i).total_byte_size for i in range(meta.num_row_groups))
            )
        columns = None if select is None else select(pq.read_schema(arrow_source(path)).names)
        return pq.read_table(arrow_source(path), columns=columns), None
    except (pa.ArrowInvalid, OSError) as exc:
        raise InputError(f"{path}: not a readable Parquet file ({str(exc).splitlines()[0]})") from None


def release_table_memory() -> None:
    """Give the memory of the tables no longer held back to the system: Arrow's default pool (jemalloc or mimalloc)
    keeps what a table freed for the next one, and a fit's working memory would come on top of it (measured: a fit
    of an hour at 1 kHz read from Parquet, 1.10 GB peak resident without this, 0.82 GB with it)."""
    pa.default_memory_pool().release_unused()


#: suffixes of Parquet tables
PARQUET_SUFFIXES = (".parquet", ".pq")
#: the first (and last) bytes of a Parquet file
PARQUET_MAGIC = b"PAR1"


def detect_table_format(path: Path) -> str | None:
    suffix = path.suffix.lower()
    if suffix in COMPRESSED_SUFFIXES and Path(path.stem).suffix.lower() in TEXT_TABLE_SUFFIXES:
        return "csv"  # compressed CSV, e.g. run.csv.gz
    if suffix in TEXT_TABLE_SUFFIXES:
        return "csv"
    if suffix in PARQUET_SUFFIXES:
        return "parquet"
    return None


def header_names(head: bytes, text: TextFormat) -> list[str]:
    """The column names of a text table's header line, from its first bytes ``head`` (:func:`gyrocomp.io.text_format.text_head`) read in
    the format ``text``."""
    names_line = head.split(b"\n")[text.preamble_lines]
    names_line = spaced_as_fields(names_line) if text.spaced else names_line
    return pacsv.read_csv(
        pa.py_buffer(names_line + b"\n"),
        read_options=pacsv.ReadOptions(encoding=text.encoding),
        parse_options=text.parse_options(),
    ).column_names


def table_header(path: str | os.PathLike) -> list[str] | None:
    """The column names of a table file (CSV and its kin, or Parquet), read from its first bytes (a text table's
    header after its preamble, as the reader finds it; a Parquet file's schema); None for a file of another kind or
    one that does not open as a table (reading it says why)."""
    path = Path(path)
    fmt = detect_table_format(path)
    try:
        if fmt == "parquet":
            return list(pq.read_schema(path).names)
        if fmt != "csv":
            return None
        head = text_head(path, csv_codec(path))
        return header_names(head, TextFormat.found(head[:4096], TableLayout())) if head.strip() else None
    except (InputError, OSError, IndexError, pa.ArrowException, *DECOMPRESS_ERRORS):
        return None


def layout_fits(header: list[str], layout: TableLayout, path: str | os.PathLike) -> bool:
    """Whether ``layout`` reads a table of the column names ``header``: its mapping resolves there, and it finds the
    time (or a nominal rate) and a gyro axis (:func:`resolved_columns`)."""
    try:
        resolved_columns(header, layout, Path(path))
    except InputError:
        return False
    return True


def resolved_columns(header: list[str], layout: TableLayout, path: Path) -> dict[str, str]:
    """The column that holds each channel, by the channel's canonical name.

    Parameters
    ----------
    header : list of str
        The table's column names.
    layout : TableLayout
        Its mapping and its nominal rate (a table without a time column).
    path : Path
        The file, for messages.

    Returns
    -------
    dict
        Canonical name (``time``, ``gyro_z``, ``temperature`` ...) to column.

    Raises
    ------
    InputError
        A column name repeated; LayoutError (an InputError) without a time column (or a rate) or a gyro column.
    """
    repeated = sorted({name for name in header if header.count(name) > 1})
    if repeated:
        raise InputError(
            f"{path}: column {repeated[0]!r} appears {header.count(repeated[0])} times in the header; "
            "give each column its own name"
        )
    cols = layout.resolve(header, str(path))
    if layout.names is None and looks_headerless(",".join(header)):
        raise InputError(
            f"{path}: the first line is numbers ({','.join(header)[:60]}), not the columns' names: a "
            "table without a header line; give the names in order (names=gyro_x,gyro_y,gyro_z,"
            "temperature), and the sample rate if it has no time column (rate_hz=50)"
        )
    timed_by_rate = layout.names is not None and layout.rate_hz is not None and TIME_COLUMN not in layout.names
    if layout.rate_hz is not None and TIME_COLUMN in cols and not timed_by_rate:
        raise InputError(
            f"{path}: rate_hz={layout.rate_hz:g}: the file has a time column ({cols[TIME_COLUMN]!r}); "
            "a nominal rate is for tables without one, or to read the rows at it instead of the file's time "
            "leave the time unread (columns={'time': ''})"
        )
    if layout.rate_hz is not None and TIME_COLUMN not in cols:
        cols[TIME_COLUMN] = NOMINAL_TIME
    if TIME_COLUMN not in cols:
        raise LayoutError(
            f"{path}: no 'time' column (the file has {', '.join(header)}); map one with columns={{'time': 'NAME'}}, "
            "or give the rows' sample rate (rate_hz=50) where the file has no time",
            path,
        )
    if not any(a in cols for a in GYRO_AXES):
        raise LayoutError(
            f"{path}: no gyro column (expected gyro_x, gyro_y or gyro_z; the file has {', '.join(header)}); "
            "map one with columns={'gyro_z': 'NAME'}",
            path,
        )
    return cols


def _temperature_columns(cols: dict[str, str], gyro_axes: tuple[str, ...]) -> list[str]:
    """One temperature per gyro axis (temperature_x, ...) when all are there and no plain one; else the plain one."""
    per_axis = [f"{TEMPERATURE_COLUMN}_{a[-1]}" for a in gyro_axes]
    if all(t in cols for t in per_axis) and TEMPERATURE_COLUMN not in cols:
        return per_axis
    return [TEMPERATURE_COLUMN] if TEMPERATURE_COLUMN in cols else []


def rows_dropped(path, dropped: int, rows: int) -> str:
    """What :func:`keep_finite_rows` says of ``dropped`` of ``rows`` rows left out (a reader in chunks: once)."""
    return f"{path}: dropped {dropped} of {rows} rows with empty, NaN or infinite values"


def keep_finite_rows(path: Path, time_s: np.ndarray, *channels: np.ndarray | None) -> tuple[np.ndarray, list]:
    """The indices of rows where every channel is finite and the channels cut to them (a warning says how many
    rows went)."""
    n = time_s.size
    ok = np.isfinite(time_s)
    for values in channels:
        if values is not None:
            ok &= np.isfinite(values.reshape(n, -1)).all(axis=1)
    if ok.all():
        return np.arange(n), [time_s, *channels]
    kept = np.flatnonzero(ok)
    warnings.warn(rows_dropped(path, n - kept.size, n), DataQualityWarning, stacklevel=user_stacklevel())
    return kept, [time_s[kept], *(None if v is None else v[kept] for v in channels)]


def _reference_rates(cols: dict[str, str], num, path: Path, factor: float) -> np.ndarray | None:
    """The rate table's reference rates (n, 3) [deg/s, in the gyro's unit in the file], or None; all three or none."""
    present = [a for a in REFERENCE_RATE_AXES if a in cols]
    if not present:
        return None
    if len(present) < 3:
        missing = [a for a in REFERENCE_RATE_AXES if a not in cols]
        raise InputError(
            f"{path}: reference rate column(s) {', '.join(missing)} missing; give all three "
            f"({', '.join(REFERENCE_RATE_AXES)}, 0 about the axes the table does not turn)"
        )
    return np.column_stack([num(a) for a in REFERENCE_RATE_AXES]) * factor


def channel_selector(channels: tuple[str, ...], layout: TableLayout, path: Path, chosen: dict):
    """The columns to read for ``channels`` (and time), resolved on the whole header (so a mapping may name any
    column), the channels found put in ``chosen``."""
    wanted = {TIME_COLUMN, *channels}

    def select(names: list[str]) -> list[str]:
        found = resolved_columns(names, layout, path)
        chosen.update({channel: column for channel, column in found.items() if channel in wanted})
        if not any(a in chosen for a in GYRO_AXES):
            raise InputError(
                f"{path}: none of the channels read ({', '.join(channels)}) is a gyro axis of the "
                f"file ({', '.join(a for a in GYRO_AXES if a in found)})"
            )
        return [column for column in dict.fromkeys(chosen.values()) if column != NOMINAL_TIME]

    return select


def read_table(
    path: str | os.PathLike,
    layout: TableLayout | None = None,
    *,
    fmt: str | None = None,
    drop_nonfinite: bool = False,
    channels: tuple[str, ...] | None = None,
) -> TableData:
    """Read a CSV or Parquet table into a :class:`Recording`, keeping the table for write-back.

    Parameters
    ----------
    path : path
        The file. Default layout: ``time,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z,temperature``
        in [s], [deg/s], [g], [degC]; any subset of gyro axes, accelerometer optional,
        ``temperature_x/_y/_z`` for one temperature per axis.
    layout : TableLayout, optional
        Column mapping and units for other layouts.
    fmt : {"csv", "parquet"}, optional
        Format; detected from the suffix when not given.
    drop_nonfinite : bool
        Drop rows where a used channel is empty, NaN or infinite (a :class:`DataQualityWarning`
        says how many) instead of refusing the file.
    channels : tuple of str, optional
        Read only these channels' columns (and time); the table kept holds only those.
    """
    layout = layout or TableLayout()
    path = Path(path)
    fmt = fmt or detect_table_format(path) or "csv"
    chosen: dict[str, str] = {}
    select = None if channels is None else channel_selector(tuple(channels), layout, path, chosen)
    opened = os.stat(path) if path.is_file() else None
    try:
        table, text_format = read_arrow(path, fmt, layout, select)
    except InputError:
        if opened is not None:  # a file replaced while it was read (opened by path more than once): said so
            require_unchanged(path, opened)
        raise
    if opened is not None:
        require_unchanged(path, opened)
    if table.num_rows == 0:
        raise InputError(f"{path}: a header but no data rows")
    cols = chosen if channels is not None else resolved_columns(table.column_names, layout, path)
    recording, kept = table_recording(
        table, cols, layout, path, fmt, drop_nonfinite=drop_nonfinite, text_format=text_format
    )
    if recording.gaps:
        longest = recording.gaps.longest()
        warnings.warn(
            f"{path}: {len(recording.gaps)} time gap(s) longer than 2 sample periods (longest {longest.duration_s:.6g} s "
            f"after row {longest.after_row}); kept as they are, nothing interpolated",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
    return TableData(recording, table, layout, cols, kept, path, text_format)


def table_recording(
    table: pa.Table,
    cols: dict[str, str],
    layout: TableLayout,
    path: Path,
    fmt: str,
    *,
    drop_nonfinite: bool = False,
    first_row: int = 0,
    text_format: TextFormat | None = None,
    time_after_s: float | None = None,
) -> tuple[Recording, np.ndarray]:
    """The recording [s, deg/s, g, degC] of a table's rows (``cols``: channel -> column) and the indices of the
    rows kept in it (all, or those with every used value finite when ``drop_nonfinite``; a warning says how many
    went). ``first_row``: the table's first row in its file (0-based); ``text_format``: a text table's (None for
    Parquet), for its decimal point and the row and line numbers in messages; ``time_after_s``: the time of the
    row before [s] (times of day run on from it). Used by :func:`read_table` and, a chunk at a time, by
    :class:`gyrocomp.io.stream.TableStream`."""
    line = header_line(text_format)
    decimal = text_format.decimal if text_format is not None else "."
    gyro_axes = tuple(a for a in GYRO_AXES if a in cols)
    accel_axes = tuple(a for a in ACCEL_AXES if a in cols)
    temp_names = _temperature_columns(cols, gyro_axes)
    gyro_factor = unit_factor("gyro", layout.gyro_unit, "gyro_unit")
    num = lambda name: numeric_column(table, cols[name], path, first_row, line, decimal)  # noqa: E731
    if cols[TIME_COLUMN] == NOMINAL_TIME:  # a table without time, at a nominal rate
        time_s = (first_row + np.arange(table.num_rows)) / layout.rate_hz
    else:
        time_s = time_column_s(table, cols[TIME_COLUMN], layout.time_unit, path, first_row, line, decimal, time_after_s)
    gyro = np.column_stack([num(a) for a in gyro_axes])
    gyro *= gyro_factor  # in place: a long table's columns are not copied twice
    temp = np.column_stack([num(t) for t in temp_names]) if temp_names else None
    accel = np.column_stack([num(a) for a in accel_axes]) if accel_axes else None
    if accel is not None:
        accel *= unit_factor("accel", layout.accel_unit, "accel_unit")
    reference = _reference_rates(cols, num, path, gyro_factor)
    n = table.num_rows
    kept = np.arange(n)
    if drop_nonfinite:
        kept, (time_s, gyro, temp, accel, reference) = keep_finite_rows(path, time_s, gyro, temp, accel, reference)
        if kept.size < 2:
            raise InputError(
                f"{path}: rows {first_row + 1}..{first_row + n}: fewer than 2 rows with values in every used column"
            )
    try:
        recording = Recording(
            time_s=time_s,
            gyro_dps=gyro,
            gyro_axes=gyro_axes,
            temperature_degc=temp,
            accel_g=accel,
            accel_axes=accel_axes,
            reference_rate_dps=reference,
            source=str(path),
            row_numbers=first_row + kept + 1,
            metadata={"path": str(path), "format": fmt, "rows_dropped": int(n - kept.size)},
        )
    except TimeOrderError as exc:
        raise _coarse_stamps_hint(exc, time_s) from None
    return recording, kept


def _coarse_stamps_hint(exc: TimeOrderError, time_s: np.ndarray) -> TimeOrderError:
    """``exc`` with, where the time repeats and runs on overall, the way to read the rows at their mean rate: a
    clock coarser than the samples (stamps in ms at 1 kHz with jitter) repeats some of them."""
    span_s = float(time_s[-1] - time_s[0]) if time_s.size > 1 else 0.0
    if not exc.repeated or not np.isfinite(span_s) or span_s <= 0:
        return exc
    rate_hz = (time_s.size - 1) / span_s
    return TimeOrderError(
        f"{exc}; if the stamps are coarser than the samples, read the rows at their mean rate instead "
        f"(columns={{'time': ''}}, rate_hz={rate_hz:.6g})",
        exc.row,
        exc.repeated,
    )


def _write_arrow(table: pa.Table, path: Path, fmt: str, text_format: TextFormat | None = None) -> None:
    with atomic_path(path) as tmp:
        if fmt == "parquet":
            pq.write_table(table, tmp)
            return
        text_format = text_format or TextFormat()
        decimal = with_decimal(table, text_format)
        for quote_text in (False, True):  # a text value holding the separator: every text value quoted, as pyarrow does
            try:
                with contextlib.ExitStack() as stack:
                    pacsv.write_csv(
                        decimal,
                        text_sink(tmp, path, stack),
                        csv_write_options(table.column_names, text_format, quote_text=quote_text),
                    )
                return
            except pa.ArrowInvalid:
                if quote_text:
                    raise


def write_gyro_back(
    data: TableData,
    gyro_dps: np.ndarray,
    path: str | os.PathLike,
    *,
    fmt: str | None = None,
    accel_g: np.ndarray | None = None,
) -> None:
    """Write the table as read with its gyro columns replaced by ``gyro_dps`` [deg/s] (and its accelerometer
    columns by ``accel_g`` [g], when given).

    Values are converted back to the file's units; every other column and the column order are unchanged, and a
    text table is written by its name (:func:`~gyrocomp.io.text_format.output_text_format`: ``.csv`` commas or the
    input's semicolons, ``.tsv`` tabs, another name the input's).
    Rows dropped on reading (``drop_nonfinite``) are left out of the output as well, as ``convert`` does: a
    row that could not be compensated is not written with its valid values replaced. Written atomically.
    """
    path = Path(path)
    fmt = fmt or detect_table_format(path) or "csv"
    table = data.table
    if data.kept_rows.size < table.num_rows:
        table = table.take(arrow_indices(data.kept_rows))
    replaced = [(data.recording.gyro_axes, gyro_dps, unit_factor("gyro", data.layout.gyro_unit))]
    if accel_g is not None:
        replaced.append((data.recording.accel_axes, accel_g, unit_factor("accel", data.layout.accel_unit)))
    for axes, values_internal, factor in replaced:
        for j, axis in enumerate(axes):
            column = data.resolved_columns[axis]
            values = values_internal[:, j] / factor
            table = table.set_column(table.column_names.index(column), column, arrow_floats(values))
    _write_arrow(table, path, fmt, output_text_format(path, data.text_format))


def write_rows(data: TableData, samples: slice, path: str | os.PathLike, *, fmt: str | None = None) -> None:
    """Write the table as read, the rows of the recording's ``samples`` only (a slice of its sample indices), in
    the input's columns and units, a text table by its name (:func:`~gyrocomp.io.text_format.output_text_format`),
    atomically: a piece of a log that reads as the log does."""
    path = Path(path)
    rows = data.kept_rows[samples]
    _write_arrow(
        data.table.take(arrow_indices(rows)),
        path,
        fmt or detect_table_format(path) or "csv",
        output_text_format(path, data.text_format),
    )


def recording_table(recording: Recording, extra_columns: dict[str, np.ndarray] | None = None) -> pa.Table:
    """A recording as a table in the default layout ([s], [deg/s], [g], [degC])."""
    columns: dict[str, np.ndarray] = {TIME_COLUMN: recording.time_s}
    for j, axis in enumerate(recording.gyro_axes):
        columns[axis] = recording.gyro_dps[:, j]
    for j, axis in enumerate(recording.accel_axes):
        columns[axis] = recording.accel_g[:, j]
    if recording.temperature_degc is not None:
        temps = recording.temperature_degc.reshape(recording.n_samples, -1)
        for j, name in enumerate(recording.temperature_columns):
            columns[name] = temps[:, j]
    if recording.reference_rate_dps is not None:
        for j, name in enumerate(REFERENCE_RATE_AXES):
            columns[name] = recording.reference_rate_dps[:, j]
    for name, values in (extra_columns or {}).items():
        columns[name] = np.asarray(values, dtype=float)
    return pa.table({name: arrow_floats(values) for name, values in columns.items()})


def table_data(recording: Recording) -> TableData:
    """A recording read from a log, as table data in the default layout, so results can be written back."""
    table = recording_table(recording)
    return TableData(
        recording,
        table,
        TableLayout(),
        {name: name for name in table.column_names},
        np.arange(recording.n_samples),
        Path(recording.source),
    )


def write_recording(
    recording: Recording,
    path: str | os.PathLike,
    *,
    fmt: str | None = None,
    extra_columns: dict[str, np.ndarray] | None = None,
    text_format: TextFormat | None = None,
) -> None:
    """Write a recording in the default layout ([s], [deg/s], [g], [degC]), atomically; a text table with the
    format :func:`~gyrocomp.io.text_format.output_text_format` gives for its name and ``text_format`` (the input's,
    say)."""
    path = Path(path)
    _write_arrow(
        recording_table(recording, extra_columns),
        path,
        fmt or detect_table_format(path) or "csv",
        output_text_format(path, text_format),
    )


__all__ = [
    "header_names",
    "layout_fits",
    "table_header",
    "TableLayout",
    "TableData",
    "parse_column_mapping",
    "read_table",
    "write_gyro_back",
    "write_recording",
    "write_rows",
    "recording_table",
    "table_data",
    "file_sha256",
    "table_recording",
    "read_arrow",
    "resolved_columns",
    "channel_selector",
]
