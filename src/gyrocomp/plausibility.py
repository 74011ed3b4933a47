"""Plausibility of a recording: what is probably a unit mistake or the wrong kind of data, said before a fit or a
compensation quietly produces a wrong result.

Each check is a pure function of the recording that returns the concerns it finds (empty when none); the
pipelines and ``apply`` turn them into :class:`gyrocomp.errors.PlausibilityWarning` (a
:class:`DataQualityWarning`) whose ``check`` names the check and whose message ends ``(check 'NAME')``. One
check is silenced with ``warnings.filterwarnings("ignore", message=silence_pattern("rotation"))``, all of them
with ``category=PlausibilityWarning``.

The limits are physical, not tuned: MEMS gyros measure at most a few thousand deg/s; a zero-rate offset is at
most tens of deg/s (the MPU-6050's tolerance is +-20 deg/s); a bias does not move by tens of deg/s within a run
at rest; temperatures of electronics in degC lie far below 150 (in kelvin they are above 200); sample rates of
logged IMUs lie between 1 mHz and 100 kHz.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import CHECKS, CheckName, InputError, PlausibilityWarning, silence_pattern
from .effects import moving_average
from .recording import Recording
from .prepared import PreparedRun

#: beyond any MEMS gyro's measurement range [deg/s]
MAX_RATE_DPS = 5000.0
#: the most any MEMS accelerometer measures [g]
MAX_ACCEL_G = 1000.0
#: beyond any zero-rate offset at rest [deg/s]
MAX_OFFSET_DPS = 50.0
#: a bias moves less than this within a run at rest; more is rotation [deg/s], judged on 10 s means
MAX_SWING_DPS = 25.0
SWING_WINDOW_S = 10.0
#: electronics read in degC stay below this; a median above it is probably kelvin [degC]
KELVIN_LOOKING_DEGC = 150.0
#: a calibration run that varies less than this in temperature cannot identify a temperature curve [degC]
MIN_TEMPERATURE_SPAN_DEGC = 1.0
#: still poses of a hand-turned multi-position session: 1 s still, judged on 0.5 s windows, up to 10 times the
#: median variance (as gyrocomp.models.triad_fit.find_poses finds them)
POSE_WINDOW_S, POSE_MIN_S, POSE_FACTOR = 0.5, 1.0, 10.0
#: plausible sample rates of a logged IMU [Hz] (the fastest MEMS output data rates are 32 kHz)
RATE_RANGE_HZ = (1e-3, 4e4)
#: a recording this long at 1 Hz or slower is more likely a time column in ms read as s [s]
LONG_SLOW_S = 7 * 86400.0


@dataclass(frozen=True)
class Concern:
    """One finding: the check that found it (``rate``, ``offset``, ``rotation``, ``kelvin``, ``time-unit``,
    ``temperature-span``) and the one-line message, which starts with the recording's source."""

    check: CheckName
    message: str

    def warning(self) -> PlausibilityWarning:
        """The warning to raise: the message ending with ``(check 'NAME')``, ``check`` set."""
        return PlausibilityWarning(f"{self.message} (check '{self.check}')", check=self.check)


def recording_concerns(recording: Recording) -> list[Concern]:
    """Unit mistakes any use of ``recording`` suffers from: values beyond any MEMS range, kelvin-looking
    temperatures, an implausible sample rate (a time column in ms read as s, or the reverse)."""
    out = []
    src = recording.source
    peak = float(np.max(np.abs(recording.gyro_dps))) if recording.gyro_dps.size else 0.0
    if peak > MAX_RATE_DPS:
        out.append(Concern("rate", f"{src}: gyro values up to {peak:.3g} deg/s, beyond any MEMS gyro's range "
                                   f"({MAX_RATE_DPS:g} deg/s): a unit mistake or a corrupt file?"))
    if recording.temperature_degc is not None:
        median = float(np.median(recording.temperature_degc))
        if median > KELVIN_LOOKING_DEGC:
            out.append(Concern("kelvin", f"{src}: median temperature {median:.4g} degC looks like kelvin; "
                                         "gyrocomp reads degC (subtract 273.15)"))
    lo, hi = RATE_RANGE_HZ
    if not lo <= recording.rate_hz <= hi:
        out.append(Concern("time-unit", f"{src}: {recording.rate_hz:.3g} Hz is no IMU's sample rate: is the time "
                                        "column in another unit than the one given?"))
    elif recording.duration_s > LONG_SLOW_S and recording.rate_hz <= 1.0:
        out.append(Concern("time-unit", f"{src}: {recording.duration_s / 86400:.3g} days at {recording.rate_hz:.3g} "
                                        "Hz: is the time column in ms read as s?"))
    return out


