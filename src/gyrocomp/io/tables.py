"""CSV and Parquet tables: the default layout, column mappings, unit conversion, write-back."""

from __future__ import annotations

import codecs
import csv
import dataclasses
import io
import lzma
import os
import re
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.csv as pacsv
import pyarrow.parquet as pq

from ..errors import DataQualityWarning, InputError, LayoutError, TimeOrderError
from ..recording import ACCEL_AXES, GYRO_AXES, REFERENCE_RATE_AXES, TEMPERATURE_COLUMN, Recording
from ..units import unit_factor
from .digest import file_sha256
from .atomic import arrow_source, atomic_path, require_unchanged
from .resource_limits import PARQUET_MEMORY_FACTOR, address_space_left, estimated_table_bytes, require_memory
from .serial import looks_headerless, read_headerless

from .layout import NOMINAL_TIME, TIME_COLUMN, TableLayout, parse_column_mapping


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


@dataclass(frozen=True)
class TextFormat:
    """How a text table separates its fields and writes its decimal point (``delimiter`` one of ``,``, ``;``, a
    tab, or :data:`SPACE` for runs of spaces and tabs; ``decimal`` ``.`` or ``,``), how many lines before its header are a preamble that is skipped
    (``preamble_lines``: a logger's metadata such as ``Fs,100``; :func:`preamble_lines`), its text's encoding
    (:func:`text_encoding`), and the fields of a line of units under its header, skipped (``units``:
    :func:`units_line`; None without one)."""

    delimiter: str = ","
    decimal: str = "."
    preamble_lines: int = 0
    encoding: str = "utf-8"
    units: tuple[str, ...] | None = None

    @classmethod
    def found(cls, head: bytes, layout: "TableLayout") -> "TextFormat":
        """A table's format from its first bytes (:func:`sniff_csv`, :func:`preamble_lines`), where ``layout``
        does not name it."""
        delimiter, decimal = sniff_csv(head)
        delimiter = layout.delimiter or delimiter
        skipped = preamble_lines(head, delimiter)
        units = units_line(head, delimiter, skipped)
        if skipped or units is not None:  # the decimal point told from the first row, not a preamble's or the units'
            lines = head.split(b"\n")
            decimal = sniff_csv(b"\n".join([lines[skipped], *lines[skipped + 1 + (units is not None) :]]))[1]
        return cls(delimiter, layout.decimal or decimal, skipped, text_encoding(head), units)

    @property
    def spaced(self) -> bool:
        """Whether fields are separated by runs of spaces and tabs (:data:`SPACE`), read through
        :class:`SpacedText` as separated by :data:`SPACED_AS` (a decimal comma stays a decimal comma)."""
        return self.delimiter == SPACE

    def parse_options(self) -> pacsv.ParseOptions:
        """pyarrow's parsing options for this format (:data:`SPACED_AS` for a table of spaces, which :meth:`source`
        gives it so)."""
        return pacsv.ParseOptions(delimiter=SPACED_AS if self.spaced else self.delimiter)

    def source(self, path: Path, source):
        """What pyarrow reads of the table at ``path``: ``source`` (its bytes, decompressed), or for a table of
        spaces the same bytes with each run of spaces and tabs between fields made one :data:`SPACED_AS`
        (:class:`SpacedText`)."""
        if not self.spaced:
            return source
        return pa.PythonFile(SpacedText(open_csv_bytes(path, csv_codec(path))), mode="r")

    def read_options(self, block_bytes: int | None = None) -> pacsv.ReadOptions:
        """pyarrow's reading options for this format: blocks of ``block_bytes`` [bytes] (default
        :data:`CSV_BLOCK_BYTES`), the preamble skipped, the text decoded."""
        return pacsv.ReadOptions(
            block_size=block_bytes or CSV_BLOCK_BYTES,
            skip_rows=self.preamble_lines,
            skip_rows_after_names=0 if self.units is None else 1,
            encoding=self.encoding,
        )


#: the delimiter of a table whose fields are separated by runs of spaces and tabs (columns aligned by padding, as
#: Fortran, MATLAB's ``save -ascii`` and many instruments write them)
SPACE = " "
#: what a run of spaces between fields is read as: a semicolon, so that a decimal comma (``0,25   1,5``) stays one
SPACED_AS = ";"
#: runs of spaces and tabs at a line's start or end, and between fields
_EDGE_SPACES = re.compile(rb"(?:^|(?<=[\r\n]))[ \t]+|[ \t]+(?=[\r\n]|\Z)")
_INNER_SPACES = re.compile(rb"[ \t]+")


