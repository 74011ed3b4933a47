"""One recording cut into runs, so that a file holding several power-ons, poses or temperature legs becomes the
runs a fit takes (``gyrocomp split``).

- ``gap``: at every time gap (the recording's own, :attr:`~gyrocomp.recording.Recording.gaps`);
- ``power-on``: at gaps of at least ``min_gap_s`` (a logger stopped and started again; short dropouts stay);
- ``still``: the poses held still: the still segments (:func:`gyrocomp.motion.stillness.detect_still`), neighbours whose
  gravity direction agrees within ``POSE_ANGLE_DEG`` joined into one pose (a drift with temperature breaks a still
  stretch into pieces; the pose is the same), the moves between poses left out; poses of at least
  ``min_still_s`` kept. E.g. the static periods of a tag turned by hand between orientations. Without an
  accelerometer, the still segments themselves;
- ``temperature-turn``: at each turning point of the temperature (:func:`gyrocomp.effects.find_turns`, a reversal
  counted when the temperature came back by more than ``min_leg_degc``), so each run heats or cools.

Units: time [s], temperature [degC].
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..effects import find_turns
from ..errors import InputError
from ..recording import Recording
from ..motion.stillness import detect_still

SplitBy = Literal["power-on", "gap", "still", "temperature-turn"]
SPLITS: tuple[str, ...] = ("power-on", "gap", "still", "temperature-turn")
#: still segments whose mean specific force points within this angle of each other are one pose [deg]
POSE_ANGLE_DEG = 10.0


@dataclass(frozen=True)
class RunPiece:
    """One run cut from a recording: its samples [start, stop) and the recording of them."""

    start: int
    stop: int
    recording: Recording

    @property
    def start_s(self) -> float:
        """Its first sample's time [s]."""
        return float(self.recording.time_s[0])


def _poses(rec: Recording, min_still_s: float) -> list[tuple[int, int]]:
    """Still segments joined into poses (see the module), those lasting ``min_still_s`` or more."""
    return [(a, b) for a, b, _ in _joined_poses(rec) if rec.time_s[b - 1] - rec.time_s[a] >= min_still_s]


def _joined_poses(rec: Recording) -> list[list]:
    """The still segments, neighbours whose gravity direction agrees joined: [start, stop, mean force [g]]."""
    segments = detect_still(rec).segments
    poses: list[list] = []
    cos_max = np.cos(np.radians(POSE_ANGLE_DEG))
    for seg in segments:
        if poses and seg.accel_mean_g is not None and poses[-1][2] is not None:
            a, b = poses[-1][2], seg.accel_mean_g
            if float(np.dot(a, b)) >= cos_max * float(np.linalg.norm(a) * np.linalg.norm(b)):
                poses[-1][1] = seg.stop
                continue
        poses.append([seg.start, seg.stop, seg.accel_mean_g])
    return poses


def _bounds(rec: Recording, by: str, min_gap_s: float, min_still_s: float, min_leg_degc: float) -> list[tuple]:
    n = rec.n_samples
    if by == "gap":
        return [(s.start, s.stop) for s in rec.contiguous_stretches()]
    if by == "power-on":
        cuts = (np.flatnonzero(np.diff(rec.time_s) >= min_gap_s) + 1).tolist()
        return list(zip([0, *cuts], [*cuts, n]))
    if by == "still":
        return _poses(rec, min_still_s)
    if rec.temperature_degc is None:
        raise InputError(f"{rec.source}: by=temperature-turn: the recording has no temperature")
    temperature = rec.temperature_degc
    turns = find_turns(temperature, min_leg_degc)
    cuts, previous = [], 0
    for confirmed in turns.turn_index:
        piece = temperature[previous : confirmed + 1]
        rising = turns.direction[max(confirmed - 1, 0)] > 0
        cut = previous + int(np.argmax(piece) if rising else np.argmin(piece))
        if cut > previous:
            cuts.append(cut)
            previous = cut
    return list(zip([0, *cuts], [*cuts, n]))


def split_runs(
    rec: Recording,
    by: SplitBy,
    *,
    min_gap_s: float = 60.0,
    min_still_s: float = 600.0,
    min_leg_degc: float = 2.0,
    min_samples: int = 10,
) -> list[RunPiece]:
    """Cut ``rec`` into runs (see the module), in time order, each of at least ``min_samples`` samples.

    Parameters
    ----------
    rec : Recording
        The recording [s, deg/s, g, degC].
    by : {"power-on", "gap", "still", "temperature-turn"}
    min_gap_s : float
        ``power-on``: the shortest gap that separates two power-ons [s].
    min_still_s : float
        ``still``: the shortest still segment kept [s].
    min_leg_degc : float
        ``temperature-turn``: how far the temperature must come back for a turn to count [degC].
    min_samples : int
        Pieces shorter than this are left out.

    Raises :class:`InputError` for an unknown ``by``, a bound that is not positive, or no piece found.
    """
    if by not in SPLITS:
        raise InputError(f"by: {by!r}; use one of {', '.join(SPLITS)}")
    for name, value in (("min_gap_s", min_gap_s), ("min_still_s", min_still_s), ("min_leg_degc", min_leg_degc)):
        if not (np.isfinite(value) and value > 0):
            raise InputError(f"{name}: must be a positive number, got {value:g}")
    pieces = [
        RunPiece(a, b, rec.take(slice(a, b)))
        for a, b in _bounds(rec, by, min_gap_s, min_still_s, min_leg_degc)
        if b - a >= min_samples
    ]
    if not pieces:
        if by == "still":  # the poses found were all shorter than asked
            longest = max((rec.time_s[b - 1] - rec.time_s[a] for a, b, _ in _joined_poses(rec)), default=0.0)
            raise InputError(
                f"{rec.source}: by=still: no still pose of min_still_s={min_still_s:g} s or more (the longest "
                f"lasts {longest:.4g} s); a shorter min_still_s keeps shorter ones"
            )
        raise InputError(f"{rec.source}: by={by}: no run of {min_samples} samples or more found")
    return pieces


__all__ = ["RunPiece", "SPLITS", "SplitBy", "split_runs"]
