"""Phases of rate data that arrives in chunks of unknown number, in one pass and bounded memory.

:func:`gyrocomp.allan.phase_from_chunks` reads its chunks twice (the mean first); a file read once, as
``gyrocomp allan`` and ``gyrocomp evaluate`` read theirs, cannot be. :class:`PhaseAccumulator` integrates each
column about the first chunk's mean m0 as the chunks come,

    S[0] = 0,  S[k] = sum_{i<k} (y[i] - m0),

into a :class:`gyrocomp.spilled_series.SpillArray` (memory, or a temporary file past a limit), and :meth:`finish` turns
the sums into the phase of the mean-removed rate, as :func:`gyrocomp.allan.to_phase` gives it,

    x[k] = (S[k] - k (mean - m0)) / rate_hz  [unit*s],  mean - m0 = S[N] / N,

in one more pass over the stored sums (equal to ``to_phase`` to rounding: the sums are about m0 instead of the
mean). Any chunking gives the same phase.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..spilled_series import DEFAULT_MEMORY_BYTES, SpillArray

_BLOCK = 1 << 20


class PhaseAccumulator:
    """Running sums of ``columns`` rate columns, turned into their phases at the end (see the module).

    Parameters
    ----------
    columns : int
        Number of rate columns in each chunk.
    memory_bytes : int
        What the sums of each column may hold in memory [bytes] before they go to a temporary file.
    directory : path, optional
        Where the temporary files go.
    """

    def __init__(self, columns: int, *, memory_bytes: int = DEFAULT_MEMORY_BYTES, directory=None):
        if int(columns) != columns or columns < 1:
            raise InputError(f"columns: a whole number >= 1, got {columns!r}")
        self.columns = int(columns)
        self._sums = [SpillArray(memory_bytes, directory) for _ in range(self.columns)]
        for sums in self._sums:
            sums.append([0.0])
        self._origin: np.ndarray | None = None  # m0, the first chunk's mean of each column
        self._carry = np.zeros(self.columns)
        self.n_samples = 0
        self._phases: list[np.ndarray] | None = None

    def __enter__(self) -> "PhaseAccumulator":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def update(self, rate) -> None:
        """Add a chunk of rate samples, shape (n, columns) [unit]."""
        if self._phases is not None:
            raise InputError("rate: the phases are finished; no more samples can be added")
        block = np.asarray(rate, dtype=np.float64)
        if block.ndim != 2 or block.shape[1] != self.columns:
            raise InputError(f"rate: expected shape (n, {self.columns}), got {block.shape}")
        if not block.shape[0]:
            return
        if self._origin is None:
            self._origin = block.mean(axis=0)
        running = np.cumsum(block - self._origin, axis=0)
        running += self._carry
        self._carry = running[-1].copy()
        for j, sums in enumerate(self._sums):
            sums.append(running[:, j])
        self.n_samples += block.shape[0]

    @property
    def mean(self) -> np.ndarray:
        """The mean of each column so far [unit]."""
        if self._origin is None:
            raise InputError("rate: no samples yet")
        return self._origin + self._carry / self.n_samples

    def finish(self, rate_hz: float) -> list[np.ndarray]:
        """The phase of each column [unit*s], N+1 points (arrays or memory-mapped files, valid until
        :meth:`close`)."""
        if self._phases is not None:
            return self._phases
        if not rate_hz > 0:
            raise InputError(f"rate_hz: must be positive, got {rate_hz}")
        if self.n_samples < 2:
            raise InputError(f"rate: need at least 2 samples, got {self.n_samples}")
        slopes = self._carry / self.n_samples  # mean - m0
        self._phases = []
        for j, sums in enumerate(self._sums):
            phase = sums.finish()
            for start in range(0, phase.size, _BLOCK):
                piece = phase[start : start + _BLOCK]
                piece -= np.arange(start, start + piece.size, dtype=np.float64) * slopes[j]
                piece /= rate_hz
            self._phases.append(phase)
        return self._phases

    def close(self) -> None:
        """Remove the temporary files."""
        self._phases = None
        for sums in self._sums:
            sums.close()