def spaced_as_fields(text: bytes) -> bytes:
    """Complete lines of a table of spaces with each run of spaces and tabs between fields made one
    :data:`SPACED_AS`, those at a line's start and end removed."""
    return _INNER_SPACES.sub(SPACED_AS.encode(), _EDGE_SPACES.sub(b"", text))


class SpacedText(io.RawIOBase):
    """A table of spaces read as one of :data:`SPACED_AS` (:func:`spaced_as_fields`), a block of lines at a time: the bytes
    after a block's last line end wait for the next block, so that a run of spaces is never cut in two.

    Parameters
    ----------
    raw : file-like
        The table's bytes (``read(n)``), decompressed; closed with this.
    block_bytes : int
        Bytes read at once [bytes].
    """

    def __init__(self, raw, block_bytes: int = 1 << 20):
        self._raw, self._block = raw, int(block_bytes)
        self._out, self._rest, self._ended = b"", b"", False

    def readable(self) -> bool:
        return True

    def readinto(self, buffer) -> int:
        while not self._out and not self._ended:
            block = self._raw.read(self._block)
            if not block:
                self._out, self._rest, self._ended = spaced_as_fields(self._rest), b"", True
                break
            text = self._rest + block
            end = max(text.rfind(b"\n"), text.rfind(b"\r")) + 1
            self._out, self._rest = spaced_as_fields(text[:end]), text[end:]
        n = min(len(buffer), len(self._out))
        buffer[:n] = self._out[:n]
        self._out = self._out[n:]
        return n

    def close(self) -> None:
        if not self.closed:
            self._raw.close()
        super().close()


def text_encoding(head: bytes) -> str:
    """The encoding of a text table from its first bytes: UTF-8 (ASCII too) where they decode as UTF-8 (a character
    cut at their end allowed), else Windows-1252, which a spreadsheet on Windows in Western Europe writes
    (``Temperatur [\u00b0C]`` with the degree sign as the one byte 0xB0), or ISO 8859-1 where a byte is none of
    Windows-1252's. The names are read as such files mean them; what gyrocomp writes is UTF-8."""
    try:
        codecs.getincrementaldecoder("utf-8")().decode(head, final=False)
        return "utf-8"
    except UnicodeDecodeError:
        pass
    try:
        head.decode("cp1252")
        return "cp1252"
    except UnicodeDecodeError:
        return "latin-1"


def header_line(text_format: TextFormat | None) -> int:
    """The line just before a table's first row (1-based): its header's, after a text table's preamble, or the line
    of units under it; 1 for Parquet (no lines)."""
    if text_format is None:
        return 1
    return 1 + text_format.preamble_lines + (text_format.units is not None)


def output_text_format(path: str | os.PathLike, source: TextFormat | None = None) -> TextFormat:
    """The format an output text table is written in: a ``.tsv`` name means tabs; otherwise the input's format
    (``source``), so that the next command reading the output with the same project file reads it; a comma and a
    decimal point where there is no input table. A decimal comma is kept only beside another separator. What gyrocomp
    writes is UTF-8, whatever the input's encoding."""
    name = Path(path).name.lower()
    for compressed in COMPRESSED_SUFFIXES:
        name = name.removesuffix(compressed)
    base = (
        dataclasses.replace(source, preamble_lines=0, encoding="utf-8", units=None)
        if source is not None
        else TextFormat()
    )
    if name.endswith(".tsv"):
        return TextFormat("\t", base.decimal)
    return base if base.delimiter != "," or base.decimal == "." else TextFormat()


#: compressed CSV, told by its first bytes: the codec's name for pyarrow (xz through Python's lzma)
_COMPRESSED = ((b"\x1f\x8b", "gzip"), (b"BZh", "bz2"), (b"\x28\xb5\x2f\xfd", "zstd"), (b"\xfd7zXZ\x00", "xz"))
#: CSV bytes parsed at once (the longest line a table may have)
CSV_BLOCK_BYTES = 1 << 20
#: field separators a CSV may use (vendor exports, spreadsheets in locales with a decimal comma)
DELIMITERS = (",", ";", "\t")


