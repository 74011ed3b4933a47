"""How the calibration data is held out for the model choice: whole runs, heating and cooling legs, or time
blocks (:func:`make_folds`), and the moving-average window of the held-out score (:func:`window_for`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..effects import find_turns
from ..runs.prepared import RunBlocks

FoldKind = Literal["runs", "legs", "blocks"]
FOLD_KINDS = ("auto", "runs", "legs", "blocks")
#: the fewest folds a choice is made on; runs are split into legs (or blocks) below this
MIN_FOLDS = 3
#: with blocks, each run is cut into this many contiguous pieces (at least MIN_FOLDS in all)
BLOCKS_PER_RUN = 4
#: the moving-average window of the score: a tenth of the median fold, within these bounds [s]
WINDOW_MIN_S = 60.0
WINDOW_MAX_S = 600.0


@dataclass(frozen=True)
class Folds:
    """How the calibration data is held out: the fold of every block of every run, and each fold's name."""

    kind: FoldKind
    of_block: tuple[np.ndarray, ...]
    names: tuple[str, ...]
    #: why the folds are not of the kind asked for ("" when they are)
    note: str = ""

    @property
    def count(self) -> int:
        return len(self.names)


def _split_long(leg_of_block: np.ndarray, pieces: int) -> np.ndarray:
    """Cut a run's blocks into ``pieces`` contiguous parts of equal length."""
    n = leg_of_block.size
    return np.minimum((np.arange(n) * pieces) // max(n, 1), pieces - 1)


def leg_labels(temperature_degc: np.ndarray, threshold_degc: float, min_length: int) -> tuple[np.ndarray, list[int]]:
    """The heating or cooling leg of each sample: legs split where a reversal is confirmed
    (:func:`gyrocomp.effects.find_turns`), a leg shorter than ``min_length`` samples joined to the one before.
    Returns the leg number of each sample and each leg's direction (+1 heating, -1 cooling, 0 unknown)."""
    turns = find_turns(temperature_degc, threshold_degc)
    n = turns.direction.size
    kept: list[int] = []
    for c in (int(i) for i in turns.turn_index):
        if c - (kept[-1] if kept else 0) >= min_length and n - c >= min_length:
            kept.append(c)
    labels = np.searchsorted(np.asarray(kept, dtype=np.int64), np.arange(n), side="right")
    starts = [0] + kept
    # a leg's direction: the one most of its samples carry (the first samples of a run have none yet)
    directions = []
    for j, start in enumerate(starts):
        stop = kept[j] if j < len(kept) else n
        d = turns.direction[start:stop]
        directions.append(int(np.sign(np.sum(d))) if d.size else 0)
    return labels, directions


def make_folds(
    runs: list[RunBlocks],
    groups: tuple[int, ...],
    thresholds_degc: list[float],
    kind: str = "auto",
    min_leg_blocks: int = 10,
) -> Folds:
    """The folds of a selection.

    Parameters
    ----------
    runs : list of RunBlocks
        Block means of each recording (one axis).
    groups : tuple of int
        The run each recording belongs to (pieces of one run are held out together).
    thresholds_degc : list of float
        Turning-point threshold of each recording [degC].
    kind : {"auto", "runs", "legs", "blocks"}
        ``auto``: runs with at least ``MIN_FOLDS`` runs, else the heating and cooling legs (two or more), else
        (the temperature never reverses) time blocks. Asked-for folds that the data cannot give are replaced by
        the next kind in that order, and ``Folds.note`` says why; blocks only when asked for or when nothing
        else is possible.
    min_leg_blocks : int
        A leg shorter than this many blocks joins the leg before it.
    """
    n_groups = len(set(groups))
    asked = kind
    if kind == "auto":
        kind = "runs" if n_groups >= MIN_FOLDS else "legs"
    if kind == "runs" and n_groups < 2:
        kind = "legs"
    if kind == "runs":
        ids = sorted(set(groups))
        return Folds(
            "runs",
            tuple(np.full(r.value.size, ids.index(g)) for r, g in zip(runs, groups)),
            tuple(f"run {g + 1}" for g in ids),
        )
    legs, names = _legs(runs, thresholds_degc, min_leg_blocks)
    note = "" if asked in ("auto", kind) else f"folds={asked!r}: one run cannot be held out against others; "
    if kind == "legs" and len(names) >= 2:
        offsets = np.cumsum([0] + [int(leg.max()) + 1 for leg in legs[:-1]])
        return Folds(
            "legs",
            tuple(leg + o for leg, o in zip(legs, offsets)),
            tuple(names),
            note + "held out each heating and cooling leg" if note else "",
        )
    if kind == "legs":
        note = (f"folds={asked!r}: " if asked != "auto" else "") + (
            "the temperature never reverses, so there are no heating and cooling legs to hold out; held out "
            f"{BLOCKS_PER_RUN} contiguous time blocks per run instead (neighbouring blocks share slow drift)"
        )
    return _time_blocks(runs, note)


def _legs(runs: list[RunBlocks], thresholds_degc: list[float], min_leg_blocks: int) -> tuple[list, list[str]]:
    """Each run's leg of each block (numbered within the run) and every leg's name, in order."""
    legs, names = [], []
    for k, (run, threshold) in enumerate(zip(runs, thresholds_degc)):
        leg, directions = leg_labels(run.temperature_degc, threshold, min_leg_blocks)
        legs.append(leg)
        names += [
            f"run {k + 1} leg {j + 1}" + {1: " (heating)", -1: " (cooling)"}.get(d, "")
            for j, d in enumerate(directions)
        ]
    return legs, names


def _time_blocks(runs: list[RunBlocks], note: str) -> Folds:
    """Folds of contiguous time blocks, ``BLOCKS_PER_RUN`` per run (more when there are few runs)."""
    per_run = max(BLOCKS_PER_RUN, math.ceil(MIN_FOLDS / len(runs)))
    of_block, names = [], []
    for k, run in enumerate(runs):
        of_block.append(_split_long(np.zeros(run.value.size), per_run) + k * per_run)
        names += [f"run {k + 1} block {j + 1}" for j in range(per_run)]
    return Folds("blocks", tuple(of_block), tuple(names), note)


def drift_window_s(fold_lengths_s, shortest_s: float) -> float:
    """The one definition of the held-out drift's moving-average window [s], shared by the model choice
    (``fit``) and ``validate``: a tenth of the median fold length [s], within [WINDOW_MIN_S, WINDOW_MAX_S], at
    most a quarter of the shortest fold (a window that still moves within it), at least ``shortest_s`` [s]
    (a block or a sample)."""
    lengths = [float(v) for v in fold_lengths_s]
    window = float(np.clip(np.median(lengths) / 10.0, WINDOW_MIN_S, WINDOW_MAX_S))
    return max(shortest_s, min(window, min(lengths) / 4.0))


def window_for(folds: Folds, runs: list[RunBlocks], block_s: float) -> float:
    """The score's moving-average window [s] (:func:`drift_window_s` of the folds' lengths)."""
    lengths = []
    for f in range(folds.count):
        n = sum(int(np.count_nonzero(fold == f)) for fold in folds.of_block)
        lengths.append(n * block_s)
    return drift_window_s(lengths, block_s)


__all__ = [
    "BLOCKS_PER_RUN",
    "FOLD_KINDS",
    "FoldKind",
    "Folds",
    "MIN_FOLDS",
    "WINDOW_MAX_S",
    "WINDOW_MIN_S",
    "drift_window_s",
    "leg_labels",
    "make_folds",
    "window_for",
]
