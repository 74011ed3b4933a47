"""Noise analysis of a recording: an Allan curve and the IEEE Std 952 noise terms for each axis.

Gyro axes are analysed in [deg/s], accelerometer axes in [g]. A recording with time gaps is refused
unless ``split_gaps`` is set; then the contiguous stretches are pooled so that no difference spans a
gap (TOTDEV, which has no pooled form, uses the longest stretch).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..allan import (
    AccelNoise,
    AllanKind,
    AllanResult,
    GyroNoise,
    NoiseTerms,
    TauGrid,
    allan_deviation,
    allan_deviation_segments,
    noise_terms,
)
from ..errors import DataQualityWarning, InputError, user_stacklevel
from .plausibility import recording_concerns, time_bursts_concern
from ..recording import Recording
from ..motion.stillness import StillDetection, detect_still, moves_most_of_the_time


@dataclass(frozen=True)
class AxisNoise:
    """One axis: the requested curve, the overlapping Allan curve the noise terms come from, the terms in
    the data's unit and in the units they are quoted in."""

    axis: str
    sensor: str
    unit: str
    curve: AllanResult
    allan: AllanResult
    terms: NoiseTerms
    noise: GyroNoise | AccelNoise


@dataclass(frozen=True)
class NoiseAnalysis:
    """Noise of every analysed axis of one recording.

    ``stretches`` is the number of contiguous stretches used and ``how`` says how gaps were handled
    (None for a recording without gaps).
    """

    source: str
    rate_hz: float
    axes: dict[str, AxisNoise]
    stretches: int = 1
    how: str | None = None

    def to_dict(self) -> dict:
        """The ``gyrocomp allan --json`` document (NaN written as null)."""
        return {
            "rate_hz": self.rate_hz,
            "axes": {
                name: {
                    "tau_s": _floats(a.curve.tau),
                    "adev": _floats(a.curve.deviation),
                    "n": [int(v) for v in a.curve.n],
                    "ci_low": _floats(a.curve.ci_low),
                    "ci_high": _floats(a.curve.ci_high),
                    "noise": {k: _float(v) for k, v in a.noise.summary().items()},
                }
                for name, a in self.axes.items()
            },
        }


def _float(value):
    if value is None:
        return None
    value = float(value)
    return value if math.isfinite(value) else None


def _floats(values) -> list:
    return [_float(v) for v in np.asarray(values, dtype=float)]


def axis_values(recording: Recording, axis: str) -> tuple[np.ndarray, str, str]:
    """A gyro [deg/s] or accelerometer [g] column of ``recording`` by name, with its sensor and unit."""
    if axis in recording.gyro_axes:
        return recording.gyro(axis), "gyro", "deg/s"
    if axis in recording.accel_axes:
        return recording.accel_g[:, recording.accel_axes.index(axis)], "accel", "g"
    have = ", ".join((*recording.gyro_axes, *recording.accel_axes))
    raise InputError(f"axes: {axis!r} is not in {recording.source}; it has {have}")


def _describe_gap(recording: Recording) -> str:
    gap = recording.gaps[0]
    more = f" (and {len(recording.gaps) - 1} more)" if len(recording.gaps) > 1 else ""
    said = (
        f"{recording.source}: time gap of {gap.duration_s:.6g} s after row {gap.after_row} "
        f"(t = {gap.start_s:.6g} s){more}; Allan deviations need evenly spaced samples: "
    )
    if time_bursts_concern(recording) is not None:  # pooling stretches of a burst or two would be wrong
        stretch = recording.n_samples / (len(recording.gaps) + 1)
        return said + (
            f"the stamps come in bursts, so the stretches between them hold {stretch:.3g} samples on average; if the "
            "sensor samples evenly, read the samples at their mean rate, the stamps left unread "
            f"(columns={{'time': ''}} and rate_hz={recording.mean_rate_hz:.4g})"
        )
    return said + "use split_gaps=True to pool the contiguous stretches"