#: the most bytes a table's header line may take, and the most columns it may name
HEADER_MAX_BYTES = 1 << 20
MAX_COLUMNS = 10_000
#: what a damaged compressed file raises while it is read
DECOMPRESS_ERRORS = (OSError, EOFError, lzma.LZMAError, pa.ArrowInvalid)


def csv_codec(path: Path) -> str | None:
    """The compression of a text table, told by its first bytes (gzip, bz2, zstd, xz), or None."""
    with open(path, "rb") as fh:
        magic = fh.read(6)
    return next((name for sig, name in _COMPRESSED if magic.startswith(sig)), None)


def open_csv_bytes(path: Path, codec: str | None) -> pa.NativeFile:
    """The file's bytes, decompressed as they are read (memory bounded by what is read at once, whatever the
    file expands to)."""
    source = arrow_source(path)
    if codec is None:
        return pa.OSFile(source, "rb") if isinstance(source, str) else pa.PythonFile(source, mode="r")
    if codec == "xz":
        return pa.PythonFile(lzma.open(path), mode="r")
    return pa.input_stream(source, compression=codec)


#: the byte-order marks of UTF-16 and UTF-32 text (a spreadsheet's "Unicode text" export), which pyarrow does not read
_WIDE_TEXT_MARKS = (
    (b"\xff\xfe\x00\x00", "UTF-32"),
    (b"\x00\x00\xfe\xff", "UTF-32"),
    (b"\xff\xfe", "UTF-16"),
    (b"\xfe\xff", "UTF-16"),
)


def text_head(path: Path, codec: str | None) -> bytes:
    """A text table's first bytes (up to :data:`HEADER_MAX_BYTES`, decompressed), its lines ended by ``\\n`` whatever
    ends them in the file (``\\r\\n``; a lone ``\\r``, as a Macintosh CSV export writes them, which pyarrow reads
    as line ends too), for the sniffing of its format and header; the header checked (:func:`check_header`). Text in
    UTF-16 or UTF-32, and bytes that are no text (a NUL byte: a file of another format named ``.csv``), are refused
    in one line."""
    try:
        with open_csv_bytes(path, codec) as peek:
            head = peek.read(HEADER_MAX_BYTES)
    except DECOMPRESS_ERRORS as exc:
        raise InputError(f"{path}: a {codec} file that does not decompress ({str(exc).splitlines()[0]})") from None
    wide = next((name for mark, name in _WIDE_TEXT_MARKS if head.startswith(mark)), None)
    if wide is not None:
        raise InputError(
            f"{path}: {wide} text (it starts with a {wide} byte-order mark); gyrocomp reads tables in UTF-8 or ASCII: "
            'save it as UTF-8 (a spreadsheet\'s "CSV UTF-8")'
        )
    nul = head.find(b"\x00", 0, 1 << 16)
    if nul >= 0:
        raise InputError(
            f"{path}: not a text table: byte {nul} is a NUL, which no text holds (a binary file, or a file of "
            "another format named as a table?)"
        )
    head = head.replace(b"\r\n", b"\n").replace(b"\r", b"\n")
    check_header(path, head)
    return head


def check_header(path: Path, head: bytes) -> None:
    """Refuse, in one line saying what is too big, a text table whose first line is longer than
    :data:`HEADER_MAX_BYTES` or names more than :data:`MAX_COLUMNS` columns (reading it would take the memory
    and time of a million empty columns)."""
    first = head.split(b"\n", 1)[0]
    if b"\n" not in head and len(head) >= HEADER_MAX_BYTES:
        raise InputError(
            f"{path}: its first line is over {HEADER_MAX_BYTES >> 20} MB long, which no table's header "
            f"is (more than {MAX_COLUMNS} columns, or a damaged or binary file); keep the columns "
            "gyrocomp reads (time, gyro, accelerometer, temperature) in a file of their own"
        )
    columns = max(first.count(d.encode()) for d in DELIMITERS) + 1
    if columns > MAX_COLUMNS:
        raise InputError(
            f"{path}: the header names {columns} columns; gyrocomp reads tables of up to "
            f"{MAX_COLUMNS}: keep the columns it reads (time, gyro, accelerometer, temperature) in a "
            "file of their own"
        )


