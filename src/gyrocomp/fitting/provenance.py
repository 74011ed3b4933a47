"""Where a calibration came from: gyrocomp's version, the time, each input and its hash."""

from __future__ import annotations


import datetime as _dt
from pathlib import Path


from .._version import __version__
from ..io import TIME_RANGE_KEY, file_sha256


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
