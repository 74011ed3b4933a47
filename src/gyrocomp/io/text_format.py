"""How a text table is written: its field separator (a comma, semicolon or tab, or runs of spaces), decimal point,
preamble, line of units and encoding, told from its first bytes (:class:`TextFormat`); its first bytes read and
checked (:func:`text_head`); a table of spaces read as one of separators (:class:`SpacedText`); and the format an
output table is written in (:func:`output_text_format`)."""

from __future__ import annotations

import codecs
import csv
import dataclasses
import io
import lzma
import os
import re
from dataclasses import dataclass
from pathlib import Path

import pyarrow as pa
import pyarrow.csv as pacsv

from ..errors import InputError
from .atomic import arrow_source
from .layout import TableLayout
from .serial import looks_headerless


@dataclass(frozen=True)
class TextFormat:
    """How a text table separates its fields and writes its decimal point (``delimiter`` one of ``,``, ``;``, a
    tab, or :data:`SPACE` for runs of spaces and tabs; ``decimal`` ``.`` or ``,``), how many lines before its header are a preamble that is skipped
    (``preamble_lines``: a logger's metadata such as ``Fs,100``; :func:`preamble_lines`), its text's encoding
    (:func:`text_encoding`), the fields of a line of units under its header, skipped (``units``:
    :func:`units_line`; None without one), and whether the reading options named the separator or the decimal
    point rather than the file's first bytes telling them (``given``)."""

    delimiter: str = ","
    decimal: str = "."
    preamble_lines: int = 0
    encoding: str = "utf-8"
    units: tuple[str, ...] | None = None
    given: bool = False

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
        given = bool(layout.delimiter or layout.decimal)
        return cls(delimiter, layout.decimal or decimal, skipped, text_encoding(head), units, given)

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
    """The format an output text table is written in: a ``.tsv`` name means tabs; a ``.csv`` name the input's format
    (``source``) where it separates by commas or semicolons (the two conventions of the name: a decimal-comma
    locale's spreadsheet writes semicolons) or the reading options named it (``source.given``: the next command
    reading the output with the same options then reads it), else (tabs, aligned spaces) commas and decimal points;
    any other name, the input's format; a comma and a decimal point where there is no input table. A decimal comma
    is kept only beside another separator. What gyrocomp writes is UTF-8, whatever the input's encoding."""
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
    if name.endswith(".csv") and not base.given and base.delimiter not in (",", ";"):
        return TextFormat()
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


def csv_source(path: Path) -> tuple[pa.NativeFile | str, bytes]:
    """The CSV's source for pyarrow (gzip, bz2, zstd or xz decompressed as they are read, by their magic bytes)
    and its first bytes as :func:`text_head` gives them."""
    codec = csv_codec(path)
    head = text_head(path, codec)
    return (arrow_source(path) if codec is None else open_csv_bytes(path, codec)), head


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


#: suffixes of delimited text tables (the delimiter is told from the header: comma, semicolon, tab, space)
TEXT_TABLE_SUFFIXES = (".csv", ".tsv", ".txt", ".dat")

#: suffixes of compressed text tables after their own (``run.csv.gz``), read as they stream
COMPRESSED_SUFFIXES = (".gz", ".bz2", ".xz", ".zst")
#: pyarrow's codec of each compressed suffix it writes (xz through Python's lzma)
_WRITTEN_CODECS = {".gz": "gzip", ".bz2": "bz2", ".zst": "zstd"}


def text_sink(tmp: str | os.PathLike, name: str | os.PathLike, stack) -> object:
    """Where a text table named ``name`` is written, at the temporary path ``tmp``: the file itself, or a stream
    compressing into it when the name ends in ``.gz``, ``.bz2``, ``.zst`` or ``.xz`` (read back as such:
    :func:`compression`); closed by ``stack`` (a :class:`contextlib.ExitStack`), so that the compressed file is
    complete before it is renamed into place."""
    suffix = Path(name).suffix.lower()
    if suffix == ".xz":
        return stack.enter_context(pa.PythonFile(stack.enter_context(lzma.open(tmp, "wb")), mode="w"))
    if suffix in _WRITTEN_CODECS:
        return stack.enter_context(pa.CompressedOutputStream(os.fspath(tmp), _WRITTEN_CODECS[suffix]))
    return tmp


def csv_write_options(
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


__all__ = [
    "COMPRESSED_SUFFIXES",
    "CSV_BLOCK_BYTES",
    "DECOMPRESS_ERRORS",
    "DELIMITERS",
    "SPACE",
    "SPACED_AS",
    "SpacedText",
    "TEXT_TABLE_SUFFIXES",
    "TextFormat",
    "check_header",
    "csv_codec",
    "fields_of",
    "header_line",
    "open_csv_bytes",
    "output_text_format",
    "preamble_lines",
    "read_error",
    "sniff_csv",
    "spaced_as_fields",
    "text_encoding",
    "text_head",
    "text_sink",
    "units_line",
    "with_decimal",
    "csv_source",
    "csv_write_options",
]