def _csv_bytes(path: Path) -> tuple[pa.NativeFile | str, bytes]:
    """The CSV's source for pyarrow (gzip, bz2, zstd or xz decompressed as they are read, by their magic bytes)
    and its first bytes as :func:`text_head` gives them."""
    codec = csv_codec(path)
    head = text_head(path, codec)
    return (arrow_source(path) if codec is None else open_csv_bytes(path, codec)), head


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


def read_error(path: Path, exc: Exception, head: bytes) -> InputError:
    """One line for a text table that pyarrow could not read (``exc``): a line too long for a block, a file that
    does not decompress, or a parse error with a hint for a log without a header line."""
    text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    if "straddl" in text:
        return InputError(
            f"{path}: a line over {CSV_BLOCK_BYTES >> 20} MB long, which no row of a table is (a "
            "damaged file, or text that is no table)"
        )
    if not isinstance(exc, pa.ArrowInvalid):
        return InputError(f"{path}: cannot be read to its end ({text}); a damaged or cut-short compressed file?")
    return InputError(f"{path}: not a readable CSV table ({text}){_headerless_hint(head)}")


def sniff_csv(head: bytes) -> tuple[str, str]:
    """(delimiter, decimal point) of a CSV from its first bytes: the separator that splits the header into the
    most fields (comma on a tie; the first line that holds one where the first line holds none, a preamble's),
    and a decimal comma when the separator is not a comma and a number in the first
    data row has one."""
    lines = head.decode("utf-8", errors="replace").splitlines()
    header = lines[0] if lines else ""
    aligned = not any(d in header for d in DELIMITERS) and _aligned(lines[:-1][:5])
    if not aligned and not any(d in header for d in DELIMITERS):  # a preamble's first line (// Start Time: ...)
        header = next((line for line in lines[1:] if any(d in line for d in DELIMITERS)), header)
    delimiter = max(DELIMITERS, key=lambda d: (header.count(d), d == ","))
    at = lines.index(header) if header in lines else 0
    if aligned or (_aligned(lines[at : at + 2]) and not _same_fields(lines[at : at + 2], delimiter)):
        delimiter = SPACE  # fields aligned by spaces (and tabs among them, which do not split the rows alike)
    decimal = "."
    if delimiter != "," and len(lines) > 1:
        cells = [c.strip().strip('"') for c in fields_of(lines[1], delimiter)]
        if any(c.replace("-", "", 1).replace(",", "", 1).isdigit() and "," in c for c in cells):
            decimal = ","
    return delimiter, decimal


def _aligned(lines: list[str]) -> bool:
    """Whether ``lines`` (two at least: a header and rows) split by runs of spaces and tabs into the same number of
    fields, at least two: a table of spaces (a decimal comma is no separator there; tabs among the spaces align),
    not a preamble before another table's header (``// Start Time: ...``, whose lines split otherwise)."""
    counts = {len(fields_of(line, SPACE)) for line in lines}
    return len(lines) >= 2 and len(counts) == 1 and counts.pop() >= 2


def _same_fields(lines: list[str], delimiter: str) -> bool:
    """Whether a header and the row after it (``lines``) split by ``delimiter`` into as many fields."""
    return len(lines) == 2 and len(fields_of(lines[0], delimiter)) == len(fields_of(lines[1], delimiter))


def fields_of(line: str, delimiter: str) -> list[str]:
    """A line's fields by ``delimiter`` as a CSV reads them (quotes kept together); by runs of spaces and tabs for
    a table of spaces (:data:`SPACE`)."""
    if delimiter == SPACE:
        return line.split()
    return next(csv.reader([line.rstrip("\r")], delimiter=delimiter), [])


def _is_number(text: str) -> bool:
    """Whether a field is a number (a decimal comma too)."""
    try:
        float(text.strip().strip('"').replace(",", ".", 1))
    except ValueError:
        return False
    return True


def units_line(head: bytes, delimiter: str, preamble: int = 0) -> tuple[str, ...] | None:
    """The fields of a line of units right under a text table's header (``s;deg/s;deg/s;degC``, as data
    acquisition tools write one), from the table's first bytes ``head`` (lines ended by ``\\n``) after ``preamble``
    lines; None where there is none: the line splits into as many fields as the header, none of them a number and
    one at least not empty, and the line after it holds a number."""
    lines = head.decode("utf-8", "replace").split("\n")[:-1]
    if len(lines) < preamble + 3:
        return None
    names, units, row = (fields_of(lines[preamble + k], delimiter) for k in range(3))
    if len(units) != len(names) or not any(u.strip() for u in units) or any(_is_number(u) for u in units if u.strip()):
        return None
    return tuple(u.strip() for u in units) if any(_is_number(x) for x in row) else None


