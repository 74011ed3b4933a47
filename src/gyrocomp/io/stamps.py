"""Time stamps held as integers (a bag's ``sec`` and ``nanosec``, a table's column of ns, us or ms since an epoch)
as seconds [s], by one formula, so that the same instants read from any format give the same float64 values.

A float64 near 1.7e9 s (the Unix epoch now) keeps about 0.24 us, and one of integer nanoseconds at that epoch
(1.7e18) keeps only 256 ns: ``ticks * 1e-9`` rounds twice. The whole seconds and the rest are taken apart in
integers first, then joined once:

    t = float(sec) + float(nsec) * 1e-9,

which is exactly what a bag's header stamp gives, whatever unit the integers came in.
"""

from __future__ import annotations

import numpy as np

#: the ticks per second of the integer time units read exactly (:func:`ticks_s`)
TICKS_PER_SECOND = {"s": 1, "ms": 1_000, "us": 1_000_000, "ns": 1_000_000_000}


def stamp_s(sec, nanosec):
    """Seconds [s] of stamps given as whole seconds and nanoseconds (arrays or numbers): ``sec + nanosec 1e-9``,
    each converted to float64 once."""
    return np.asarray(sec).astype(float) + np.asarray(nanosec).astype(float) * 1e-9


def ticks_s(ticks: np.ndarray, per_second: int) -> np.ndarray:
    """Seconds [s] of integer stamps, ``per_second`` ticks a second (1000 for ms, 10**9 for ns; a whole number
    dividing 10**9): the whole seconds and the rest split in integers, then :func:`stamp_s`."""
    whole, rest = np.divmod(np.asarray(ticks, dtype=np.int64), per_second)
    return stamp_s(whole, rest * (1_000_000_000 // per_second))


__all__ = ["TICKS_PER_SECOND", "stamp_s", "ticks_s"]
