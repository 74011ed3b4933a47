"""Stillness detection of the online learner: block statistics, quantiles as the C code takes them, and the
temperature dequantizer's state (steps 1-4 of :mod:`gyrocomp.fitting.online`)."""

from __future__ import annotations

import math

import numpy as np


def c_quantile(values: np.ndarray, q: float) -> np.ndarray:
    """Column quantiles by linear interpolation between order statistics (as the C code computes them)."""
    s = np.sort(values, axis=0)
    pos = q * (s.shape[0] - 1)
    low = int(math.floor(pos))
    if low + 1 >= s.shape[0]:
        return s[low]
    return s[low] + (pos - low) * (s[low + 1] - s[low])


def block_statistics(blocks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Means and detrended variances of blocks (n, m, c) over their m samples (see the module, step 1)."""
    m = blocks.shape[1]
    x = np.ascontiguousarray(np.transpose(blocks, (0, 2, 1)))  # (n, c, m): each sum runs over a contiguous row
    d = x - x[:, :, :1]
    i = np.arange(m) - (m - 1) / 2.0
    s1 = d.sum(axis=2)
    s2 = (d * d).sum(axis=2)
    si = (d * i).sum(axis=2)
    i2 = m * (m * m - 1) / 12.0
    mean = x[:, :, 0] + s1 / m
    var = np.maximum(s2 - s1 * s1 / m - si * si / i2, 0.0) / (m - 2)
    return mean, var


def fresh_dequantizer() -> dict:
    """The dequantizer's state: the last reading, the last crossing [degC], its time [s], the rate [degC/s] and
    half the step there [degC] (None/0: none yet)."""
    return {"previous": None, "crossing": None, "time": 0.0, "rate": 0.0, "half": 0.0}


__all__ = ["block_statistics", "c_quantile", "fresh_dequantizer"]