#: the most lines before a text table's header skipped as its preamble
MAX_PREAMBLE_LINES = 50


def preamble_lines(head: bytes, delimiter: str) -> int:
    """The lines before a text table's header that are a preamble (a logger's metadata: ``Fs,100``, ``Logging
    Type,1``), from its first bytes ``head``: the header is the first line from which every complete line of
    ``head`` splits into the same number of fields (at least two) by ``delimiter``, and is not a row of numbers.
    0 when that is the first line, when the lines after it are too few to tell (fewer than two), when the header
    would lie past :data:`MAX_PREAMBLE_LINES`, or when it is a row of numbers (a log without a header line after
    its preamble, which the table's names read)."""
    lines = head.decode("utf-8", "replace").split("\n")[:-1]  # the last piece: a line not complete, or nothing
    counts = [len(fields_of(line, delimiter)) for line in lines]
    if len(counts) < 3 or counts[-1] < 2:
        return 0
    first = len(counts) - 1
    while first > 0 and counts[first - 1] == counts[-1]:
        first -= 1
    if first == 0 or first > MAX_PREAMBLE_LINES or len(counts) - first < 3 or looks_headerless(lines[first]):
        return 0
    return first


def _read_arrow(path: Path, fmt: str, layout: TableLayout, select=None) -> tuple[pa.Table, TextFormat | None]:
    """The table, and a text table's format (None for Parquet); ``select`` (a function of the header's names
    giving the names to read, or None for all) reads only some columns. A table without a header line
    (``layout.names``) is read by :func:`gyrocomp.io.serial.read_headerless`."""
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
        source, head = _csv_bytes(path)
        if not head.strip():
            raise InputError(f"{path}: the file is empty; expected a header such as time,gyro_z,temperature")
        text = TextFormat.found(head[:4096], layout)
        source = text.source(path, source)
        parse = text.parse_options()
        convert = pacsv.ConvertOptions(strings_can_be_null=True, decimal_point=text.decimal)
        try:
            if select is not None:  # the header's names, from its line
                names_line = head.split(b"\n")[text.preamble_lines]
                names_line = spaced_as_fields(names_line) if text.spaced else names_line
                header = pacsv.read_csv(
                    pa.py_buffer(names_line + b"\n"),
                    read_options=pacsv.ReadOptions(encoding=text.encoding),
                    parse_options=parse,
                )
                convert.include_columns = select(header.column_names)
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


def _headerless_hint(head: bytes) -> str:
    """A hint for a CSV that does not parse whose lines after the first are numbers: a serial terminal's log, a
    banner where the header should be."""
    lines = [line for line in head[:4096].decode("utf-8", "replace").splitlines()[1:-1] if line.strip()]
    if lines and sum(map(looks_headerless, lines)) > len(lines) / 2:
        return (
            "; if it has no header line (a serial terminal's log), give its columns' names in order: "
            "names=gyro_x,gyro_y,gyro_z,temperature"
        )
    return ""


def release_table_memory() -> None:
    """Give the memory of the tables no longer held back to the system: Arrow's default pool (jemalloc or mimalloc)
    keeps what a table freed for the next one, and a fit's working memory would come on top of it (measured: a fit
    of an hour at 1 kHz read from Parquet, 1.10 GB peak resident without this, 0.82 GB with it)."""
    pa.default_memory_pool().release_unused()


def arrow_floats(values: np.ndarray) -> pa.Array:
    """A float64 Arrow array of ``values`` (zero-copy when they are contiguous float64). Unlike ``pa.array``, it
    does not make pyarrow import pandas (a third of a second at start-up)."""
    values = np.ascontiguousarray(values, dtype=np.float64)
    return pa.Array.from_buffers(pa.float64(), values.size, [None, pa.py_buffer(values)])


def arrow_indices(values: np.ndarray) -> pa.Array:
    """An int64 Arrow array of ``values`` (row indices for ``take``), without pandas (see :func:`arrow_floats`)."""
    values = np.ascontiguousarray(values, dtype=np.int64)
    return pa.Array.from_buffers(pa.int64(), values.size, [None, pa.py_buffer(values)])


