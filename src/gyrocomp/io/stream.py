"""CSV and Parquet tables read and written in chunks, so a command's memory is bounded by the chunk, whatever the
file's length: CSV through pyarrow's streaming reader (``pyarrow.csv.open_csv``, compressed files decompressed as
they stream), Parquet by record batches (``ParquetFile.iter_batches``), written through ``CSVWriter`` or
``ParquetWriter`` into a temporary file renamed over the target at the end (atomic, as every output).

Each chunk is validated as a whole file is (:class:`gyrocomp.Recording`: finite values, increasing time, row numbers
of the file in the messages); time must also increase from one chunk to the next; gaps and dropped rows are counted
over the whole file and reported once, as :func:`gyrocomp.io.read_table` reports them.
"""

from __future__ import annotations

import contextlib
import lzma
import os
import sys
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.csv as pacsv
import pyarrow.parquet as pq

from ..errors import DataQualityWarning, InputError, user_stacklevel
from ..recording import ACCEL_AXES, GYRO_AXES, Recording
from .atomic import arrow_source, atomic_path, require_unchanged
from .tables import (
    TableLayout,
    channel_selector,
    read_arrow,
    resolved_columns,
    check_parquet_footer,
    detect_table_format,
    rows_dropped,
    table_recording,
)
from .text_format import (
    CSV_BLOCK_BYTES,
    DECOMPRESS_ERRORS,
    TextFormat,
    csv_write_options,
    csv_codec,
    open_csv_bytes,
    output_text_format,
    read_error,
    text_head,
    text_sink,
    with_decimal,
)

#: rows per chunk (about 100 MB of numbers for an 8-column table)
CHUNK_ROWS = 262144
#: CSV bytes parsed at once by the streaming reader, CSV_BLOCK_BYTES (1 MB; it infers the column types from the
#: first block; it reads about twenty blocks ahead, so larger blocks cost memory: 16 MB blocks held 300 MB)


class NotStreamable(Exception):
    """The file cannot be read in chunks as it is (a CSV column whose type changes after the first block): the
    caller reads it whole instead."""


@dataclass(frozen=True, eq=False)
class TableChunk:
    """Consecutive rows of a table: the rows as read (``table``, every column), the recording built from those
    kept (``kept``: 0-based indices in this chunk), and the index of its first row in the file."""

    table: pa.Table
    recording: Recording
    kept: np.ndarray
    first_row: int