def calibration_concerns(recording: Recording) -> list[Concern]:
    """What makes ``recording`` a poor calibration run besides :func:`recording_concerns`: a zero-rate offset
    no MEMS part has, or a swing of the 10 s means that only rotation makes (a 10 s mean is the angle turned
    over 10 s: turning a unit between positions, 90 or 180 degrees, stays below the limit, a rate table does
    not; a hand-turned multi-position session may exceed it and is recognized, :func:`turned_between_poses`)."""
    out = recording_concerns(recording)
    src = recording.source
    w = max(1, int(round(SWING_WINDOW_S * recording.rate_hz)))
    for j, axis in enumerate(recording.gyro_axes):
        x = recording.gyro_dps[:, j]
        median = float(np.median(x))
        if abs(median) > MAX_OFFSET_DPS:
            out.append(Concern("offset", f"{src}: {axis} reads {median:.3g} deg/s at the median, more than any "
                                         "zero-rate offset: does the unit turn, or is the unit of the data wrong?"))
        if x.size >= w:
            swing = float(np.ptp(moving_average(x, w)))
            if swing > MAX_SWING_DPS and not turned_between_poses(recording):
                out.append(Concern("rotation", f"{src}: {axis} swings by {swing:.3g} deg/s over {SWING_WINDOW_S:g} s "
                                               "means: the unit turns, and a calibration run must be at rest "
                                               "(record still positions, or cut the run to them)"))
    return out


def turned_between_poses(recording: Recording) -> bool:
    """Whether the recording is a multi-position session: still poses (of at least 1 s) whose gravity directions
    turn every accelerometer axis within 60 deg of up and of down. Its turns are meant (the fits use its still
    stretches, and the scale-factor fit its turns), so its swing is no sign of a run that should have been at
    rest."""
    if recording.accel_g is None or recording.accel_g.shape[1] != 3:
        return False
    segments = PreparedRun.of(recording).static_segments(window_s=POSE_WINDOW_S, min_duration_s=POSE_MIN_S,
                                                        factor=POSE_FACTOR)
    if len(segments) < 6:
        return False
    means = np.array([recording.accel_g[s.start:s.stop].mean(axis=0) for s in segments])
    units = means / np.maximum(np.linalg.norm(means, axis=1), 1e-12)[:, None]
    return bool(np.all(np.any(units > 0.5, axis=0)) and np.all(np.any(units < -0.5, axis=0)))


def _largest_span_degc(recordings: list[Recording]) -> float | None:
    """The largest temperature span of any run [degC], or None when no run has a temperature."""
    spans = [float(np.ptp(r.temperature_degc)) for r in recordings if r.temperature_degc is not None]
    return max(spans) if spans else None


def require_temperature_span(recordings: list[Recording], what: str) -> None:
    """Refuse to compare temperature models on runs whose temperature does not vary at all: every such model
    is then undetermined (``what`` names the operation in the message)."""
    span = _largest_span_degc(recordings)
    if span is not None and span < MIN_TEMPERATURE_SPAN_DEGC:
        raise InputError(f"{recordings[0].source}: the temperature of every run spans at most {span:.3g} degC; "
                         f"{what} compares temperature models, which need runs over a temperature range")


def temperature_span_concern(recordings: list[Recording]) -> Concern | None:
    """A temperature curve asked for on runs that each stay at one temperature: with one constant per run, such
    runs say nothing about the curve (a multi-position run at room temperature is fine for G alone)."""
    span = _largest_span_degc(recordings)
    if span is None or span >= MIN_TEMPERATURE_SPAN_DEGC:
        return None
    return Concern("temperature-span", f"{recordings[0].source}: the temperature of every run spans at most "
                                       f"{span:.3g} degC; a temperature curve needs runs over a temperature "
                                       "range (or fit with temperature=none)")


__all__ = ["CHECKS", "CheckName", "Concern", "calibration_concerns", "recording_concerns", "require_temperature_span",
           "silence_pattern", "temperature_span_concern", "turned_between_poses"]
