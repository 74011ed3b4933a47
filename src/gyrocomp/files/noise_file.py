"""The noise analysis of a file: a CSV or Parquet table read in chunks, in memory bounded by the chunk whatever the file's
length (issue #21): each chunk's rates are integrated into phases as they come (:class:`gyrocomp.allan.PhaseAccumulator`,
kept in memory up to ``memory_bytes`` per series and in temporary files beyond), and the Allan deviations are read
from the phases (:func:`gyrocomp.measures.noise.analyse_noise_phases`); :func:`gyrocomp.files.evaluate_file` does the
same for the figures of merit.

The result equals :func:`gyrocomp.measures.noise.analyse_noise` of the whole file to rounding (relative 1e-8); the sample
rate is the median time step of the whole file, as a :class:`gyrocomp.Recording` takes it. A file with time gaps
(whose stretches are pooled or refused) or a CSV whose column types change after its first megabyte is read whole
instead, with the same result.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..allan import AllanKind, TauGrid
from ..allan.streaming import PhaseAccumulator
from ..errors import DataQualityWarning, InputError, user_stacklevel
from ..io import ReadOptions
from ..io.stream import NotStreamable, TableStream
from ..measures.noise import NoiseAnalysis, analyse_noise, analyse_noise_phases, axis_values, noise_axes, warn_if_moving
from ..measures.plausibility import temperature_range_concerns, time_unit_concern
from ..motion.stillness import StillnessState, detection
from ..recording import ACCEL_AXES, GYRO_AXES
from .chunks import ChunkSettings, TimeSteps, chunked_or_whole, with_channels


def analyse_noise_file(
    path,
    axes: list[str] | None = None,
    *,
    options: ReadOptions | None = None,
    fmt: str | None = None,
    with_accel: bool = False,
    kind: AllanKind = "oadev",
    taus: TauGrid | np.ndarray = "octave",
    split_gaps: bool = False,
    fit_taus_s: tuple[float, float] | None = None,
    chunks: ChunkSettings = ChunkSettings(),
    progress=None,
) -> NoiseAnalysis:
    """:func:`gyrocomp.measures.noise.analyse_noise` of a file: a CSV or Parquet table read in chunks (see the
    module), any other file whole; only time and the analysed columns are read.

    Parameters
    ----------
    path : path
        The file.
    axes : list of str, optional
        Gyro [deg/s] and/or accelerometer [g] columns; default every gyro axis.
    options : ReadOptions, optional
        How to read the file (layout and units, dropping non-finite rows, instance, time range, ...).
    fmt : str, optional
        Its format (default: told from the file).
    with_accel : bool
        Also analyse every accelerometer axis of the file (Kalibr's noise file needs both sensors).
    kind, taus, split_gaps : as :func:`gyrocomp.measures.noise.analyse_noise`.
    fit_taus_s : (float, float), optional
        The averaging times the noise terms are fitted between [s] (as :func:`gyrocomp.measures.noise.analyse_noise`).
    chunks : ChunkSettings
        Chunk size, memory per series [bytes], folder of the temporary files.
    progress : callable, optional
        Called with the fraction of the file read.
    """
    named = list(axes) if axes else None
    wanted = (*GYRO_AXES, *(named or ()), *(ACCEL_AXES if with_accel else ()))
    if any(name not in GYRO_AXES + ACCEL_AXES for name in wanted):
        wanted = None  # a name that is no axis: read everything, so the refusal can list what the file has

    def whole(read) -> NoiseAnalysis:
        with warnings.catch_warnings():
            # the gaps are refused by analyse_noise in one line of their own, or split and said in the result's how
            warnings.filterwarnings("ignore", message=r".*time gap\(s\) longer than", category=DataQualityWarning)
            recording = read().recording
        return analyse_noise(
            recording, named, kind=kind, taus=taus, split_gaps=split_gaps, fit_taus_s=fit_taus_s, with_accel=with_accel
        )

    return chunked_or_whole(
        path,
        with_channels(options, wanted),
        fmt=fmt,
        chunks=chunks,
        progress=progress,
        whole=whole,
        chunked=lambda stream: _noise_stream(stream, named, with_accel, kind, taus, fit_taus_s, chunks),
    )


def _noise_stream(
    stream: TableStream, named, with_accel: bool, kind, taus, fit_taus_s, chunks: ChunkSettings
) -> NoiseAnalysis:
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
                        warnings.warn(concern.warning(), stacklevel=user_stacklevel())
                        said = True
            rate_hz = steps.rate_hz()
            stream.warn_summary()
            if still is not None:
                warn_if_moving(str(stream.path), detection(still.blocks()))
            concern = time_unit_concern(str(stream.path), rate_hz, (steps.last or 0.0) - (first_s or 0.0))
            if concern is not None:  # the same words as a whole recording's check (allan on ns read as s)
                warnings.warn(concern.warning(), stacklevel=user_stacklevel())
            integrated = dict(zip(names, phases.finish(rate_hz)))
            return analyse_noise_phases(
                integrated, rate_hz, source=str(stream.path), kind=kind, taus=taus, fit_taus_s=fit_taus_s
            )
    finally:
        steps.close()


__all__ = ["analyse_noise_file"]
