"""Faults a real calibration run suffers, injected into a simulated run's table: the corpus the data check
(:mod:`gyrocomp.measures.data_check`) is measured on, and a way to test one's own pipeline against bad data.

A run is its table's columns as arrays (``time`` [s], ``gyro_x/y/z`` [deg/s], ``accel_x/y/z`` [g],
``temperature`` [degC]: the canonical table); :func:`inject` returns the columns of the faulty run. Each fault
is named by the data check that should find it (:data:`FAULTS`).
"""

from __future__ import annotations

import math

import numpy as np

#: fault -> the data check that should name it
FAULTS: dict[str, str] = {
    "temperature-missing": "temperature-missing",  # no temperature column
    "temperature-constant": "temperature-constant",  # a stuck sensor: its first value throughout
    "temperature-span": "temperature-span",  # a chamber that barely moved: 0.5 degC in all
    "temperature-quantized": "temperature-quantized",  # whole degrees
    "gaps": "gaps",  # 5 % of the samples lost in four stretches
    "rail": "rail",  # three knocks beyond a 250 deg/s range, clipped there
    "motion": "motion",  # the unit picked up and turned for a minute (20..60 deg/s)
    "time-back": "time",  # two logs appended: the clock restarts half way
    "time-repeat": "time",  # 1 % of the rows written twice
    "rad-as-deg": "unit",  # rad/s data read as deg/s
    "deg-as-rad": "unit",  # deg/s data read as rad/s (converted once more)
    "too-short": "too-short",  # the log stopped after 15 samples
    "no-reversal": "reversal",  # a monotonic run, with turning-point hysteresis asked
}
#: the range the rail fault clips at [deg/s]
RAIL_DPS = 250.0
GYRO = ("gyro_x", "gyro_y", "gyro_z")


def inject(columns: dict[str, np.ndarray], fault: str, rng: np.random.Generator) -> dict[str, np.ndarray]:
    """The columns of a run with ``fault`` (a key of :data:`FAULTS`; ``no-reversal`` changes nothing: it is a
    monotonic run checked with hysteresis asked). ``rng`` places the fault."""
    if fault not in FAULTS:
        raise ValueError(f"fault: {fault!r}; use one of {', '.join(FAULTS)}")
    out = {k: np.array(v, dtype=float, copy=True) for k, v in columns.items()}
    n = out["time"].size
    gyro = [k for k in GYRO if k in out]
    if fault == "temperature-missing":
        out.pop("temperature")
    elif fault == "temperature-constant":
        out["temperature"][:] = out["temperature"][0]
    elif fault == "temperature-span":
        t = out["temperature"]
        out["temperature"] = t[0] + 0.5 * (t - t.min()) / max(float(np.ptp(t)), 1e-9)
    elif fault == "temperature-quantized":
        out["temperature"] = np.round(out["temperature"])
    elif fault == "gaps":
        keep = np.ones(n, dtype=bool)
        for start in rng.choice(np.arange(n // 10, n - n // 10), 4, replace=False):
            keep[start : start + n // 80] = False
        out = {k: v[keep] for k, v in out.items()}
    elif fault == "rail":
        rate_hz = 1.0 / float(np.median(np.diff(out["time"])))
        width = max(3, int(2 * rate_hz))
        for start in rng.choice(np.arange(n // 10, n - n // 10), 3, replace=False):
            axis = gyro[int(rng.integers(len(gyro)))]
            out[axis][start : start + width] += rng.choice([-1.0, 1.0]) * 400.0
        for axis in gyro:
            np.clip(out[axis], -RAIL_DPS, RAIL_DPS, out=out[axis])
    elif fault == "motion":
        rate_hz = 1.0 / float(np.median(np.diff(out["time"])))
        width = max(2, int(60 * rate_hz))
        start = int(rng.integers(n // 10, max(n // 10 + 1, n - width - n // 10)))
        axis = gyro[int(rng.integers(len(gyro)))]
        phase = np.arange(min(width, n - start)) / max(width, 1)
        out[axis][start : start + width] += rng.uniform(20.0, 60.0) * np.sin(2 * math.pi * 3 * phase)
    elif fault == "time-back":
        half = n // 2
        out["time"][half:] -= out["time"][half] - out["time"][0]
    elif fault == "time-repeat":
        rows = np.sort(rng.choice(n, max(1, n // 100), replace=False))
        index = np.sort(np.concatenate([np.arange(n), rows]))
        out = {k: v[index] for k, v in out.items()}
    elif fault == "rad-as-deg":
        for axis in gyro:
            out[axis] *= math.pi / 180.0
    elif fault == "deg-as-rad":
        for axis in gyro:
            out[axis] *= 180.0 / math.pi
    elif fault == "too-short":
        out = {k: v[:15] for k, v in out.items()}
    return out


__all__ = ["FAULTS", "RAIL_DPS", "inject"]