def _to_numpy(array: pa.ChunkedArray) -> np.ndarray:
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
    validity, data = chunk.buffers()[:2]
    dtype = np.dtype(
        np.float32 if pa.types.is_float32(kind) else np.float64 if pa.types.is_float64(kind) else kind.to_pandas_dtype()
    )
    values = np.frombuffer(data, dtype=dtype, count=len(chunk), offset=chunk.offset * dtype.itemsize)
    values = values.astype(float, copy=False)
    if chunk.null_count:
        bits = np.unpackbits(np.frombuffer(validity, dtype=np.uint8), bitorder="little")
        valid = bits[chunk.offset : chunk.offset + len(chunk)].astype(bool)
        values = np.where(valid, values, np.nan)
    return values


def _numeric_column(
    table: pa.Table, column: str, source: Path, first_row: int = 0, header_line: int = 1, decimal: str = "."
) -> np.ndarray:
    """A column as float64; a value that is no number is one line naming its row in the file (the table's rows
    after ``first_row`` of them) and its line (the line before the first row is ``header_line``, 1-based). A
    column read as text because one value is no number keeps its numbers' ``decimal`` point (a comma), so that
    the message names that value, not the first number."""
    array = table.column(column)
    if pa.types.is_floating(array.type) or pa.types.is_integer(array.type):
        return _to_numpy(array).astype(float, copy=False)
    if pa.types.is_null(array.type):
        return np.full(len(array), np.nan)
    if pa.types.is_boolean(array.type) or pa.types.is_timestamp(array.type):
        raise InputError(f"{source}: column {column!r} has type {array.type}; expected numbers")
    if pa.types.is_nested(array.type):
        raise InputError(f"{source}: column {column!r} {vector_column(array.type)}")
    try:  # numbers stored as text (quoted, say): one vectorized cast; only on failure find the bad row
        return _to_numpy(array.cast(pa.float64()))  # pyarrow.compute, loaded only here (70 ms)
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
    :func:`_numeric_column`'s."""
    array = table.column(column)
    clock = _clock_s(array, source, column, first_row, header_line, after_s)
    if clock is None:
        return _numeric_column(table, column, source, first_row, header_line, decimal) * unit_factor(
            "time", time_unit, "time_unit"
        )
    if unit_factor("time", time_unit, "time_unit") != 1.0:
        raise InputError(
            f"{source}: column {column!r} holds dates or times of day, whose unit is their own; time_unit="
            f"{time_unit!r} is for a column of numbers"
        )
    return clock


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
        return _to_numpy(array.cast(pa.int64())) * _CLOCK_UNIT_S[kind.unit]
    if pa.types.is_time(kind):
        whole = pa.int64() if kind.bit_width == 64 else pa.int32()
        return _past_midnight(_to_numpy(array.cast(whole)) * _CLOCK_UNIT_S[kind.unit], after_s)
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
            hms = _to_numpy(pc.list_flatten(parts).cast(pa.float64())).reshape(-1, 3)
        except (pa.ArrowInvalid, pa.ArrowNotImplementedError):
            hms = None
        if hms is not None and np.all(hms[:, :2] == np.round(hms[:, :2])):
            out = np.full(len(array), np.nan)
            out[_to_numpy(pc.is_valid(array).cast(pa.int8())).astype(bool)] = hms @ np.array([3600.0, 60.0, 1.0])
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


#: suffixes of delimited text tables (the delimiter is told from the header: comma, semicolon, tab, space)
TEXT_TABLE_SUFFIXES = (".csv", ".tsv", ".txt", ".dat")
#: suffixes of compressed text tables after their own (``run.csv.gz``), read as they stream
COMPRESSED_SUFFIXES = (".gz", ".bz2", ".xz", ".zst")
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


def _resolved_columns(header: list[str], layout: TableLayout, path: Path) -> dict[str, str]:
    """Canonical name to column, refusing a repeated column name, a missing time column or no gyro column."""
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
    warnings.warn(rows_dropped(path, n - kept.size, n), DataQualityWarning, stacklevel=3)
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


