"""The checks of the samples themselves, taken a part of a run at a time: a gyro axis that says nothing (one value
in every sample), two axes that hold the same samples, raw counts (every sample a whole number), temperature
spikes (a sample far from the median of its neighbours).

:class:`SampleCheck` is fed a run's consecutive parts (:meth:`SampleCheck.add`, a chunk of a streamed table or the
whole run) and gives the same :class:`SampleFacts` whatever the parts: the data check
(:mod:`gyrocomp.measures.data_check`) feeds it a whole run, ``apply`` each chunk it compensates.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from ..recording import Recording

#: a temperature sample this far from the median of its TEMPERATURE_SPIKE_SAMPLES neighbours is a spike [degC]: a
#: die changes temperature by well under a degree in a few samples, even on a 10 degC/min chamber ramp logged at 1 Hz
TEMPERATURE_SPIKE_DEGC, TEMPERATURE_SPIKE_SAMPLES = 2.0, 9
#: the first spikes whose rows are kept to be named
SPIKE_ROWS_NAMED = 3


@dataclass(frozen=True)
class SampleFacts:
    """What :class:`SampleCheck` found in a run's samples.

    Attributes
    ----------
    gyro_axes : tuple of str
    n_samples : int
    constant_dps : dict of int to float
        The axes (indices) whose every sample is one value, and that value [deg/s].
    identical : tuple of (int, int)
        Pairs of axes (indices, neither constant) that hold the same samples in every row.
    whole_numbers : bool
        Every gyro sample, on every axis, is a whole number.
    spread_dps : float
        The largest range of an axis's samples [deg/s].
    spikes : int
        Temperature samples :data:`TEMPERATURE_SPIKE_DEGC` or more from the median of the
        :data:`TEMPERATURE_SPIKE_SAMPLES` around them (0 where the temperature is absent, not finite in every row
        or shorter than the window).
    spike_rows : tuple of int
        The file rows of the first :data:`SPIKE_ROWS_NAMED` spikes.
    spike_worst_degc : float
        The largest distance of a spike from the median of its neighbours [degC].
    temperature_samples : int
        Temperature samples checked for spikes.
    """

    gyro_axes: tuple[str, ...]
    n_samples: int
    constant_dps: dict[int, float]
    identical: tuple[tuple[int, int], ...]
    whole_numbers: bool
    spread_dps: float
    spikes: int
    spike_rows: tuple[int, ...]
    spike_worst_degc: float
    temperature_samples: int


class SampleCheck:
    """The sample checks of one run, fed its consecutive parts in order (see the module)."""

    def __init__(self) -> None:
        self._axes: tuple[str, ...] | None = None
        self._n = 0
        self._first: np.ndarray | None = None
        self._varies: np.ndarray | None = None
        self._differ: np.ndarray | None = None  # (axes, axes): some row differs
        self._whole = True
        self._lo: np.ndarray | None = None
        self._hi: np.ndarray | None = None
        self._spikes = _Spikes()

    def add(self, recording: Recording) -> SampleCheck:
        """Take the next part of the run (its rows after those given before); returns self."""
        x = np.asarray(recording.gyro_dps, dtype=float)
        if self._axes is None:
            self._axes = tuple(recording.gyro_axes)
            m = x.shape[1]
            self._varies = np.zeros(m, dtype=bool)
            self._differ = np.zeros((m, m), dtype=bool)
            self._lo, self._hi = np.full(m, np.inf), np.full(m, -np.inf)
        if x.shape[0]:
            if self._first is None:
                self._first = x[0].copy()
            self._varies |= np.any(x != self._first, axis=0)
            for j in range(x.shape[1]):
                for k in range(j + 1, x.shape[1]):
                    if not self._differ[j, k] and not np.array_equal(x[:, j], x[:, k]):
                        self._differ[j, k] = True
            self._whole = self._whole and bool(np.all(x == np.round(x)))
            self._lo, self._hi = np.minimum(self._lo, x.min(axis=0)), np.maximum(self._hi, x.max(axis=0))
        self._n += x.shape[0]
        self._spikes.add(_temperature(recording, x.shape[0]), np.asarray(recording.row_numbers))
        return self

    def facts(self) -> SampleFacts:
        """What the parts given so far show, as one run."""
        axes = self._axes or ()
        m = len(axes)
        constant = {j: float(self._first[j]) for j in range(m) if self._n and not self._varies[j]}
        identical = tuple(
            (j, k)
            for j in range(m)
            for k in range(j + 1, m)
            if self._n and j not in constant and not self._differ[j, k]
        )
        spread = float(np.max(self._hi - self._lo)) if self._n and m else 0.0
        count, rows, worst, checked = self._spikes.finish()
        return SampleFacts(
            axes, self._n, constant, identical, self._whole and self._n > 0, spread, count, rows, worst, checked
        )


def _temperature(recording: Recording, n: int) -> np.ndarray | None:
    """A part's temperature [degC] (the mean of several sensors); None when absent or not finite in every row."""
    t = recording.temperature_degc
    if t is None:
        return None
    t = np.asarray(t, dtype=float)
    t = t.mean(axis=1) if t.ndim == 2 else t
    return t if t.size == n and np.isfinite(t).all() else None