class TableStream:
    """A CSV or Parquet table read in chunks of about ``chunk_rows`` rows (see the module); with ``channels``, only
    those channels' columns (and time) are read, as :func:`gyrocomp.io.read_table` reads them."""

    def __init__(
        self,
        path,
        layout: TableLayout | None = None,
        *,
        fmt: str | None = None,
        drop_nonfinite: bool = False,
        chunk_rows: int = CHUNK_ROWS,
        progress=None,
        channels: tuple[str, ...] | None = None,
    ):
        self.path = Path(path)
        self.layout = layout or TableLayout()
        self.fmt = fmt or detect_table_format(self.path) or "csv"
        if not self.path.exists():
            raise InputError(f"{self.path}: no such file")
        if self.path.is_dir():
            raise InputError(f"{self.path}: is a folder, not a file")
        if int(chunk_rows) != chunk_rows or chunk_rows < 2:
            raise InputError(f"chunk_rows: a whole number of at least 2, got {chunk_rows!r}")
        self.drop_nonfinite = drop_nonfinite
        self.chunk_rows = int(chunk_rows)
        self.progress = progress  # called with the fraction of the file read
        self._source = None  # the open CSV file, whose position tells the progress (None: compressed)
        self._total_rows: int | None = None  # a Parquet file's rows, read once for the progress
        self._read: list[str] | None = None  # the columns read (None: all)
        #: a text table's separator and decimal point (None for Parquet)
        self.text_format: TextFormat | None = None
        #: a table without a header line, read whole (a serial terminal's log: :mod:`gyrocomp.io.serial`)
        self._headerless: pa.Table | None = None
        self._opened = os.stat(self.path)  # the file as it was when the reading began
        self.schema = self._open_schema()
        if channels is None:
            self.columns = resolved_columns(self.schema.names, self.layout, self.path)
        else:  # only these channels' columns (and time) are read, as read_table(channels=...)
            self.columns = {}
            self._read = channel_selector(tuple(channels), self.layout, self.path, self.columns)(self.schema.names)
        self.gyro_axes = tuple(a for a in GYRO_AXES if a in self.columns)
        self.accel_axes = tuple(a for a in ACCEL_AXES if a in self.columns)
        self.rows = 0
        self.rows_dropped = 0
        self.gaps = 0
        self.longest_gap: tuple[float, int] | None = None  # (duration [s], after row)

    # ------------------------------------------------------------------ reading
    def _open_schema(self) -> pa.Schema:
        if self.layout.names is not None:
            self._headerless, self.text_format = read_arrow(self.path, self.fmt, self.layout)
            return self._headerless.schema
        if self.fmt == "parquet":
            check_parquet_footer(self.path)
            try:
                return pq.ParquetFile(arrow_source(self.path)).schema_arrow
            except (pa.ArrowInvalid, OSError) as exc:
                raise InputError(f"{self.path}: not a readable Parquet file ({str(exc).splitlines()[0]})") from None
        with self._csv_reader() as reader:
            return reader.schema

    @contextlib.contextmanager
    def _csv_reader(self):
        codec = csv_codec(self.path)
        head = b""
        with contextlib.ExitStack() as stack:
            try:
                head = text_head(self.path, codec)
                if not head.strip():
                    raise InputError(
                        f"{self.path}: the file is empty; expected a header such as time,gyro_z,temperature"
                    )
                self.text_format = TextFormat.found(head[:4096], self.layout)
                source = stack.enter_context(self.text_format.source(self.path, open_csv_bytes(self.path, codec)))
                self._source = source if codec is None and not self.text_format.spaced else None
                parse = self.text_format.parse_options()
                convert = pacsv.ConvertOptions(
                    strings_can_be_null=True, decimal_point=self.text_format.decimal, include_columns=self._read or []
                )
                reader = pacsv.open_csv(
                    source,
                    read_options=self.text_format.read_options(CSV_BLOCK_BYTES),
                    parse_options=parse,
                    convert_options=convert,
                )
            except DECOMPRESS_ERRORS as exc:
                raise read_error(self.path, exc, head) from None
            yield reader

    def _batches(self) -> Iterator[pa.RecordBatch]:
        if self._headerless is not None:
            table = self._headerless if self._read is None else self._headerless.select(self._read)
            yield from table.to_batches(max_chunksize=self.chunk_rows)
            return
        if self.fmt == "parquet":
            # without pre-buffering: pyarrow would keep every row group's read-ahead until the file is closed
            # (memory growing with the file, about 12 bytes a row)
            yield from pq.ParquetFile(arrow_source(self.path), pre_buffer=False).iter_batches(
                batch_size=self.chunk_rows, columns=self._read
            )
            return
        with self._csv_reader() as reader:
            while True:
                try:
                    batch = reader.read_next_batch()
                except StopIteration:
                    return
                except pa.ArrowInvalid as exc:  # a later block does not fit the types of the first
                    if "straddl" in str(exc):  # a line longer than a block: no row
                        raise read_error(self.path, exc, b"") from None
                    raise NotStreamable(str(exc).splitlines()[0]) from None
                except (OSError, EOFError, lzma.LZMAError) as exc:  # a compressed file damaged further on
                    raise read_error(self.path, exc, b"") from None
                yield batch

    def _tables(self) -> Iterator[pa.Table]:
        """Batches gathered into tables of about ``chunk_rows`` rows, none of fewer than 2 (a short last one is
        joined to the one before)."""
        gathered, rows, held = [], 0, None
        for batch in self._batches():
            offset = 0
            while offset < batch.num_rows:  # a batch longer than a chunk is cut
                take = min(batch.num_rows - offset, self.chunk_rows - rows)
                gathered.append(batch.slice(offset, take))
                rows += take
                offset += take
                if rows >= self.chunk_rows:
                    if held is not None:
                        yield held
                    held = pa.Table.from_batches(gathered)
                    gathered, rows = [], 0
        rest = pa.Table.from_batches(gathered) if gathered else None
        if held is not None and rest is not None and rest.num_rows < 2:
            held, rest = pa.concat_tables([held, rest]), None
        for table in (held, rest):
            if table is not None:
                yield table

    def chunks(self) -> Iterator[TableChunk]:
        """The file's rows as :class:`TableChunk` s, each validated as a recording."""
        last: tuple[float, int] | None = None  # time [s] and row number of the previous chunk's last row
        period = None
        first = 0
        for table in self._tables():
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", DataQualityWarning)  # rows dropped: counted over the file, said once
                recording, kept = table_recording(
                    table,
                    self.columns,
                    self.layout,
                    self.path,
                    self.fmt,
                    drop_nonfinite=self.drop_nonfinite,
                    first_row=first,
                    text_format=self.text_format,
                    time_after_s=None if last is None else last[0],
                )
            self.rows_dropped += table.num_rows - kept.size
            time_s = recording.time_s
            if last is not None:
                step = float(time_s[0] - last[0])
                if not step > 0:
                    raise InputError(
                        f"{self.path}: row {first + kept[0] + 1}: time {time_s[0]!r} s does not "
                        f"increase (row {last[1]}: {last[0]!r} s); sort the file by time"
                    )
                if step > 2.0 * period:
                    self._gap(step, last[1])
            period = period or 1.0 / recording.rate_hz
            longest = recording.gaps.longest()
            if longest is not None:  # the chunk's gaps: counted, the longest kept (as one by one)
                self.gaps += len(recording.gaps) - 1
                self._gap(longest.duration_s, longest.after_row)
            last = (float(time_s[-1]), int(first + kept[-1] + 1))
            self.rows += table.num_rows
            self._report()
            yield TableChunk(table, recording, kept, first)
            first += table.num_rows
        if self.rows == 0:
            raise InputError(f"{self.path}: a header but no data rows")
        require_unchanged(self.path, self._opened)
        if self.progress:
            self.progress(1.0)

    def _report(self) -> None:
        if not self.progress:
            return
        if self.fmt == "parquet":
            if self._total_rows is None:
                self._total_rows = pq.ParquetFile(arrow_source(self.path)).metadata.num_rows
            self.progress(self.rows / self._total_rows if self._total_rows else 1.0)
        elif self._source is not None:
            with contextlib.suppress(OSError, ValueError):
                self.progress(self._source.tell() / max(self.path.stat().st_size, 1))

    def _gap(self, duration_s: float, after_row: int) -> None:
        self.gaps += 1
        if self.longest_gap is None or duration_s > self.longest_gap[0]:
            self.longest_gap = (duration_s, after_row)

    def warn_summary(self) -> None:
        """The warnings a whole-file read gives: rows dropped, time gaps (once each, for the whole file)."""
        if self.rows_dropped:
            warnings.warn(
                rows_dropped(self.path, self.rows_dropped, self.rows), DataQualityWarning, stacklevel=user_stacklevel()
            )
        if self.gaps:
            duration, row = self.longest_gap
            warnings.warn(
                f"{self.path}: {self.gaps} time gap(s) longer than 2 sample periods (longest "
                f"{duration:.6g} s after row {row}); kept as they are, nothing interpolated",
                DataQualityWarning,
                stacklevel=user_stacklevel(),
            )


