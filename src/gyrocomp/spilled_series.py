"""Long series of numbers whose length is not known in advance, held in memory while small and in a temporary
file beyond a limit, so a command that reads a file in chunks keeps a bounded working memory whatever the file's
length (issue #21); and the exact median of such a series, read block by block.

The file is a raw float64 array (or of the series' ``dtype``; native byte order) in a temporary folder removed on
:meth:`SpillArray.close`; :meth:`SpillArray.finish` gives it back as a ``np.memmap`` that the Allan engine and the
moving averages read in blocks (:mod:`gyrocomp.allan`), or as an ordinary array when it stayed in memory, and
:meth:`SpillArray.detach` hands it over (a recording gathered from a file's chunks, :mod:`gyrocomp.files.chunks`).
Functions that walk such a series a part at a time take their parts from :func:`parts`.
"""

from __future__ import annotations

import contextlib
import shutil
import tempfile
import weakref
from pathlib import Path

import numpy as np

from .errors import InputError

#: bytes a :class:`SpillArray` holds in memory before it moves to a file (8 MiB: 1 M samples)
DEFAULT_MEMORY_BYTES = 1 << 23
#: samples a part of a long series holds where a function walks it a part at a time (:func:`parts`: a few MB a
#: column, whatever the series' length)
PART_ROWS = 1 << 18
#: values read at once by :func:`block_median`
_BLOCK = 1 << 20
#: series up to this length are read whole (128 MiB) and handed to np.median
_WHOLE = 1 << 24
#: bins of each histogram :func:`block_median` narrows the median with
_BINS = 4096


def parts(n: int, overlap: int = 0, rows: int | None = None):
    """(start, stop) of the consecutive parts of a series of ``n`` values, ``rows`` each (default
    :data:`PART_ROWS`, read when called), each part reaching ``overlap`` values into the next (1 for first
    differences, 2 for second), the parts' starts covering 0..n - overlap."""
    rows = PART_ROWS if rows is None else int(rows)
    for start in range(0, max(n - overlap, 0), rows):
        yield start, min(n, start + rows + overlap)


class WindowSums:
    """Sums over windows of ``w`` consecutive values of a series given a part at a time (:meth:`add`): the running
    sum is carried from part to part in the same order of additions as ``np.cumsum`` over the whole series, so each
    window's sum is that series' ``c[k + w] - c[k]`` to the bit, and only the last ``w`` running sums are held.

    Parameters
    ----------
    w : int
        Values in a window (at least 1).
    """

    def __init__(self, w: int):
        self.w = int(w)
        self._held: np.ndarray | None = None  # the running sums from the first window not yet summed on

    def add(self, values: np.ndarray) -> np.ndarray:
        """The sums of the windows that end within ``values`` (the series' next values, 1-D or one row per value),
        in order; empty until the first window is complete."""
        values = np.asarray(values, dtype=float)
        if self._held is None:
            self._held = np.zeros((1, *values.shape[1:]))
        held = np.concatenate([self._held, np.cumsum(np.concatenate([self._held[-1:], values]), axis=0)[1:]])
        windows = max(held.shape[0] - self.w, 0)
        self._held = held[windows:]
        return held[self.w : self.w + windows] - held[:windows]


