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
from ..io.read_options import ProgressCallback
from ..io.stream import CHUNK_ROWS, NotStreamable, TableStream
from ..recording import GAP_FACTOR, Recording, nominal_rate_hz
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
            reader = reader_named(fmt)
            reader.warn_unused_layout(Path(path), options)
            stream = reader.stream(Path(path), options, chunks.chunk_rows, progress)
        try:
            return chunked(stream)
        except NotStreamable:
            pass
    return whole(lambda: read_input(path, options, fmt=fmt, progress=progress))


#: a file larger than this [bytes] is read by :func:`read_whole` in chunks, its columns gathered in series that go
#: to temporary files past the memory limit (a ten-hour, 1 kHz bag is 13 GB, its table 0.4 GB; an hour at 1 kHz as
#: a CSV table about 0.3 GB)
LARGE_FILE_BYTES = 256 << 20


@dataclass(frozen=True)
class GatheredRun:
    """A file's whole recording gathered from its chunks (:func:`read_whole`): its columns may be memory-mapped
    temporary files, removed when the last array that reads them is dropped."""

    recording: Recording


def file_bytes(path) -> int:
    """The bytes of a file, or of every file in a folder (a ROS 2 bag)."""
    path = Path(path)
    if path.is_dir():
        return sum(p.stat().st_size for p in path.rglob("*") if p.is_file())
    return path.stat().st_size


def read_whole(
    path,
    options: ReadOptions | None = None,
    *,
    fmt: str | None = None,
    progress: ProgressCallback | None = None,
    settings: ChunkSettings = ChunkSettings(),
    large_bytes: int | None = None,
) -> TableData | GatheredRun:
    """The whole recording of a file (``.recording``) for a command that needs all of it at once (a fit), in a
    working memory that does not grow with the file: a file larger than ``large_bytes`` [bytes] (default:
    :data:`LARGE_FILE_BYTES`) that can be read in chunks (:func:`reads_in_chunks`) is, each chunk's columns
    appended to series held in memory up to ``settings.memory_bytes`` and in temporary files beyond
    (:class:`gyrocomp.spilled_series.SpillArray`), and the recording reads those files mapped in memory (pages the
    system can drop and read again); any other file is read whole (:func:`gyrocomp.io.read_input`). Either way the
    recording is the same, and so are the warnings (the stream's, :meth:`warn_summary`, once for the file)."""
    options = options or ReadOptions()
    if not Path(path).exists():
        raise InputError(f"{path}: no such file")
    if file_bytes(path) <= (LARGE_FILE_BYTES if large_bytes is None else large_bytes):
        return read_input(path, options, fmt=fmt, progress=progress)
    return chunked_or_whole(
        path,
        options,
        fmt=fmt,
        chunks=settings,
        progress=progress,
        chunked=lambda stream: GatheredRun(gathered_recording(stream, settings)),
        whole=lambda read: read(),
    )


#: the columns of a recording that :func:`gathered_recording` gathers
_GATHERED = ("time_s", "gyro_dps", "temperature_degc", "accel_g", "reference_rate_dps", "row_numbers")


def gathered_recording(stream, settings: ChunkSettings = ChunkSettings()) -> Recording:
    """The recording of every chunk of ``stream`` (a :class:`~gyrocomp.io.stream.TableStream` or a reader's
    stream) end to end, its columns in :class:`~gyrocomp.spilled_series.SpillArray` s (memory-mapped files when
    long, removed when the recording's last array is dropped); the stream's warnings said once."""
    series: dict[str, SpillArray] = {}
    first = None
    try:
        for chunk in stream.chunks():
            rec = chunk.recording
            if first is None:
                first = rec
            for name in _GATHERED:
                values = getattr(rec, name)
                if values is not None:
                    if name not in series:
                        series[name] = SpillArray(settings.memory_bytes, settings.scratch_dir, dtype=values.dtype)
                    series[name].append(values)
        if first is None:
            raise InputError(f"{stream.path}: no samples")
        stream.warn_summary()
        # each column's file removed when the last array reading it is dropped
        arrays = {name: s.detach().reshape((-1, *getattr(first, name).shape[1:])) for name, s in series.items()}
    except BaseException:
        for s in series.values():
            s.close()
        raise
    return Recording(
        gyro_axes=first.gyro_axes,
        accel_axes=first.accel_axes,
        source=first.source,
        metadata={**first.metadata, "rows_dropped": int(stream.rows_dropped)},
        **arrays,
    )


def with_channels(options: ReadOptions | None, channels: tuple[str, ...] | None) -> ReadOptions:
    """``options`` (default ones when None) reading only ``channels`` (None: every channel)."""
    return dataclasses.replace(options or ReadOptions(), channels=channels)


__all__ = [
    "ChunkSettings",
    "GatheredRun",
    "LARGE_FILE_BYTES",
    "TimeSteps",
    "chunked_or_whole",
    "file_bytes",
    "gathered_recording",
    "read_whole",
    "reads_in_chunks",
    "with_channels",
]