class _Spikes:
    """Temperature spikes over consecutive parts: each sample is judged once the samples around it are in, the
    run's ends mirrored, as one pass over the whole run would judge it."""

    def __init__(self) -> None:
        self._half = TEMPERATURE_SPIKE_SAMPLES // 2
        self._t = np.zeros(0)
        self._rows = np.zeros(0, dtype=np.int64)
        self._at_start = True  # the held samples begin at the run's start
        self._judged = 0  # of the held samples, this many are judged
        self._valid = True
        self._count, self._named, self._worst, self._checked = 0, [], 0.0, 0

    def add(self, t: np.ndarray | None, rows: np.ndarray) -> None:
        """Take a part's temperatures [degC] (None: the run is not checked) and file rows."""
        if t is None:
            self._valid = False
        if not self._valid:
            return
        self._t, self._rows = np.concatenate([self._t, t]), np.concatenate([self._rows, rows])
        self._checked += t.size
        if self._t.size > 2 * self._half + 1:
            self._judge(self._t.size - self._half, at_end=False)

    def finish(self) -> tuple[int, tuple[int, ...], float, int]:
        """(spikes, the first ones' rows, the worst distance [degC], samples checked)."""
        if not self._valid or self._checked < TEMPERATURE_SPIKE_SAMPLES:
            return 0, (), 0.0, self._checked if self._valid else 0
        self._judge(self._t.size, at_end=True)
        return self._count, tuple(self._named), self._worst, self._checked

    def _judge(self, stop: int, at_end: bool) -> None:
        """Judge the held samples from the first not judged up to ``stop``, then keep only those the next ones
        need."""
        h = self._half
        padded = np.pad(self._t, (h if self._at_start else 0, h if at_end else 0), mode="reflect")
        local = np.median(sliding_window_view(padded, 2 * h + 1), axis=1)  # of each held sample from h (or 0) on
        offset = 0 if self._at_start else h  # the held index of local[0]
        idx = np.arange(self._judged, stop)
        distance = np.abs(self._t[idx] - local[idx - offset])
        far = idx[distance >= TEMPERATURE_SPIKE_DEGC]
        if far.size:
            self._count += far.size
            self._named += [int(r) for r in self._rows[far[: max(SPIKE_ROWS_NAMED - len(self._named), 0)]]]
            self._worst = max(self._worst, float(distance.max()))
        keep = max(stop - h, 0)  # the samples the window of the first not yet judged reaches back to
        self._t, self._rows = self._t[keep:], self._rows[keep:]
        self._judged = stop - keep
        self._at_start = self._at_start and keep == 0


__all__ = ["SPIKE_ROWS_NAMED", "SampleCheck", "SampleFacts", "TEMPERATURE_SPIKE_DEGC", "TEMPERATURE_SPIKE_SAMPLES"]