class SpillArray:
    """An append-only float64 series (or of another ``dtype``): in memory up to ``memory_bytes`` [bytes], then in a
    temporary file.

    Parameters
    ----------
    memory_bytes : int
        What the series may hold in memory [bytes]; beyond it, everything goes to a file. 0 writes to a file from
        the first value.
    directory : path, optional
        Where the temporary folder goes (default: the system's temporary folder).
    dtype : numpy dtype
        The values' type (default float64); what is appended is converted to it.

    Use as a context manager, or call :meth:`close`, to remove the file.
    """

    def __init__(self, memory_bytes: int = DEFAULT_MEMORY_BYTES, directory=None, dtype=np.float64):
        if int(memory_bytes) != memory_bytes or memory_bytes < 0:
            raise InputError(f"memory_bytes: a whole number of bytes >= 0, got {memory_bytes!r}")
        self.memory_bytes = int(memory_bytes)
        self.directory = directory
        self.dtype = np.dtype(dtype)
        self._blocks: list[np.ndarray] = []
        self._held = 0  # bytes in _blocks
        self._folder: str | None = None
        self._file = None
        self._path: Path | None = None
        self.size = 0
        self._finished: np.ndarray | None = None

    def __enter__(self) -> "SpillArray":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __len__(self) -> int:
        return self.size

    @property
    def on_disk(self) -> bool:
        return self._path is not None

    def append(self, values) -> None:
        """Add ``values`` (1-D) at the end."""
        if self._finished is not None:
            raise InputError("values: the series is finished; no more values can be added")
        block = np.ascontiguousarray(values, dtype=self.dtype).reshape(-1)
        if not block.size:
            return
        self.size += block.size
        if self._file is None and self._held + block.nbytes > self.memory_bytes:
            self._spill()
        if self._file is not None:
            self._write(block)
        else:
            self._blocks.append(block.copy() if block.base is not None else block)
            self._held += block.nbytes

    def _spill(self) -> None:
        self._folder = tempfile.mkdtemp(prefix="gyrocomp-", dir=self.directory)
        self._path = Path(self._folder) / "series.f64"
        self._file = open(self._path, "wb")
        for block in self._blocks:
            self._write(block)
        self._blocks, self._held = [], 0

    def _write(self, block: np.ndarray) -> None:
        """``block`` onto the file; a failure (a full disk) names the file, so that a message says where the
        temporary series went (the system's temporary folder, ``TMPDIR``, unless a ``directory`` was given)."""
        try:
            self._file.write(block.tobytes())
        except OSError as exc:
            raise OSError(exc.errno, exc.strerror, str(self._path)) from exc

    def _close_file(self) -> None:
        file, self._file = self._file, None
        try:
            file.close()  # what was still buffered is written here
        except OSError as exc:
            raise OSError(exc.errno, exc.strerror, str(self._path)) from exc

    def finish(self) -> np.ndarray:
        """The whole series, writable: an array, or a ``np.memmap`` of the file (valid until :meth:`close`)."""
        if self._finished is None:
            if self._file is not None:
                self._close_file()
                self._finished = (
                    np.memmap(self._path, dtype=self.dtype, mode="r+", shape=(self.size,))
                    if self.size
                    else np.empty(0, self.dtype)
                )
            else:
                self._finished = (
                    np.concatenate(self._blocks)
                    if len(self._blocks) > 1
                    else self._blocks[0]
                    if self._blocks
                    else np.empty(0, self.dtype)
                )
                self._blocks = []
        return self._finished

    def detach(self) -> np.ndarray:
        """The whole series (:meth:`finish`), handed over: the series forgets it, and its file, if it has one, is
        removed when the array and every view of it are dropped (not at :meth:`close`)."""
        values = self.finish()
        folder = self._folder
        self._finished, self._folder, self._path = None, None, None
        if folder is not None:
            weakref.finalize(values, shutil.rmtree, folder, True)
        return values

    def close(self) -> None:
        """Forget the series and remove its file."""
        if self._file is not None:
            with contextlib.suppress(OSError):  # what the file could not take is dropped with it
                self._file.close()
            self._file = None
        self._finished, self._blocks = None, []
        if self._folder is not None:
            shutil.rmtree(self._folder, ignore_errors=True)
            self._folder = self._path = None


