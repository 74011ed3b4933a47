"""The PX4-style temperature calibration a user writes by hand, the baseline of ``bench_fit_protocol.py``: read each
CSV with pandas, median-filter the gyro (31 samples, as PX4's offline scripts smooth the logs), average into 2000
temperature bins, and fit one cubic in temperature with one constant per run by least squares.

Usage: python benchmarks/px4_style_fit.py RUN.csv [RUN.csv ...]
"""

from __future__ import annotations

import sys

import numpy as np
import pandas as pd
from scipy.signal import medfilt

AXES = ("gyro_x", "gyro_y", "gyro_z")
BINS = 2000


def main(paths: list[str]) -> None:
    frames = [pd.read_csv(p) for p in paths]
    temps = np.concatenate([f["temperature_degc"].to_numpy() for f in frames])
    edges = np.linspace(temps.min(), temps.max(), BINS + 1)
    t_mid = 0.5 * (temps.min() + temps.max())
    rows, values = [], {axis: [] for axis in AXES}
    for r, frame in enumerate(frames):
        temp = frame["temperature_degc"].to_numpy()
        which = np.clip(np.digitize(temp, edges) - 1, 0, BINS - 1)
        counts = np.bincount(which, minlength=BINS)
        keep = counts > 0
        t_bin = np.bincount(which, temp, minlength=BINS)[keep] / counts[keep]
        onehot = np.zeros((t_bin.size, len(frames)))
        onehot[:, r] = 1.0
        rows.append(np.hstack([onehot, (t_bin[:, None] - t_mid) ** np.arange(1, 4)]))
        for axis in AXES:
            smooth = medfilt(frame[axis].to_numpy(), 31)
            values[axis].append(np.bincount(which, smooth, minlength=BINS)[keep] / counts[keep])
    x = np.vstack(rows)
    for axis in AXES:
        coef, *_ = np.linalg.lstsq(x, np.concatenate(values[axis]), rcond=None)
        print(axis, " ".join(f"{c:.6g}" for c in coef[len(frames) :]))


if __name__ == "__main__":
    main(sys.argv[1:])
