"""Converting a file to the canonical table: :func:`convert_file`, a table in chunks and any other file whole."""

from __future__ import annotations

import warnings
from dataclasses import dataclass

from ..io import ReadOptions, write_recording
from ..io.stream import TableStream, TableWriter
from ..io.tables import recording_table
from ..measures.plausibility import recording_concerns
from .chunks import ChunkSettings, chunked_or_whole
from ..errors import user_stacklevel


@dataclass(frozen=True)
class ConvertResult:
    """What :func:`convert_file` wrote: rows [count], the time it spans [s], the nominal rate of its first chunk
    [Hz], the time gaps found, and the channels written."""

    rows: int
    duration_s: float
    rate_hz: float
    gaps: int
    channels: tuple[str, ...]


def convert_file(
    input_path,
    output_path,
    *,
    options: ReadOptions | None = None,
    fmt: str | None = None,
    out_fmt: str | None = None,
    chunks: ChunkSettings = ChunkSettings(),
    progress=None,
) -> ConvertResult:
    """Any file gyrocomp reads written as the canonical table (time [s], gyro [deg/s], accel [g], temperature
    [degC]) in CSV or Parquet (a text table by its name, :func:`gyrocomp.io.text_format.output_text_format`: ``.csv``
    commas or the input's semicolons, ``.tsv`` tabs, another name the
    input's): the same bytes as reading it whole and writing the recording
    (:func:`gyrocomp.io.write_recording`). A CSV or Parquet table is read and written chunk by chunk, in memory
    bounded by ``chunks.chunk_rows`` [rows]; any other file whole.

    Parameters
    ----------
    input_path, output_path : path
    options : ReadOptions, optional
        How to read the input (layout and units, dropping non-finite rows, instance, time range, ...).
    fmt, out_fmt : str, optional
        The input's format (default: told from the file) and the output's (default: its suffix).
    chunks : ChunkSettings
        Rows per chunk.
    progress : callable, optional
        Called with the fraction read.
    """

    def whole(read) -> ConvertResult:
        data = read()
        recording = data.recording
        _warn_once(recording_concerns(recording))
        write_recording(recording, output_path, fmt=out_fmt, text_format=data.text_format)
        channels = (*recording.gyro_axes, *recording.accel_axes, *recording.temperature_columns)
        return ConvertResult(
            recording.n_samples, recording.duration_s, recording.rate_hz, len(recording.gaps), channels
        )

    return chunked_or_whole(
        input_path,
        options,
        fmt=fmt,
        chunks=chunks,
        progress=progress,
        whole=whole,
        chunked=lambda stream: _convert_stream(stream, output_path, out_fmt),
    )


def _convert_stream(stream: TableStream, output_path, out_fmt) -> ConvertResult:
    first = last = None
    written = 0
    concerns = []
    with TableWriter(output_path, out_fmt, text_format=stream.text_format) as writer:
        for chunk in stream.chunks():
            rec = chunk.recording
            first = first or rec
            last = rec
            concerns += recording_concerns(rec)
            table = recording_table(rec)
            writer.write(table)
            written += table.num_rows
    stream.warn_summary()
    _warn_once(concerns)
    channels = (*first.gyro_axes, *first.accel_axes, *first.temperature_columns)
    return ConvertResult(written, float(last.time_s[-1] - first.time_s[0]), first.rate_hz, stream.gaps, channels)


def _warn_once(concerns) -> None:
    """The plausibility concerns of what was converted (values beyond a sensor's range, kelvin, a time column in
    another unit), the first of each kind: a converted file is read again later, and what is wrong with it is said
    now, with its row."""
    said = set()
    for concern in concerns:
        if concern.check not in said:
            said.add(concern.check)
            warnings.warn(concern.warning(), stacklevel=user_stacklevel())


__all__ = ["ConvertResult", "convert_file"]
