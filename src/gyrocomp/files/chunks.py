"""Chunked file work, in one place: whether a file is read in chunks, the chunk settings, and the one pattern
every file command follows (apply, convert, evaluate, allan): a CSV or Parquet table, or a file whose reader
streams (a ROS bag), is read in chunks, in memory bounded by the chunk whatever the file's length, and any other
file (a log, a table whose rows are selected by time, a file that cannot be read in chunks: a time gap, a CSV
column whose type changes after its first megabyte, a bag whose stamps go back) is read whole, with the same
result.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

import numpy as np

from ..errors import InputError
from ..io import ReadOptions, TableData, detect_format, read_input, table_formats
from ..io.readers import reader_named
from ..io.common import ProgressCallback
from ..io.stream import CHUNK_ROWS, NotStreamable, TableStream
from ..recording import GAP_FACTOR, nominal_rate_hz
from ..spilled_series import DEFAULT_MEMORY_BYTES, SpillArray, block_median

T = TypeVar("T")


@dataclass(frozen=True)
class ChunkSettings:
    """How a file is read in chunks: ``chunk_rows`` [rows] at a time, each integrated series held in memory up to
    ``memory_bytes`` [bytes] and in a temporary file in ``scratch_dir`` (default: the system's) beyond."""

    chunk_rows: int = CHUNK_ROWS
    memory_bytes: int = DEFAULT_MEMORY_BYTES
    scratch_dir: str | None = None


class TimeSteps:
    """The time steps of a file read in chunks [s] (:meth:`add` each chunk's time), kept (spilled past the memory
    limit) for their median."""

    def __init__(self, settings: ChunkSettings):
        self.steps = SpillArray(settings.memory_bytes, settings.scratch_dir)
        self.last: float | None = None
        self.longest = 0.0

    def add(self, time_s: np.ndarray) -> None:
        steps = np.diff(time_s) if self.last is None else np.diff(time_s, prepend=self.last)
        if steps.size:
            self.longest = max(self.longest, float(steps.max()))
        self.steps.append(steps)
        self.last = float(time_s[-1])

    def rate_hz(self) -> float:
        """The file's sample rate [Hz] as a whole-file recording takes it; a step over GAP_FACTOR periods (which
        a chunk alone may not see as a gap) sends the file to the whole-file path."""
        period = block_median(self.steps.finish())
        if self.longest > GAP_FACTOR * period:
            raise NotStreamable("a time gap")
        return nominal_rate_hz(period)

    def close(self) -> None:
        self.steps.close()


def reads_in_chunks(fmt: str, options: ReadOptions) -> bool:
    """Whether a file of format ``fmt`` is read in chunks with these options: a table, or a format whose reader
    streams (a ROS bag), whose rows are not selected by time (a time range is cut from the whole file)."""
    return (fmt in table_formats() or reader_named(fmt).stream is not None) and options.time_range_s is None


def chunked_or_whole(
    path,
    options: ReadOptions | None,
    *,
    fmt: str | None,
    chunks: ChunkSettings,
    progress: ProgressCallback | None,
    chunked: Callable[[TableStream], T],
    whole: Callable[[Callable[[], TableData]], T],
) -> T:
    """``chunked(stream)`` of the file read in chunks when it can be (:func:`reads_in_chunks`), else (and when the
    stream raises :class:`~gyrocomp.io.stream.NotStreamable`) ``whole(read)``, ``read()`` reading the whole file
    with the same options (:func:`gyrocomp.io.read_input`).

    Parameters
    ----------
    path : path
        The file.
    options : ReadOptions, optional
        How to read it (the layout, dropping non-finite rows, the channels, the time range, ...).
    fmt : str, optional
        Its format (default: told from the file).
    chunks : ChunkSettings
        Rows per chunk.
    progress : callable, optional
        Called with the fraction of the file read.
    """
    options = options or ReadOptions()
    if not Path(path).exists():
        raise InputError(f"{path}: no such file")
    fmt = detect_format(path, fmt)
    if reads_in_chunks(fmt, options):
        if fmt in table_formats():
            stream = TableStream(
                path,
                options.layout,
                fmt=fmt,
                drop_nonfinite=options.drop_nonfinite,
                chunk_rows=chunks.chunk_rows,
                progress=progress,
                channels=options.channels,
            )
        else:
            stream = reader_named(fmt).stream(Path(path), options, chunks.chunk_rows, progress)
        try:
            return chunked(stream)
        except NotStreamable:
            pass
    return whole(lambda: read_input(path, options, fmt=fmt, progress=progress))


def with_channels(options: ReadOptions | None, channels: tuple[str, ...] | None) -> ReadOptions:
    """``options`` (default ones when None) reading only ``channels`` (None: every channel)."""
    return dataclasses.replace(options or ReadOptions(), channels=channels)


__all__ = ["ChunkSettings", "TimeSteps", "chunked_or_whole", "reads_in_chunks", "with_channels"]