#: RMS misfit (in ln deviation) of the noise model beyond which :func:`analyse_noise` warns
POOR_FIT_LOG_RESIDUAL = 0.25


def noise_axes(axes, gyro_axes, accel_axes, with_accel: bool = False) -> list[str]:
    """The axes a noise analysis covers: those named in ``axes`` (default every gyro axis), and with
    ``with_accel`` every accelerometer axis besides (Kalibr's noise file needs both sensors)."""
    names = list(axes) if axes else list(gyro_axes)
    if with_accel:
        names += [a for a in accel_axes if a not in names]
    return names


def warn_if_moving(source: str, found: StillDetection) -> None:
    """Warn when a log moves most of the time (as ``fit`` tells a field log,
    :func:`gyrocomp.motion.stillness.moves_most_of_the_time`): its Allan deviation then measures the motion. A log
    with no still block at all is not judged (pure noise above any MEMS part's, or a test signal)."""
    if found.still_blocks.any() and moves_most_of_the_time(found):
        whole = found.blocks.whole
        warnings.warn(
            f"{source}: the log moves most of the time ({found.still_blocks[whole].mean():.0%} of it "
            "still): its Allan deviation and noise terms describe the motion, not the sensor's noise; "
            "analyse a still stretch (time_range_s=) or the still poses, split into runs of their own (split by still)",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )


def analyse_noise(
    recording: Recording,
    axes: list[str] | None = None,
    *,
    kind: AllanKind = "oadev",
    taus: TauGrid | np.ndarray = "octave",
    split_gaps: bool = False,
    fit_taus_s: tuple[float, float] | None = None,
    with_accel: bool = False,
    motion_check: bool = True,
    plausibility_check: bool = True,
) -> NoiseAnalysis:
    """Allan curve (``kind``) and noise terms (from the overlapping Allan deviation) for each axis.

    Parameters
    ----------
    recording : Recording
    axes : list of str, optional
        Gyro and/or accelerometer columns, e.g. ``["gyro_x", "accel_z"]``; default every gyro axis.
    kind, taus : see :func:`gyrocomp.allan.allan_deviation`.
    split_gaps : bool
        Pool the contiguous stretches of a recording with gaps instead of refusing it.
    fit_taus_s : (float, float), optional
        Fit the noise model only on taus in this range [s] (see :func:`gyrocomp.allan.noise_terms`).
    with_accel : bool
        Also analyse every accelerometer axis of the recording.
    motion_check : bool
        Warn when the log moves most of the time (:func:`warn_if_moving`); a caller that judged its stillness
        already passes False.
    plausibility_check : bool
        Warn of unit mistakes (:func:`.plausibility.recording_concerns`); a caller that checked them passes False.
    """
    names = noise_axes(axes, recording.gyro_axes, recording.accel_axes, with_accel)
    for concern in recording_concerns(recording) if plausibility_check else ():
        warnings.warn(
            concern.warning(), stacklevel=user_stacklevel()
        )  # a time column in ns read as s gives taus of 1e10 s
    if recording.gaps and not split_gaps:
        raise InputError(_describe_gap(recording))
    if motion_check:
        warn_if_moving(recording.source, detect_still(recording))
    stretches = recording.contiguous_stretches()
    results = {}
    for name in names:
        values, sensor, unit = axis_values(recording, name)
        curve, allan = _curves([values[s] for s in stretches], recording.rate_hz, kind, taus)
        results[name] = _axis_noise(name, sensor, unit, curve, allan, fit_taus_s)
    how = _pooling_note(recording, stretches, kind)
    return NoiseAnalysis(
        source=recording.source, rate_hz=recording.rate_hz, axes=results, stretches=len(stretches), how=how
    )


