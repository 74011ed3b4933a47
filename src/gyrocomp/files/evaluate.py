"""Judging a calibration on a file: :func:`evaluate_file`, a table in chunks and any other file whole."""

from __future__ import annotations

import numpy as np

from ..allan.streaming import PhaseAccumulator
from ..calibration import Calibration
from ..calibration.compensate import Compensator, accel_xyz, compensator_for, warn_disagreement
from ..errors import InputError
from ..evaluation import evaluate
from ..io import ReadOptions
from ..io.stream import NotStreamable, TableStream
from ..measures.merit import Evaluation, check_compensated, evaluate_phases
from ..recording import ACCEL_AXES, Recording
from .chunks import ChunkSettings, TimeSteps, chunked_or_whole


def evaluate_file(
    calibration: Calibration,
    path,
    *,
    options: ReadOptions | None = None,
    fmt: str | None = None,
    window_s: float | None = None,
    turn_on_window_s: float | None = None,
    chunks: ChunkSettings = ChunkSettings(),
    progress=None,
) -> Evaluation:
    """:func:`gyrocomp.evaluation.evaluate` of ``calibration`` on a file: a CSV or Parquet table read in chunks
    (each chunk compensated by one :class:`gyrocomp.Compensator`, both the raw and the compensated rates
    integrated into phases as they come, the figures read from the phases; equal to the whole file's to
    rounding), any other file whole.

    Parameters
    ----------
    calibration : Calibration
    path : path
        The run.
    options : ReadOptions, optional
        How to read it (layout and units, dropping non-finite rows, instance, time range, ...).
    fmt : str, optional
        Its format (default: told from the file).
    window_s, turn_on_window_s : as :func:`gyrocomp.evaluation.evaluate` [s].
    chunks : ChunkSettings
    progress : callable, optional
        Called with the fraction of the file read.
    """
    if not isinstance(calibration, Calibration):
        raise InputError(
            f"calibration: expected a Calibration (from fit_calibration or Calibration.load), "
            f"got {type(calibration).__name__}"
        )

    def chunked(stream: TableStream) -> Evaluation:
        if calibration.gyro_triad is not None or calibration.accel_triad is not None:
            raise NotStreamable("a triad is judged on whole still poses")
        return Evaluation([_evaluate_stream(calibration, stream, window_s, turn_on_window_s, chunks)])

    return chunked_or_whole(
        path,
        options,
        fmt=fmt,
        chunks=chunks,
        progress=progress,
        chunked=chunked,
        whole=lambda read: evaluate(
            calibration, read().recording, window_s=window_s, turn_on_window_s=turn_on_window_s
        ),
    )


def _evaluate_stream(calibration: Calibration, stream: TableStream, window_s, turn_on_window_s, chunks: ChunkSettings):
    comp: Compensator | None = None
    accel_axes: tuple[str, ...] = ()
    steps, raw, compensated = TimeSteps(chunks), None, None
    pending_rows = np.empty(0, dtype=np.int64)  # file rows of the samples the compensator still holds
    try:
        for chunk in stream.chunks():
            recording = chunk.recording
            if recording.gaps or stream.gaps:
                raise NotStreamable("a time gap")
            if comp is None:
                comp = compensator_for(calibration, recording, turn_on_window_s=turn_on_window_s)
                if comp.compensates_accel and turn_on_window_s is not None:
                    raise NotStreamable("the accelerometer is not held back with the turn-on window")
                if calibration.accel_axes and comp.compensates_accel:
                    accel_axes = recording.accel_axes
                columns = len(recording.gyro_axes) + len(accel_axes)
                raw, compensated = (
                    PhaseAccumulator(columns, memory_bytes=chunks.memory_bytes, directory=chunks.scratch_dir)
                    for _ in range(2)
                )
                first = recording
            steps.add(recording.time_s)
            raw.update(np.column_stack([recording.gyro_dps] + ([recording.accel_g] if accel_axes else [])))
            out = comp.update(recording.time_s, recording.gyro_dps, recording.temperature_degc, accel_xyz(recording))
            pending_rows = np.concatenate([pending_rows, recording.row_numbers])
            block = _compensated(comp, out, accel_axes)
            _check_block(first, block, accel_axes, pending_rows[: len(block)])
            compensated.update(block)
            pending_rows = pending_rows[len(block) :]
        block = _compensated(comp, comp.finish(), accel_axes)
        _check_block(first, block, accel_axes, pending_rows[: len(block)])
        compensated.update(block)
        warn_disagreement(comp)
        rate_hz = steps.rate_hz()
        stream.warn_summary()
        return evaluate_phases(
            first.source,
            raw.finish(rate_hz),
            compensated.finish(rate_hz),
            rate_hz,
            gyro_axes=first.gyro_axes,
            accel_axes=accel_axes,
            window_s=window_s,
        )
    finally:
        steps.close()
        for accumulator in (raw, compensated):
            if accumulator is not None:
                accumulator.close()


def _check_block(first: Recording, block: np.ndarray, accel_axes: tuple[str, ...], rows: np.ndarray) -> None:
    """:func:`gyrocomp.measures.merit.check_compensated` on each column of a compensated block (``rows``: its file rows)."""
    for j, axis in enumerate((*first.gyro_axes, *accel_axes)):
        check_compensated(first.source, axis, block[:, j], rows)


def _compensated(comp: Compensator, gyro: np.ndarray, accel_axes: tuple[str, ...]) -> np.ndarray:
    """The compensated block to integrate: the gyro, then the accelerometer in the file's axis order."""
    if not accel_axes:
        return gyro
    return np.column_stack([gyro, comp.take_accel()[:, [ACCEL_AXES.index(a) for a in accel_axes]]])


__all__ = ["evaluate_file"]
