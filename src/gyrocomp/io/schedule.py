"""A rate table's schedule: the rates it applied, when, in which run, as a CSV file instead of columns.

Rate-table software logs its commanded rates apart from the IMU data more often than in the same file. A
schedule names, for each run, the stretches of constant rate::

    file,start_s,end_s,ref_rate_x,ref_rate_y,ref_rate_z
    rt_25C.csv,60,120,100,0,0
    rt_25C.csv,120,180,-100,0,0

``file`` is the run's file name (as given, or its last part); ``start_s``/``end_s`` are seconds from the run's
first sample, [start_s, end_s); the rates are the table's rate in the sensor frame [deg/s]. Between the listed
stretches the table stands still (0 deg/s). Applied to a run, the schedule gives its ``reference_rate_dps``
exactly as ``ref_rate_x/_y/_z`` columns would.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..recording import REFERENCE_RATE_AXES, Recording

SCHEDULE_COLUMNS = ("file", "start_s", "end_s") + REFERENCE_RATE_AXES


@dataclass(frozen=True)
class RateStretch:
    """One stretch of constant table rate: seconds from the run's first sample [s], rate [deg/s], and the row
    of the schedule it came from (1-based, the header being row 1)."""

    file: str
    start_s: float
    end_s: float
    rate_dps: tuple[float, float, float]
    row: int


@dataclass(frozen=True)
class RateSchedule:
    """The stretches of a schedule file (see the module doc)."""

    stretches: tuple[RateStretch, ...]
    source: str

    @property
    def files(self) -> tuple[str, ...]:
        """The runs the schedule names, in order of first appearance."""
        return tuple(dict.fromkeys(s.file for s in self.stretches))

    def names(self, path: str | os.PathLike) -> str | None:
        """The schedule's name for the run at ``path`` (the path as given or its last part), None when absent."""
        for name in (str(path), Path(path).name):
            if name in self.files:
                return name
        return None

    def apply(self, recording: Recording, name: str) -> Recording:
        """``recording`` with the reference rates of the run the schedule calls ``name`` [deg/s]."""
        if recording.reference_rate_dps is not None:
            raise InputError(
                f"{recording.source}: has ref_rate_x/_y/_z columns and the schedule {self.source} names "
                "it too; give the rates once"
            )
        t = recording.time_s - recording.time_s[0]
        reference = np.zeros((recording.n_samples, 3))
        for s in self.stretches:
            if s.file != name:
                continue
            if s.start_s >= t[-1]:
                raise InputError(
                    f"{self.source}, row {s.row}: start_s {s.start_s:g} s is after the end of "
                    f"{recording.source} ({t[-1]:g} s)"
                )
            reference[(t >= s.start_s) & (t < s.end_s)] = s.rate_dps
        return replace(recording, reference_rate_dps=reference)


def apply_schedule(
    schedule: RateSchedule, recordings: list[Recording], paths: list[str | os.PathLike]
) -> list[Recording]:
    """Each recording (read from the matching path) with its reference rates when the schedule names it; refuses
    a schedule that names a run not among them."""
    out, used = [], set()
    for rec, path in zip(recordings, paths):
        name = schedule.names(path)
        out.append(rec if name is None else schedule.apply(rec, name))
        used.add(name)
    unused = [f for f in schedule.files if f not in used]
    if unused:
        row = next(s.row for s in schedule.stretches if s.file == unused[0])
        raise InputError(f"{schedule.source}, row {row}: file {unused[0]!r} is not among the runs given")
    return out


def read_rate_schedule(path: str | os.PathLike) -> RateSchedule:
    """Read and check a schedule file (CSV, see the module doc): every column present, numbers finite,
    end_s > start_s >= 0, no two stretches of one run overlapping."""
    import pandas as pd  # slow to import; only a schedule file needs it

    path = Path(path)
    try:
        table = pd.read_csv(path, dtype={"file": str}, keep_default_na=False)
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not a readable CSV schedule ({str(exc).splitlines()[0]})") from None
    missing = [c for c in SCHEDULE_COLUMNS if c not in table.columns]
    if missing:
        raise InputError(
            f"{path}: schedule column(s) {', '.join(missing)} missing; it needs {', '.join(SCHEDULE_COLUMNS)}"
        )
    stretches = []
    for i, row in enumerate(table.itertuples(index=False), start=2):
        values = {}
        for col in SCHEDULE_COLUMNS[1:]:
            value = pd.to_numeric(pd.Series([getattr(row, col)]), errors="coerce").iloc[0]
            if not np.isfinite(value):
                raise InputError(f"{path}, row {i}: {col} {getattr(row, col)!r} is not a finite number")
            values[col] = float(value)
        if not str(row.file).strip():
            raise InputError(f"{path}, row {i}: file is empty; name the run the stretch belongs to")
        if not 0 <= values["start_s"] < values["end_s"]:
            raise InputError(
                f"{path}, row {i}: start_s {values['start_s']:g}, end_s {values['end_s']:g}; need "
                "0 <= start_s < end_s [s from the run's first sample]"
            )
        stretches.append(
            RateStretch(
                str(row.file).strip(),
                values["start_s"],
                values["end_s"],
                tuple(values[c] for c in REFERENCE_RATE_AXES),
                i,
            )
        )
    if not stretches:
        raise InputError(f"{path}: the schedule has no stretches")
    for name in dict.fromkeys(s.file for s in stretches):
        own = sorted((s for s in stretches if s.file == name), key=lambda s: s.start_s)
        for a, b in zip(own, own[1:]):
            if b.start_s < a.end_s:
                raise InputError(f"{path}, rows {a.row} and {b.row}: the stretches of {name} overlap")
    return RateSchedule(tuple(stretches), str(path))


__all__ = ["RateSchedule", "RateStretch", "SCHEDULE_COLUMNS", "apply_schedule", "read_rate_schedule"]
