"""Tables without a header line, as a serial terminal (PuTTY, ``screen``, an Arduino's serial monitor) or a
microcontroller's UART logger writes them: a banner, then one line of numbers per sample, separated by commas,
semicolons, tabs or spaces, a few lines garbled where the link dropped bytes, often no time column.

The columns' names come from the user, in order (``TableLayout.names``, ``--names gyro_x,gyro_y,gyro_z,temperature``;
``gyrocomp init`` writes them into the project file). A line is a row when it holds exactly that many numbers;
every other line (the banner, a garbled or cut line, a repeated header) is skipped, and a warning counts them and
quotes the first. Without a time column, a nominal rate (``--rate 50``) gives each line its time, i ⁄ rate [s]
for the i-th line after the first row: a garbled line keeps its place in time, so the samples after it are not
moved.

The file is read line by line (compressed ones decompressed as they stream); a line longer than
:data:`MAX_LINE_BYTES` is no sample and is skipped unread.
"""

from __future__ import annotations

import bz2
import contextlib
import gzip
import lzma
import math
import re
import warnings
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pyarrow as pa

from ..errors import DataQualityWarning, InputError, printable, user_stacklevel

#: the longest line that can be a row [bytes]: 1 kB holds 40 numbers
MAX_LINE_BYTES = 1024
#: separators between a row's numbers: runs of commas, semicolons, tabs and spaces
_SEPARATORS = re.compile(r"[\s,;]+")
#: magic bytes of compressed text files and their openers
_OPENERS = ((b"\x1f\x8b", gzip.open), (b"BZh", bz2.open), (b"\xfd7zXZ\x00", lzma.open))


def parse_names(text: str) -> tuple[str, ...]:
    """``--names``'s text, ``"gyro_x,gyro_y,gyro_z,temperature"``, as the columns' names in order."""
    return tuple(name.strip() for name in str(text).split(","))


def parse_rate(text: str) -> float:
    """``--rate``'s text: a sample rate [Hz], finite and > 0."""
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise InputError(f"rate_hz: {text!r} is not a number; give the rows' sample rate in Hz, e.g. 50") from None
    return check_rate(value)


def check_rate(value) -> float:
    """A nominal sample rate [Hz]: a finite number > 0 (and at most 1 MHz), else one line naming it."""
    if (
        isinstance(value, bool)
        or not isinstance(value, (int, float))
        or not math.isfinite(value)
        or not 0 < value <= 1e6
    ):
        raise InputError(f"rate_hz: must be a positive number of Hz up to 1e6, got {value!r}")
    return float(value)


@contextlib.contextmanager
def _lines(path: Path) -> Iterator[Iterator[bytes]]:
    """The file's lines as bytes, each cut at :data:`MAX_LINE_BYTES` + 1 (longer ones are no rows)."""
    with open(path, "rb") as fh:
        magic = fh.read(6)
    opener = next((op for sig, op in _OPENERS if magic.startswith(sig)), open)
    if magic.startswith(b"\x28\xb5\x2f\xfd"):
        stream = pa.input_stream(str(path), compression="zstd")
    else:
        stream = opener(path, "rb")
    with stream as fh:

        def lines() -> Iterator[bytes]:
            while True:
                line = fh.readline(MAX_LINE_BYTES + 1)
                if not line:
                    return
                if len(line) > MAX_LINE_BYTES and not line.endswith(b"\n"):
                    while line and not line.endswith(b"\n"):  # the rest of an over-long line, unread as a row
                        line = fh.readline(1 << 16)
                    yield b"\x00"  # a placeholder that is no row
                    continue
                yield line

        yield lines()


def _numbers(line: bytes, count: int) -> list[float] | None:
    """The line's numbers when it holds exactly ``count`` of them, else None."""
    try:
        fields = _SEPARATORS.split(line.decode("ascii").strip())
    except UnicodeDecodeError:
        return None
    if len(fields) != count:
        return None
    try:
        return [float(f) for f in fields]
    except ValueError:
        return None


def read_headerless(path, names: tuple[str, ...], rate_hz: float | None = None) -> pa.Table:
    """The rows of a table without a header line (see the module) as float64 columns named ``names``, with a
    ``time`` column of each line's nominal time [s] when ``rate_hz`` [Hz] is given and no name is ``time``.

    Parameters
    ----------
    path : path
        The text file (gzip, bz2, xz or zstd compressed ones as well).
    names : tuple of str
        The columns' names in order.
    rate_hz : float, optional
        Nominal sample rate [Hz]: the n-th line after the first row is at n / rate_hz [s].
    """
    path = Path(path)
    count = len(names)
    rows: list[list[float]] = []
    slots: list[int] = []
    skipped, first_skipped, first_row_line = 0, None, None
    try:
        with _lines(path) as lines:
            for number, line in enumerate(lines, start=1):
                if not line.strip():
                    continue
                values = _numbers(line, count)
                if values is None:
                    skipped += 1
                    if first_skipped is None:
                        first_skipped = (number, line)
                    continue
                if first_row_line is None:
                    first_row_line = number
                rows.append(values)
                slots.append(number - first_row_line)
    except (OSError, EOFError, lzma.LZMAError) as exc:
        raise InputError(f"{path}: a compressed file that does not decompress ({exc})") from None
    if not rows:
        shown = (
            f"; its first line: {printable(first_skipped[1].decode('utf-8', 'replace').strip())[:80]!r}"
            if first_skipped
            else ""
        )
        raise InputError(f"{path}: no line holds {count} numbers, one per name given ({', '.join(names)}){shown}")
    if skipped:
        line_number, text = first_skipped
        quoted = (
            "(longer than a row can be)"
            if text == b"\x00"
            else repr(printable(text.decode("utf-8", "replace").strip())[:60])
        )
        warnings.warn(
            f"{path}: skipped {skipped} line(s) that are not {count} numbers (a banner, a header or "
            f"a garbled line), the first: line {line_number} {quoted}",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
    values = np.asarray(rows, dtype=float)
    columns = {name: _floats(values[:, i]) for i, name in enumerate(names)}
    if rate_hz is not None and "time" not in names:
        columns = {"time": _floats(np.asarray(slots, dtype=float) / rate_hz), **columns}
    return pa.table(columns)


def _floats(values: np.ndarray) -> pa.Array:
    """A float64 Arrow array (``pa.array`` would import pandas)."""
    values = np.ascontiguousarray(values, dtype=np.float64)
    return pa.Array.from_buffers(pa.float64(), values.size, [None, pa.py_buffer(values)])


def split_fields(line: str) -> list[str]:
    """A line's fields, between runs of commas, semicolons, tabs and spaces."""
    return [f for f in _SEPARATORS.split(line.strip()) if f]


def looks_headerless(first_line: str) -> bool:
    """Whether a table's first line is numbers, not names: the table has no header line."""
    fields = split_fields(first_line)
    if not fields:
        return False
    try:
        [float(f) for f in fields]
    except ValueError:
        return False
    return True


__all__ = [
    "MAX_LINE_BYTES",
    "check_rate",
    "looks_headerless",
    "parse_names",
    "parse_rate",
    "read_headerless",
    "split_fields",
]