def _channel_selector(channels: tuple[str, ...], layout: TableLayout, path: Path, chosen: dict):
    """The columns to read for ``channels`` (and time), resolved on the whole header (so a mapping may name any
    column), the channels found put in ``chosen``."""
    wanted = {TIME_COLUMN, *channels}

    def select(names: list[str]) -> list[str]:
        found = _resolved_columns(names, layout, path)
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
    select = None if channels is None else _channel_selector(tuple(channels), layout, path, chosen)
    opened = os.stat(path) if path.is_file() else None
    try:
        table, text_format = _read_arrow(path, fmt, layout, select)
    except InputError:
        if opened is not None:  # a file replaced while it was read (opened by path more than once): said so
            require_unchanged(path, opened)
        raise
    if opened is not None:
        require_unchanged(path, opened)
    if table.num_rows == 0:
        raise InputError(f"{path}: a header but no data rows")
    cols = chosen if channels is not None else _resolved_columns(table.column_names, layout, path)
    recording, kept = table_recording(
        table, cols, layout, path, fmt, drop_nonfinite=drop_nonfinite, text_format=text_format
    )
    if recording.gaps:
        longest = recording.gaps.longest()
        warnings.warn(
            f"{path}: {len(recording.gaps)} time gap(s) longer than 2 sample periods (longest {longest.duration_s:.6g} s "
            f"after row {longest.after_row}); kept as they are, nothing interpolated",
            DataQualityWarning,
            stacklevel=2,
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
    num = lambda name: _numeric_column(table, cols[name], path, first_row, line, decimal)  # noqa: E731
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
        else:
            text_format = text_format or TextFormat()
            decimal = with_decimal(table, text_format)
            try:
                pacsv.write_csv(decimal, tmp, _csv_options(table.column_names, text_format))
            except pa.ArrowInvalid:  # a text value holds the separator: every text value quoted, as pyarrow does
                pacsv.write_csv(decimal, tmp, _csv_options(table.column_names, text_format, quote_text=True))


def _csv_options(
    names: list[str], text_format: TextFormat | None = None, quote_text: bool = False
) -> pacsv.WriteOptions:
    """A header as other tools write and expect it: names unquoted unless one needs quotes; fields separated
    by ``text_format``'s delimiter (default a comma)."""
    text_format = text_format or TextFormat()
    delimiter = text_format.delimiter
    plain = not any(ch in name for name in names for ch in (delimiter, '"', "\n", "\r"))
    # numbers written with a decimal comma are text to pyarrow, which quotes every text value: not quoted here
    # (a value that would need quotes is refused by the writer, never written ambiguous), unless ``quote_text``
    values = {"quoting_style": "none"} if text_format.decimal == "," and not quote_text else {}
    try:
        return pacsv.WriteOptions(quoting_header="none" if plain else "needed", delimiter=delimiter, **values)
    except TypeError:  # pyarrow without the option (before 17): its default, quoted names
        return pacsv.WriteOptions(delimiter=delimiter, **values)


def with_decimal(table: pa.Table, text_format: TextFormat) -> pa.Table:
    """``table`` with its floating-point columns as text with a decimal comma, where ``text_format`` has one
    (pyarrow's CSV writer writes a point); unchanged otherwise."""
    if text_format.decimal == ".":
        return table
    import pyarrow.compute as pc  # loaded only for a decimal comma (70 ms)

    for k, field in enumerate(table.schema):
        if pa.types.is_floating(field.type):
            text = pc.replace_substring(table.column(k).cast(pa.string()), ".", ",")
            table = table.set_column(k, field.name, text)
    return table


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
    text table is written with the input's separator and decimal point (:func:`output_text_format`: a ``.tsv``
    name means tabs).
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
    the input's columns, units, separator and decimal point (:func:`output_text_format`), atomically: a piece of a
    log that reads as the log does."""
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
    separator and decimal point of ``text_format`` (the input's, say), a ``.tsv`` name meaning tabs
    (:func:`output_text_format`)."""
    path = Path(path)
    _write_arrow(
        recording_table(recording, extra_columns),
        path,
        fmt or detect_table_format(path) or "csv",
        output_text_format(path, text_format),
    )


__all__ = [
    "TableLayout",
    "TableData",
    "TextFormat",
    "header_line",
    "output_text_format",
    "preamble_lines",
    "parse_column_mapping",
    "read_table",
    "write_gyro_back",
    "write_recording",
    "write_rows",
    "recording_table",
    "table_data",
    "file_sha256",
    "table_recording",
]
