"""Applying a calibration to a file: :func:`apply_file`, a table in chunks and any other file whole (the one
place ``gyrocomp apply`` and the library compensate files)."""

from __future__ import annotations

import dataclasses
import os
import warnings

import numpy as np
import pyarrow as pa

from ..calibration import Calibration
from ..calibration.compensate import accel_xyz, apply, compensated_axes, compensator_for, warn_disagreement
from ..errors import DataQualityWarning, InputError, user_stacklevel
from ..io import ReadOptions
from ..io.stream import NotStreamable, TableStream, TableWriter
from ..io.columns import arrow_floats, arrow_indices
from ..io.tables import write_gyro_back
from ..measures.data_check import sample_findings
from ..measures.sample_check import SampleCheck
from ..recording import ACCEL_AXES
from ..units import unit_factor
from .chunks import ChunkSettings, chunked_or_whole


@dataclasses.dataclass(frozen=True)
class FileResult:
    """What :func:`apply_file` wrote: the rows [count], the gyro and accelerometer axes compensated, and whether
    it went through the file in chunks (``streamed``) or read it whole."""

    rows: int
    axes: tuple[str, ...]
    streamed: bool


def apply_file(
    calibration: Calibration,
    input_path,
    output_path,
    *,
    options: ReadOptions | None = None,
    fmt: str | None = None,
    out_fmt: str | None = None,
    axes: tuple[str, ...] | None = None,
    turn_on_window_s: float | None = None,
    chunks: ChunkSettings = ChunkSettings(),
    progress=None,
) -> FileResult:
    """Compensate a file into ``output_path`` (CSV or Parquet): the same rows and columns, the gyro columns (and
    the accelerometer's when the model compensates them) replaced in the file's units.

    The output is what :func:`gyrocomp.calibration.compensate.apply` and :func:`gyrocomp.io.write_gyro_back` give
    for the whole file, to the bit. A CSV or Parquet table is read in chunks (:mod:`gyrocomp.files.chunks`), each
    through one :class:`~gyrocomp.calibration.compensate.Compensator`, and the output written as it comes into a
    temporary file renamed over ``output_path`` at the end, so memory stays bounded by ``chunks.chunk_rows``
    [rows] whatever the file's length; a log, a table whose rows are selected by time, a table that cannot be
    read in chunks, or a model with accelerometer axes applied with ``turn_on_window_s``, is read whole instead.
    The samples are checked as they are compensated (:class:`gyrocomp.measures.sample_check.SampleCheck`, the same
    answer chunked or whole): a dead or doubled gyro axis, temperature spikes and raw counts are each a
    :class:`~gyrocomp.errors.DataQualityWarning` naming the file and the axes or rows.

    Parameters
    ----------
    calibration : Calibration
    input_path, output_path : path
    options : ReadOptions, optional
        How to read the input (layout and units, dropping non-finite rows, instance, time range, ...).
    fmt, out_fmt : str, optional
        The input's format (default: told from the file) and the output's (default: its suffix).
    axes : tuple of str, optional
        Gyro axes to compensate (default: every one the model has; the others are left raw).
    turn_on_window_s : float, optional
        Estimate the turn-on bias from the first seconds of the file [s] (default: the model's mean).
    chunks : ChunkSettings
        Rows per chunk.
    progress : callable, optional
        Called with the fraction of the file read.
    """
    if not isinstance(calibration, Calibration):
        raise InputError(
            f"calibration: expected a Calibration (from fit_calibration or Calibration.load), "
            f"got {type(calibration).__name__}"
        )

    checks: list[SampleCheck] = []  # the samples as compensated (a stream that falls back to reading whole: anew)

    def whole(read) -> FileResult:
        data = read()
        checks.append(SampleCheck().add(data.recording))
        compensated = apply(calibration, data.recording, turn_on_window_s=turn_on_window_s, axes=axes)
        accel = compensated.accel_g if calibration.accel_axes or calibration.accel_triad else None
        write_gyro_back(data, compensated.gyro_dps, output_path, fmt=out_fmt, accel_g=accel)
        done = compensated_axes(calibration, data.recording, axes, accel is not None)
        return FileResult(data.recording.n_samples, done, False)

    def chunked(stream) -> FileResult:
        checks.append(SampleCheck())
        return _apply_stream(calibration, stream, output_path, out_fmt, axes, turn_on_window_s, checks[-1])

    result = chunked_or_whole(
        input_path, options, fmt=fmt, chunks=chunks, progress=progress, whole=whole, chunked=chunked
    )
    _warn_samples(checks[-1], os.fspath(input_path))
    return result


def _warn_samples(check: SampleCheck, source: str) -> None:
    """Warn of what the sample checks found in the compensated samples (a dead or doubled axis, temperature
    spikes, raw counts), as the data check names it."""
    for f in sample_findings(check.facts(), source):
        warnings.warn(
            f"{f.message} (data check '{f.check}'; the output compensates those samples as they are)",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )


def _apply_stream(
    calibration: Calibration, stream: TableStream, output_path, out_fmt, axes, turn_on_window_s, check: SampleCheck
) -> FileResult:
    gyro_factor = unit_factor("gyro", stream.layout.gyro_unit)
    accel_factor = unit_factor("accel", stream.layout.accel_unit)
    comp, accel_order, pending, written, first = None, None, [], 0, None
    computed = tuple(stream.columns[a] for a in stream.gyro_axes + stream.accel_axes)
    with TableWriter(output_path, out_fmt, computed=computed, text_format=stream.text_format) as writer:

        def flush(gyro: np.ndarray, accel: np.ndarray | None) -> None:
            nonlocal pending, written
            if not len(gyro):
                return
            rows = pa.concat_tables(pending) if len(pending) > 1 else pending[0]
            out, rest = rows.slice(0, len(gyro)), rows.slice(len(gyro))
            pending = [rest] if rest.num_rows else []
            replaced = [(stream.gyro_axes, gyro, gyro_factor)]
            if accel is not None:
                replaced.append((stream.accel_axes, accel, accel_factor))
            for names, values, factor in replaced:
                for j, axis in enumerate(names):
                    column = stream.columns[axis]
                    out = out.set_column(out.column_names.index(column), column, arrow_floats(values[:, j] / factor))
            writer.write(out)
            written += out.num_rows

        for chunk in stream.chunks():
            rec = chunk.recording
            check.add(rec)
            if comp is None:
                first = rec
                comp = compensator_for(calibration, rec, axes=axes, turn_on_window_s=turn_on_window_s)
                if comp.compensates_accel and turn_on_window_s is not None:
                    raise NotStreamable("the accelerometer is not held back with the turn-on window")
            accel = accel_xyz(rec)
            rows = (
                chunk.table if chunk.kept.size == chunk.table.num_rows else chunk.table.take(arrow_indices(chunk.kept))
            )
            pending.append(rows)
            gyro = comp.update(rec.time_s, rec.gyro_dps, rec.temperature_degc, accel)
            accel_out = None
            if comp.compensates_accel:
                accel_order = accel_order or [ACCEL_AXES.index(a) for a in rec.accel_axes]
                accel_out = comp.take_accel()[:, accel_order]
            flush(gyro, accel_out)
        flush(comp.finish(), None)
        warn_disagreement(comp)
    stream.warn_summary()
    return FileResult(written, compensated_axes(calibration, first, axes, comp.compensates_accel), True)


__all__ = ["FileResult", "apply_file"]