def block_median(values, block: int = _BLOCK, whole: int = _WHOLE) -> float:
    """The median of ``values`` (any sliceable 1-D series, a ``np.memmap`` included), exactly as ``np.median``
    gives it, reading ``block`` values at a time (a series of at most ``whole`` values is read at once).

    The order statistic is narrowed by histograms: each pass counts the values in ``_BINS`` bins of the interval
    known to hold it, equal in the floats' ordered bit patterns (:func:`_keys`), and keeps the bin where the count
    crosses its rank, until that bin holds at most ``block`` values (gathered and selected with ``np.partition``)
    or one value only. Each pass divides the interval's representable floats by 4096, so a series of float64
    needs six passes at most, however its values spread; memory stays at a block and a histogram.
    """
    n = len(values)
    if n == 0:
        raise InputError("values: the median of an empty series is undefined")
    if n <= max(block, whole):
        return float(np.median(np.asarray(values[:], dtype=np.float64)))
    low, high = np.inf, -np.inf
    for start in range(0, n, block):
        chunk = np.asarray(values[start : start + block], dtype=np.float64)
        if np.isnan(chunk).any():
            return float("nan")
        low, high = min(low, float(chunk.min())), max(high, float(chunk.max()))
    lower = _order_statistic(values, (n - 1) // 2, low, high, block)
    upper = lower if n % 2 else _order_statistic(values, n // 2, low, high, block)
    return float(np.mean([lower, upper]))


def streamed_median(pieces) -> float:
    """The median of the values of ``pieces`` (an iterable of 1-D arrays, taken in turn), exactly as ``np.median``
    of them joined gives it: kept in a :class:`SpillArray` (a temporary file when long), then
    :func:`block_median`."""
    with SpillArray() as series:
        for piece in pieces:
            series.append(piece)
        return block_median(series.finish())


#: the bits of a float64 below its sign: flipped for a negative value, they order its int64 view as the floats
_LOW_BITS = np.int64(0x7FFFFFFFFFFFFFFF)


def _keys(values: np.ndarray) -> np.ndarray:
    """The float64 ``values`` as int64 keys in the same order (-0.0 just below +0.0); the map is its own inverse
    (keys given as int64 come back as the floats' bits)."""
    bits = np.ascontiguousarray(values).view(np.int64)
    return bits ^ ((bits >> 63) & _LOW_BITS)


def _value(key: int) -> float:
    """The float64 whose key (:func:`_keys`) is ``key``."""
    return float(_keys(np.array([key], dtype=np.int64)).view(np.float64)[0])


def _order_statistic(values, rank: int, low: float, high: float, block: int) -> float:
    """The ``rank``-th smallest (0-based) of ``values``, all of which lie in [low, high].

    The interval is narrowed in the values' int64 keys (:func:`_keys`), where equal bins hold equally many
    representable floats: each pass divides the keys' span by ``_BINS`` (4096), so 64-bit keys need six passes at
    most, whatever the values' spread (bins of equal width in the values took a pass per 12 bits of exponent near
    zero: 88 passes for the second differences of an interpolated temperature, 1e-300 to 1e-3)."""
    lo, hi = int(_keys(np.array([low]))[0]), int(_keys(np.array([high]))[0])
    below = 0  # values whose key is less than lo
    while lo < hi:
        span = hi - lo + 1
        width = -(-span // _BINS)  # bin k holds keys in [lo + k width, lo + (k + 1) width)
        bins = -(-span // width)
        counts = np.zeros(bins, dtype=np.int64)
        start = np.uint64(lo % (1 << 64))
        for keys in _inside(values, lo, hi, block):
            # the distance from lo in unsigned 64-bit arithmetic (it can exceed the int64 range), divided
            offsets = (keys.view(np.uint64) - start) // np.uint64(width)
            counts += np.bincount(offsets.astype(np.intp), minlength=bins)
        cumulated = below + np.cumsum(counts)
        j = int(np.searchsorted(cumulated, rank, side="right"))
        below = int(cumulated[j - 1]) if j else below
        lo, hi = lo + j * width, min(hi, lo + (j + 1) * width - 1)
        if counts[j] <= block:
            keys = np.concatenate(list(_inside(values, lo, hi, block)))
            return _value(int(np.partition(keys, rank - below)[rank - below]))
    return _value(lo)


def _inside(values, lo: int, hi: int, block: int):
    """The keys (:func:`_keys`) of the values whose keys lie in [lo, hi], block by block."""
    for start in range(0, len(values), block):
        keys = _keys(np.asarray(values[start : start + block], dtype=np.float64))
        yield keys[(keys >= lo) & (keys <= hi)]
