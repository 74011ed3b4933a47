"""Calibration without a chamber: fit on the still moments of everyday logs.

A field log (a flight, a drive, a robot's shift) starts cold, warms up by self-heating, and stands still now and
then. :func:`field_recordings` finds each log's still segments (:func:`gyrocomp.motion.stillness.detect_still`) and keeps
only those samples, as one run per log (each log is one power-on, with its own turn-on constant); the fit then
sees a chamber-like run with holes where the vehicle moved (the thermal lag is carried across them, the
temperature taken as linear over each hole). Still segments at different attitudes also give the g-sensitivity.

``still_only="auto"`` keeps every sample of a log that is still most of the time (a chamber run, a multi-position
session whose turns the scale-factor fit needs) and only the still samples of a log that moves most of the time
(fewer than ``AUTO_STILL_FRACTION`` of its whole blocks still; such a log without a still segment is refused). A
log of fewer than ``AUTO_MIN_BLOCKS`` whole blocks (a minute at 10 Hz and up) is too short to judge and is used
whole, as is one still most of the time whatever its segments (a multi-position session whose poses are shorter
than a segment).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..errors import InputError
from ..recording import Recording
from ..motion.stillness import (
    AUTO_MIN_BLOCKS,
    AUTO_STILL_FRACTION,
    MIN_DURATION_S,
    StillDetection,
    detect_still,
    moves_most_of_the_time,
)

#: the still data of all logs together must span at least this [degC]
MIN_FIELD_SPAN_DEGC = 5.0

StillOnly = Literal["auto", "yes", "no"]


@dataclass(frozen=True)
class LogContribution:
    """What one log gave the fit: its still time [s] and segments, the temperature range they cover [degC] (None
    without still data), and whether only its still samples were kept."""

    source: str
    duration_s: float
    still_s: float
    segments: int
    temperature_min_degc: float | None
    temperature_max_degc: float | None
    still_only: bool

    @property
    def still_fraction(self) -> float:
        return self.still_s / self.duration_s if self.duration_s > 0 else 0.0


def field_recordings(
    recordings: list[Recording], still_only: StillOnly = "auto", *, min_still_s: float = MIN_DURATION_S
) -> tuple[list[Recording], list[LogContribution]]:
    """The runs to fit from ``recordings`` (see the module), and what each log contributed.

    Parameters
    ----------
    recordings : list of Recording
        One power-on each [s, deg/s, g, degC], with a temperature.
    still_only : {"auto", "yes", "no"}
        Keep only the still samples of every log (``"yes"``), of the logs that move most of the time
        (``"auto"``), or of none (``"no"``: the recordings as given).
    min_still_s : float
        Shortest still segment used [s].

    Raises :class:`InputError` for a log without temperature (``"yes"``; ``"auto"`` uses such a run as given, as it
    does a rate table's), when no log kept for its still samples has a still segment, or when their still data
    together span less than ``MIN_FIELD_SPAN_DEGC``. The contributions list the logs looked at.
    """
    if still_only not in ("auto", "yes", "no"):
        raise InputError(f"still_only: {still_only!r}; use auto, yes or no")
    if still_only == "no":
        return list(recordings), []
    runs, contributions = [], []
    for rec in recordings:
        if rec.temperature_degc is None or rec.reference_rate_dps is not None:
            if still_only == "yes" and rec.temperature_degc is None:
                raise InputError(
                    f"{rec.source}: no temperature; a field calibration learns the bias against temperature"
                )
            runs.append(rec)  # auto: a run for the accelerometer, G or a rate table, used as given
            continue
        found = detect_still(rec, min_duration_s=min_still_s)
        keep = still_only == "yes" or moves_most_of_the_time(found)
        contributions.append(_contribution(rec, found, keep))
        if not keep:
            runs.append(rec)
        elif found.segments:
            runs.append(rec.take(found.mask(rec.n_samples)))
    if any(c.still_only for c in contributions):
        _require_still_data([c for c in contributions if c.still_only])
    return runs, contributions


def _contribution(rec: Recording, found: StillDetection, keep: bool) -> LogContribution:
    temps = [
        (s.temperature_min_degc, s.temperature_max_degc) for s in found.segments if s.temperature_min_degc is not None
    ]
    if not keep:  # the whole log is used
        temps = [(float(np.min(rec.temperature_degc)), float(np.max(rec.temperature_degc)))]
    return LogContribution(
        rec.source,
        rec.duration_s,
        found.still_s,
        len(found.segments),
        min(t[0] for t in temps) if temps else None,
        max(t[1] for t in temps) if temps else None,
        keep,
    )


def _require_still_data(contributions: list[LogContribution]) -> None:
    used = [c for c in contributions if c.temperature_min_degc is not None]
    if not used:
        raise InputError(
            f"{contributions[0].source}: no still segment of at least the minimum length in any log "
            f"({len(contributions)} log(s)); a field calibration needs the vehicle still for a while"
        )
    low = min(c.temperature_min_degc for c in used)
    high = max(c.temperature_max_degc for c in used)
    if high - low < MIN_FIELD_SPAN_DEGC:
        raise InputError(
            f"{used[0].source}: the still data of {len(used)} log(s) cover {low:.1f}..{high:.1f} degC "
            f"({high - low:.1f} degC); a temperature model needs at least {MIN_FIELD_SPAN_DEGC:g} degC "
            "(log cold starts and warm-ups, still now and then)"
        )


__all__ = [
    "AUTO_MIN_BLOCKS",
    "AUTO_STILL_FRACTION",
    "LogContribution",
    "MIN_FIELD_SPAN_DEGC",
    "StillOnly",
    "field_recordings",
    "moves_most_of_the_time",
]