class TableWriter:
    """A CSV or Parquet table written chunk by chunk into a temporary file, renamed over ``path`` when the block
    ends without an error (else removed): use as a context manager, :meth:`write` each chunk. ``computed`` names
    the columns whose values were computed (compensated rates): Parquet stores them without a dictionary, which
    only costs time on continuous values (twice the writing time in row groups of 2^18 rows)."""

    def __init__(
        self, path, fmt: str | None = None, *, computed: tuple[str, ...] = (), text_format: TextFormat | None = None
    ):
        self.path = Path(path)
        self.fmt = fmt or detect_table_format(self.path) or "csv"
        self.computed = tuple(computed)
        #: a text table's separator and decimal point (:func:`gyrocomp.io.text_format.output_text_format` of the input's)
        self.text_format = output_text_format(self.path, text_format)
        self._writer = None
        self._schema: pa.Schema | None = None
        self._stack = contextlib.ExitStack()

    def __enter__(self) -> "TableWriter":
        self._tmp = self._stack.enter_context(atomic_path(self.path))
        return self

    def write(self, table: pa.Table) -> None:
        if self._writer is None:
            self._schema = table.schema
            if self.fmt == "parquet":
                dictionary = [n for n in table.column_names if n not in self.computed] if self.computed else True
                self._writer = pq.ParquetWriter(self._tmp, table.schema, use_dictionary=dictionary)
            else:
                self._writer = pacsv.CSVWriter(
                    text_sink(self._tmp, self.path, self._stack),
                    with_decimal(table, self.text_format).schema,
                    write_options=csv_write_options(table.column_names, self.text_format),
                )
        elif table.schema != self._schema:
            try:
                table = table.cast(self._schema)
            except (pa.ArrowInvalid, pa.ArrowNotImplementedError) as exc:
                raise NotStreamable(str(exc).splitlines()[0]) from None
        try:
            self._writer.write_table(table if self.fmt == "parquet" else with_decimal(table, self.text_format))
        except pa.ArrowInvalid as exc:  # a text value that would need quotes beside numbers with a decimal comma
            raise NotStreamable(str(exc).splitlines()[0]) from None

    def __exit__(self, kind, value, traceback) -> bool:
        try:
            if self._writer is not None:
                self._writer.close()
        except BaseException:
            self._stack.__exit__(*sys.exc_info())
            raise
        return self._stack.__exit__(kind, value, traceback)


__all__ = ["CHUNK_ROWS", "NotStreamable", "TableChunk", "TableStream", "TableWriter"]
