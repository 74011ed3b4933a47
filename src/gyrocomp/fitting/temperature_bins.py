"""Temperature bins: the width from the calibration's span, and the samples' means per bin."""

from __future__ import annotations


from dataclasses import dataclass

import numpy as np

from ..errors import InputError


#: default number of temperature bins across the span of the calibration data
DEFAULT_BINS_PER_SPAN = 100


@dataclass(frozen=True)
class TemperatureBins:
    """Bin averages of one run: each temperature interval becomes one weighted point.

    Attributes
    ----------
    temperature_degc : array (b,)
        Mean temperature of the samples in each occupied bin [degC].
    value : array (b,)
        Mean of the binned quantity (e.g. gyro output [deg/s]) in each bin.
    count : array (b,) of int
        Samples in each bin.
    run : array (b,) of int
        Index of the run the bin belongs to.
    """

    temperature_degc: np.ndarray
    value: np.ndarray
    count: np.ndarray
    run: np.ndarray

    @property
    def weight(self) -> np.ndarray:
        """Weight of each bin: 1, less for bins holding fewer samples than the median bin.

        Every temperature interval counts equally however long the run stayed in it
        (so a slow heating rate does not dominate), while a bin with a few stray samples
        cannot pull the fit.
        """
        return np.minimum(1.0, self.count / np.median(self.count))


def bin_width_for(temperatures: list[np.ndarray], bin_width_degc: float | None) -> float:
    """The bin width [degC]: as given, or the span of all runs divided by ``DEFAULT_BINS_PER_SPAN``."""
    if bin_width_degc is not None:
        if not bin_width_degc > 0:
            raise InputError(f"bin_width_degc: must be positive, got {bin_width_degc}")
        return float(bin_width_degc)
    lo = min(float(t.min()) for t in temperatures)
    hi = max(float(t.max()) for t in temperatures)
    return max((hi - lo) / DEFAULT_BINS_PER_SPAN, 1e-3)


def bin_by_temperature(
    temperatures: list[np.ndarray], values: list[np.ndarray], width_degc: float, origin_degc: float = 0.0
) -> TemperatureBins:
    """Average ``values`` in temperature bins of ``width_degc``, separately for each run."""
    temps, vals, counts, runs = [], [], [], []
    for r, (t, v) in enumerate(zip(temperatures, values)):
        idx = np.floor((t - origin_degc) / width_degc).astype(np.int64)
        uniq, inverse, count = np.unique(idx, return_inverse=True, return_counts=True)
        temps.append(np.bincount(inverse, weights=t) / count)
        vals.append(np.bincount(inverse, weights=v) / count)
        counts.append(count)
        runs.append(np.full(uniq.size, r))
    return TemperatureBins(np.concatenate(temps), np.concatenate(vals), np.concatenate(counts), np.concatenate(runs))