def _curves(pieces: list[np.ndarray], rate_hz: float, kind: str, taus) -> tuple[AllanResult, AllanResult]:
    """The curve of ``kind`` and the octave overlapping Allan deviation of an axis's contiguous ``pieces``."""
    if len(pieces) == 1:
        curve = allan_deviation(pieces[0], rate_hz, kind=kind, taus=taus)
        return curve, curve if kind == "oadev" else allan_deviation(pieces[0], rate_hz, taus="octave")
    allan = allan_deviation_segments(pieces, rate_hz, taus="octave")
    if kind == "totdev":
        curve = allan_deviation(max(pieces, key=len), rate_hz, kind=kind, taus=taus)
    elif kind == "oadev" and isinstance(taus, str) and taus == "octave":
        curve = allan
    else:
        curve = allan_deviation_segments(pieces, rate_hz, kind=kind, taus=taus)
    return curve, allan


def _pooling_note(recording: Recording, stretches: list[slice], kind: str) -> str | None:
    """How the stretches between the recording's gaps were pooled (None: one stretch)."""
    if len(stretches) <= 1:
        return None
    longest = max(stretches, key=lambda s: s.stop - s.start)
    length_s = (longest.stop - longest.start) / recording.rate_hz
    if kind == "totdev":
        return (
            f"{recording.source}: TOTDEV on the longest of {len(stretches)} contiguous stretches "
            f"({length_s:.6g} s, rows {recording.row_numbers[longest.start]}-"
            f"{recording.row_numbers[longest.stop - 1]}); the noise terms pool all stretches"
        )
    return (
        f"{recording.source}: pooled {len(stretches)} contiguous stretches split at "
        f"{len(recording.gaps)} gap(s); no difference spans a gap (longest stretch {length_s:.6g} s)"
    )


def analyse_noise_phases(
    phases: dict[str, np.ndarray],
    rate_hz: float,
    *,
    source: str = "<phases>",
    kind: str = "oadev",
    taus="octave",
    fit_taus_s: tuple[float, float] | None = None,
) -> NoiseAnalysis:
    """:func:`analyse_noise` of one contiguous stretch given as the phase of each axis, e.g. integrated chunk by
    chunk from a file (:class:`gyrocomp.allan.PhaseAccumulator`), possibly memory-mapped.

    Parameters
    ----------
    phases : dict of str to array (N+1,)
        The phase of each axis [unit*s]: ``gyro_*`` in [deg], ``accel_*`` in [g*s].
    rate_hz : float
        Sample rate [Hz].
    source : str
        The file's name, for messages.
    kind, taus, fit_taus_s : as :func:`analyse_noise`.
    """
    results = {}
    for name, phase in phases.items():
        sensor, unit = ("accel", "g") if name.startswith("accel") else ("gyro", "deg/s")
        curve = allan_deviation(phase, rate_hz, kind=kind, taus=taus, data_type="phase")
        allan = curve if kind == "oadev" else allan_deviation(phase, rate_hz, taus="octave", data_type="phase")
        results[name] = _axis_noise(name, sensor, unit, curve, allan, fit_taus_s)
    return NoiseAnalysis(source=source, rate_hz=rate_hz, axes=results)


def _axis_noise(
    name: str, sensor: str, unit: str, curve: AllanResult, allan: AllanResult, fit_taus_s: tuple[float, float] | None
) -> AxisNoise:
    """One axis's noise terms read from its overlapping Allan curve (a warning when the model misses it)."""
    terms = noise_terms(allan, fit_taus_s)
    if terms.fit_rms_log_residual > POOR_FIT_LOG_RESIDUAL:
        warnings.warn(
            f"{name}: the five-term noise model misses the curve by {terms.fit_rms_log_residual:.0%} "
            "RMS; compare the read-offs, or restrict the fit to the taus where a term holds "
            "(fit_taus_s: (low, high) [s])",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
    quoted = GyroNoise.from_terms(terms) if sensor == "gyro" else AccelNoise.from_terms(terms)
    return AxisNoise(name, sensor, unit, curve, allan, terms, quoted)
