"""Helpers every model shares: temperature binning, the per-run turn-on constants, provenance (block means:
:mod:`gyrocomp.runs.prepared`)."""

from __future__ import annotations

import datetime as _dt
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._version import __version__
from ..errors import InputError, NotFittedError
from ..io import TIME_RANGE_KEY, file_sha256
from ..runs.prepared import fit_axes
from ..recording import Recording


class LearnedAttributes:
    """Base of the estimators (scikit-learn style): reading a learned attribute (a name ending in ``_``, set by
    the fit) before the fit raises :class:`~gyrocomp.errors.NotFittedError` naming the estimator and the call that
    fits it (``FIT_CALL``). Other missing attributes are an ordinary AttributeError (``hasattr`` works)."""

    #: how the estimator is fitted, as the error tells the user
    FIT_CALL = "fit(recordings)"

    def __getattr__(self, name: str):
        if name.endswith("_") and not name.startswith("_"):
            raise NotFittedError(
                f"{type(self).__name__} is not fitted yet; call {self.FIT_CALL} first ({name} is learned by the fit)"
            )
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")


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


def one_temperature_column(recordings: list[Recording]) -> bool:
    """Whether every recording reads one temperature for all the axes a fit models (one sensor, so one die and one
    lag): one column, or the accelerometer's axes (which all read the mean of the gyro's columns)."""
    return all(
        rec.temperature_degc is None or len({rec.temperature_column_for(a) for a in fit_axes([rec])}) == 1
        for rec in recordings
    )


def provenance(recordings) -> dict:
    """Where a calibration came from: gyrocomp's version, the time, and each input (name, rows, duration,
    rate, SHA-256 of the file when it is on disk, the gyro's and accelerometer's device ids when the log names
    them)."""
    inputs = []
    for rec in recordings:
        entry = {
            "file": Path(rec.source).name,
            "rows": rec.n_samples,
            "duration_s": rec.duration_s,
            "rate_hz": rec.rate_hz,
        }
        path = rec.metadata.get("path")
        if path and Path(path).is_file():
            entry["sha256"] = file_sha256(path)
        window = rec.metadata.get(TIME_RANGE_KEY)
        if window is not None:  # the rows fitted: only this window of the file (--time), [A, B) s from its start
            entry["time_range_s"] = [None if v is None else float(v) for v in window]
        for key in ("device_id", "accel_device_id"):  # the sensor's id in its autopilot (a ULog's sensor_gyro)
            if isinstance(rec.metadata.get(key), int):
                entry[key] = rec.metadata[key]
        inputs.append(entry)
    return {
        "gyrocomp_version": __version__,
        "created_utc": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "inputs": inputs,
    }
