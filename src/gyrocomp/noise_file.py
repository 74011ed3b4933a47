"""The noise analysis of a CSV or Parquet file read in chunks, in memory bounded by the chunk whatever the file's
length (issue #21): each chunk's rates are integrated into phases as they come (:class:`gyrocomp.allan.PhaseAccumulator`,
kept in memory up to ``memory_bytes`` per series and in temporary files beyond), and the Allan deviations are read
from the phases (:func:`gyrocomp.noise.analyse_noise_phases`); :func:`gyrocomp.evaluation.evaluate_file` does the
same for the figures of merit.

The result equals :func:`gyrocomp.noise.analyse_noise` of the whole file to rounding (relative 1e-8); the sample
rate is the median time step of the whole file, as a :class:`gyrocomp.Recording` takes it. A file with time gaps
(whose stretches are pooled or refused) or a CSV whose column types change after its first megabyte is read whole
instead, with the same result.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from .allan import AllanKind, TauGrid
from .allan.streaming import PhaseAccumulator
from .errors import DataQualityWarning, InputError
from .io.stream import CHUNK_ROWS, NotStreamable, TableStream
from .io.tables import TableLayout, read_table
from .noise import NoiseAnalysis, analyse_noise, analyse_noise_phases, axis_values, noise_axes, warn_if_moving
from .stillness import StillnessState, detection
from .plausibility import temperature_range_concerns, time_unit_concern
from .recording import ACCEL_AXES, GAP_FACTOR, GYRO_AXES, nominal_rate_hz
from .spill import DEFAULT_MEMORY_BYTES, SpillArray, block_median


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


def analyse_noise_file(path, axes: list[str] | None = None, *, layout: TableLayout | None = None,
                       fmt: str | None = None, drop_nonfinite: bool = False, with_accel: bool = False,
                       kind: AllanKind = "oadev", taus: TauGrid | np.ndarray = "octave", split_gaps: bool = False,
                       fit_taus_s: tuple[float, float] | None = None, chunks: ChunkSettings = ChunkSettings(),
                       progress=None) -> NoiseAnalysis:
    """:func:`gyrocomp.noise.analyse_noise` of a CSV or Parquet file, read in chunks (see the module); only time
    and the analysed columns are read.

    Parameters
    ----------
    path : path
        The table.
    axes : list of str, optional
        Gyro [deg/s] and/or accelerometer [g] columns; default every gyro axis.
    layout, fmt, drop_nonfinite : as :func:`gyrocomp.io.read_table`.
    with_accel : bool
        Also analyse every accelerometer axis of the file (Kalibr's noise file needs both sensors).
    kind, taus, split_gaps, fit_taus_s : as :func:`gyrocomp.noise.analyse_noise`.
    chunks : ChunkSettings
        Chunk size, memory per series [bytes], folder of the temporary files.
    progress : callable, optional
        Called with the fraction of the file read.
    """
    named = list(axes) if axes else None
    wanted = (*GYRO_AXES, *(named or ()), *(ACCEL_AXES if with_accel else ()))
    if any(name not in GYRO_AXES + ACCEL_AXES for name in wanted):
        wanted = None  # a name that is no axis: read everything, so the refusal can list what the file has
    stream = TableStream(path, layout, fmt=fmt, drop_nonfinite=drop_nonfinite, chunk_rows=chunks.chunk_rows,
                         progress=progress, channels=wanted)
    try:
        return _noise_stream(stream, named, with_accel, kind, taus, fit_taus_s, chunks)
    except NotStreamable:
        with warnings.catch_warnings():
            # the gaps are refused by analyse_noise in one line of their own, or split and said in the result's how
            warnings.filterwarnings("ignore", message=r".*time gap\(s\) longer than", category=DataQualityWarning)
            recording = read_table(path, layout, fmt=stream.fmt, drop_nonfinite=drop_nonfinite,
                                   channels=wanted).recording
        return analyse_noise(recording, named, kind=kind, taus=taus, split_gaps=split_gaps, fit_taus_s=fit_taus_s,
                             with_accel=with_accel)


def _noise_stream(stream: TableStream, named, with_accel: bool, kind, taus, fit_taus_s,
                  chunks: ChunkSettings) -> NoiseAnalysis:
    names = noise_axes(named, stream.gyro_axes, stream.accel_axes, with_accel)
    have = (*stream.gyro_axes, *stream.accel_axes)
    for name in names:
        if name not in have:
            raise InputError(f"axes: {name!r} is not in {stream.path}; it has {', '.join(have)}")
    steps = TimeSteps(chunks)
    first_s, said, still = None, False, None
    try:
        with PhaseAccumulator(len(names), memory_bytes=chunks.memory_bytes, directory=chunks.scratch_dir) as phases:
            for chunk in stream.chunks():
                recording = chunk.recording
                if recording.gaps or stream.gaps:
                    raise NotStreamable("a time gap")
                first_s = float(recording.time_s[0]) if first_s is None and recording.n_samples else first_s
                steps.add(recording.time_s)
                if still is None and recording.n_samples > 1:  # blocks of the first chunk's rate (motion is coarse)
                    still = StillnessState(recording.rate_hz)
                if still is not None:
                    still.update(recording.time_s, recording.gyro_dps, recording.accel_g)
                phases.update(np.column_stack([axis_values(recording, name)[0] for name in names]))
                if not said and recording.temperature_degc is not None:  # the first impossible sample, once
                    for concern in temperature_range_concerns(recording):
                        warnings.warn(concern.warning(), stacklevel=3)
                        said = True
            rate_hz = steps.rate_hz()
            stream.warn_summary()
            if still is not None:
                warn_if_moving(str(stream.path), detection(still.blocks()))
            concern = time_unit_concern(str(stream.path), rate_hz, (steps.last or 0.0) - (first_s or 0.0))
            if concern is not None:  # the same words as a whole recording's check (allan on ns read as s)
                warnings.warn(concern.warning(), stacklevel=3)
            integrated = dict(zip(names, phases.finish(rate_hz)))
            return analyse_noise_phases(integrated, rate_hz, source=str(stream.path), kind=kind, taus=taus,
                                        fit_taus_s=fit_taus_s)
    finally:
        steps.close()
