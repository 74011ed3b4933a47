"""Fields of records that lie at byte offsets of one buffer, read and written for all the records at once.

Serialized messages of one layout hold each field at the same offset from their start. A topic's messages in a bag
chunk mostly follow each other at one stride (one record length), broken where another topic's message lies between
them (a temperature at 1 Hz among IMU messages at 1 kHz). :class:`Places` splits the records' offsets into runs of
one stride and reads a field of each run as one strided view of the buffer, copied once; records that do not fall
into a few runs are gathered offset by offset. Both ways give the same values (tests compare them); the runs avoid
a gather per field, most of the time of decoding a chunk of small messages.
"""

from __future__ import annotations

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

#: the offsets are gathered one by one where they form more runs of one stride than this, or one per this many
_MOST_RUNS = 64


class Places:
    """Where records start in a buffer, for reading or writing a field of every record at once.

    Parameters
    ----------
    data : array of uint8, 1-D
        The buffer (a bag chunk's bytes, say); writable where :meth:`write` is used.
    at : array of int
        Where each record starts in ``data`` [bytes], in any order.
    """

    def __init__(self, data: np.ndarray, at: np.ndarray):
        self.data = data
        self.at = np.asarray(at, dtype=np.int64)
        n = self.at.size
        self._span = (int(self.at.min()), int(self.at.max())) if n else (0, 0)
        self.stride = 0
        self.runs: list[tuple[int, int]] | None = [(0, n)] if n else []
        if n > 1:
            step = np.diff(self.at)
            self.stride = int(step[step.size // 2])  # the usual step; any choice reads the same values
            ends = np.flatnonzero(step != self.stride)
            if self.stride <= 0 or ends.size >= max(_MOST_RUNS, n // _MOST_RUNS):
                self.runs = None
            else:
                bounds = [0, *(ends + 1).tolist(), n]
                self.runs = list(zip(bounds[:-1], bounds[1:]))

    def _checked(self, shift: int, width: int) -> None:
        """A ValueError unless the field ``width`` bytes long at ``shift`` from each record lies in the buffer."""
        if self.at.size and (self._span[0] + shift < 0 or self._span[1] + shift + width > self.data.size):
            raise ValueError(f"a field of {width} bytes at {shift} from a record's start lies outside the buffer")

    def _views(self, shift: int, dtype: np.dtype, count: int) -> list[np.ndarray]:
        """Each run's field as a strided view of the buffer (n_run, count)."""
        return [
            np.ndarray(
                (stop - start, count),
                dtype=dtype,
                buffer=self.data,
                offset=int(self.at[start]) + shift,
                strides=(self.stride, dtype.itemsize),
            )
            for start, stop in self.runs
        ]

    def read(self, shift: int, dtype, count: int = 1) -> np.ndarray:
        """The field of ``count`` values of ``dtype`` at ``shift`` [bytes] from each record's start, a copy: shape
        (n,) for one value, else (n, count); a ValueError where a field lies outside the buffer."""
        dtype = np.dtype(dtype)
        width = dtype.itemsize * count
        self._checked(shift, width)
        if self.runs is None:
            values = sliding_window_view(self.data, width)[self.at + shift].view(dtype)
        elif len(self.runs) == 1:
            values = self._views(shift, dtype, count)[0].copy()
        else:
            values = np.concatenate(self._views(shift, dtype, count)) if self.runs else np.empty((0, count), dtype)
        return values[:, 0] if count == 1 else values.reshape(-1, count)

    def write(self, shift: int, values: np.ndarray, rows: np.ndarray | None = None) -> None:
        """Write ``values`` (n, count), each record's (or those of ``rows``, in order), at ``shift`` [bytes] from
        each record's start; their dtype is the field's."""
        values = np.asarray(values)
        count = values.shape[1]
        self._checked(shift, values.dtype.itemsize * count)
        if rows is None and self.runs is not None:
            for view, (start, stop) in zip(self._views(shift, values.dtype, count), self.runs):
                view[...] = values[start:stop]
            return
        at = self.at if rows is None else self.at[rows]
        if at.size == 0:
            return
        raw = np.ascontiguousarray(values).view(np.uint8).reshape(at.size, -1)
        sliding_window_view(self.data, raw.shape[1], writeable=True)[at + shift] = raw


def among(values: np.ndarray, ids) -> np.ndarray:
    """Whether each of ``values`` is one of ``ids`` (a few connection ids, say): :func:`numpy.isin`, without its
    sorting for a handful of ids."""
    ids = list(ids)
    if len(ids) > 8:
        return np.isin(values, np.asarray(ids, dtype=np.int64))
    found = np.zeros(np.shape(values), dtype=bool)
    for value in ids:
        found |= values == value
    return found


__all__ = ["Places", "among"]
