"""Replaying recorded logs through the online learner, one session each."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from ...errors import InputError
from ...recording import Recording
from .settings import GYRO_AXES, ReplayedLog
from .calibrator import OnlineCalibrator

#: a log whose sample rate differs from the learner's by more than this fraction is refused
RATE_TOLERANCE = 0.1


def replay(
    learner: OnlineCalibrator, recordings: Iterable[Recording], *, chunk_samples: int = 65536
) -> list[ReplayedLog]:
    """Feed ``recordings`` to ``learner``, each one power-on (a session), in chunks of ``chunk_samples`` (any
    chunking gives the same model); what each gave. Raises :class:`InputError` for a log without temperature,
    without gyro_x, gyro_y and gyro_z, or at a rate the learner was not set up for."""
    out = []
    for rec in recordings:
        if rec.temperature_degc is None:
            raise InputError(f"{rec.source}: no temperature; the learner learns the bias against temperature")
        if not any(a in rec.gyro_axes for a in GYRO_AXES):
            raise InputError(f"{rec.source}: none of {', '.join(GYRO_AXES)}; the learner learns those axes")
        rate = learner.settings.rate_hz
        if abs(rec.rate_hz - rate) > RATE_TOLERANCE * rate:
            raise InputError(
                f"{rec.source}: sampled at {rec.rate_hz:.4g} Hz; the learner was set up for {rate:.4g} Hz "
                "(rate_hz): its blocks and gaps count samples at that rate"
            )
        gyro = np.zeros((rec.n_samples, 3))  # an axis the log lacks reads 0: no noise, never tested, learns 0
        for j, axis in enumerate(GYRO_AXES):
            if axis in rec.gyro_axes:
                gyro[:, j] = rec.gyro_dps[:, rec.gyro_axes.index(axis)]
        temperature = np.asarray(rec.temperature_degc, dtype=float)
        before = learner.status
        learner.start_session()
        for start in range(0, rec.n_samples, chunk_samples):
            part = slice(start, start + chunk_samples)
            learner.update(
                rec.time_s[part], gyro[part], None if rec.accel_g is None else rec.accel_g[part], temperature[part]
            )
        learner.end_session()
        after = learner.status
        out.append(
            ReplayedLog(
                rec.source,
                tuple(a for a in GYRO_AXES if a in rec.gyro_axes),
                rec.duration_s,
                after.still_s - before.still_s,
                after.rejected_bound + after.rejected_outliers - before.rejected_bound - before.rejected_outliers,
                float(np.nanmin(temperature)),
                float(np.nanmax(temperature)),
            )
        )
    return out


__all__ = ["RATE_TOLERANCE", "replay"]
