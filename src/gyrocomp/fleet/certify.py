"""What a unit's certificate needs besides its row: the held-out residual of its runs, read again from the
paths the row names and checked against their recorded SHA-256 (a run changed since the calibration is refused)."""

from __future__ import annotations

from ..errors import InputError
from ..evaluation.held_out import HeldOut, held_out_residuals
from ..io import ReadOptions, read_input
from .devices import content_hash
from .store import CalibrationRecord


def held_out_of(record: CalibrationRecord, read: ReadOptions | None = None, fmt: str | None = None) -> HeldOut:
    """The held-out residual and band of the calibration ``record`` (gyrocomp's default fit on its runs, as a
    fleet fit makes it); its runs must still be where the row says, with the content they had."""
    for run in record.inputs:
        try:
            digest = content_hash(run.path)
        except OSError as exc:
            raise InputError(
                f"{run.path}: a run of unit {record.serial!r} cannot be read ({exc.strerror or exc}); "
                "the certificate's residual needs the unit's runs"
            ) from None
        if digest != run.sha256:
            raise InputError(
                f"{run.path}: changed since unit {record.serial!r} was calibrated (SHA-256 "
                f"{digest[:12]}..., the store has {run.sha256[:12]}...)"
            )
    recordings = [read_input(run.path, read or ReadOptions(), fmt=fmt).recording for run in record.inputs]
    return held_out_residuals(recordings)


__all__ = ["held_out_of"]
