"""Long series of numbers whose length is not known in advance, held in memory while small and in a temporary
file beyond a limit, so a command that reads a file in chunks keeps a bounded working memory whatever the file's
length (issue #21); and the exact median of such a series, read block by block.

The file is a raw float64 array (native byte order) in a temporary folder removed on :meth:`SpillArray.close`;
:meth:`SpillArray.finish` gives it back as a ``np.memmap`` that the Allan engine and the moving averages read in
blocks (:mod:`gyrocomp.allan`), or as an ordinary array when it stayed in memory.
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import numpy as np

from .errors import InputError

#: bytes a :class:`SpillArray` holds in memory before it moves to a file (8 MiB: 1 M samples)
DEFAULT_MEMORY_BYTES = 1 << 23
#: values read at once by :func:`block_median`
_BLOCK = 1 << 20
#: series up to this length are read whole (128 MiB) and handed to np.median
_WHOLE = 1 << 24
#: bins of each histogram :func:`block_median` narrows the median with
_BINS = 4096


class SpillArray:
    """An append-only float64 series: in memory up to ``memory_bytes`` [bytes], then in a temporary file.

    Parameters
    ----------
    memory_bytes : int
        What the series may hold in memory [bytes]; beyond it, everything goes to a file. 0 writes to a file from
        the first value.
    directory : path, optional
        Where the temporary folder goes (default: the system's temporary folder).

    Use as a context manager, or call :meth:`close`, to remove the file.
    """

    def __init__(self, memory_bytes: int = DEFAULT_MEMORY_BYTES, directory=None):
        if int(memory_bytes) != memory_bytes or memory_bytes < 0:
            raise InputError(f"memory_bytes: a whole number of bytes >= 0, got {memory_bytes!r}")
        self.memory_bytes = int(memory_bytes)
        self.directory = directory
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
        block = np.ascontiguousarray(values, dtype=np.float64).reshape(-1)
        if not block.size:
            return
        self.size += block.size
        if self._file is None and self._held + block.nbytes > self.memory_bytes:
            self._spill()
        if self._file is not None:
            self._file.write(block.tobytes())
        else:
            self._blocks.append(block.copy() if block.base is not None else block)
            self._held += block.nbytes

    def _spill(self) -> None:
        self._folder = tempfile.mkdtemp(prefix="gyrocomp-", dir=self.directory)
        self._path = Path(self._folder) / "series.f64"
        self._file = open(self._path, "wb")
        for block in self._blocks:
            self._file.write(block.tobytes())
        self._blocks, self._held = [], 0

    def finish(self) -> np.ndarray:
        """The whole series, writable: an array, or a ``np.memmap`` of the file (valid until :meth:`close`)."""
        if self._finished is None:
            if self._file is not None:
                self._file.close()
                self._file = None
                self._finished = (
                    np.memmap(self._path, dtype=np.float64, mode="r+", shape=(self.size,)) if self.size else np.empty(0)
                )
            else:
                self._finished = (
                    np.concatenate(self._blocks)
                    if len(self._blocks) > 1
                    else self._blocks[0]
                    if self._blocks
                    else np.empty(0)
                )
                self._blocks = []
        return self._finished

    def close(self) -> None:
        """Forget the series and remove its file."""
        if self._file is not None:
            self._file.close()
            self._file = None
        self._finished, self._blocks = None, []
        if self._folder is not None:
            shutil.rmtree(self._folder, ignore_errors=True)
            self._folder = self._path = None


def block_median(values, block: int = _BLOCK, whole: int = _WHOLE) -> float:
    """The median of ``values`` (any sliceable 1-D series, a ``np.memmap`` included), exactly as ``np.median``
    gives it, reading ``block`` values at a time (a series of at most ``whole`` values is read at once).

    The order statistic is narrowed by histograms: each pass counts the values in ``_BINS`` equal bins of the
    interval known to hold it and keeps the bin where the count crosses its rank, until that bin holds at most
    ``block`` values (gathered and selected with ``np.partition``) or one value only. Each pass divides the
    interval by 4096, so a series of float64 needs a few passes at most; memory stays at a block and a histogram.
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


def _order_statistic(values, rank: int, low: float, high: float, block: int) -> float:
    """The ``rank``-th smallest (0-based) of ``values``, all of which lie in [low, high]."""
    below = 0  # values less than low
    closed = True  # whether high itself belongs to the interval
    while True:
        if low == high:
            return low
        edges = np.linspace(low, high, _BINS + 1)
        counts = np.zeros(_BINS, dtype=np.int64)
        for chunk in _inside(values, low, high, closed, block):
            # bin k holds edges[k] <= v < edges[k + 1] (the last also v == high); edges a few float64 steps apart
            # may repeat, leaving empty bins
            index = np.minimum(np.searchsorted(edges, chunk, side="right") - 1, _BINS - 1)
            counts += np.bincount(index, minlength=_BINS)
        cumulated = below + np.cumsum(counts)
        j = int(np.searchsorted(cumulated, rank, side="right"))
        new_low, new_high = float(edges[j]), float(edges[j + 1])
        below = int(cumulated[j - 1]) if j else below
        closed = closed and j == _BINS - 1
        if counts[j] <= block:
            inside = np.concatenate(list(_inside(values, new_low, new_high, closed, block)))
            return float(np.partition(inside, rank - below)[rank - below])
        if not (low < new_low or new_high < high):
            # a bin a few float64 steps wide that cannot be split: a few distinct values, counted
            tally: dict[float, int] = {}
            for chunk in _inside(values, new_low, new_high, closed, block):
                for value, count in zip(*np.unique(chunk, return_counts=True)):
                    tally[float(value)] = tally.get(float(value), 0) + int(count)
            for value in sorted(tally):
                below += tally[value]
                if below > rank:
                    return value
        low, high = new_low, new_high


def _inside(values, low: float, high: float, closed: bool, block: int):
    """The values in [low, high] (``closed``) or [low, high), block by block."""
    for start in range(0, len(values), block):
        chunk = np.asarray(values[start : start + block], dtype=np.float64)
        yield chunk[(chunk >= low) & ((chunk <= high) if closed else (chunk < high))]
