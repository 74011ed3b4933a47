"""The accelerometer's fit: temperature models of its axes (each static segment a piece of its own when a run
turns the unit), then bias, scale factor and misalignment from still poses where the runs turn every axis."""

from __future__ import annotations

import dataclasses

from ..calibration import Calibration
from ..calibration.compensate import apply
from ..errors import InputError
from ..fitting.provenance import provenance
from ..motion.positions import orientations
from ..recording import ACCEL_AXES, Recording
from ..runs.prepared import PreparedRun, prepare
from ..threads import single_threaded_blas
from .joint import checked_options, fit_joint
from .options import FitOptions
from .triads import fit_accel_triad, spanning_poses


def _accelerometer_pieces(recordings: list[PreparedRun], min_static_s: float) -> tuple[list[PreparedRun], tuple, bool]:
    """Each run prepared to model its accelerometer against temperature (``channel="accel"``): the whole run when
    it stays in one orientation, else each static segment on its own (its own constant absorbs its gravity
    projection). Also gives the run each piece comes from (its validation fold), and whether some run was split."""
    pieces, folds, split = [], [], False
    for run, rec in enumerate(recordings):
        if rec.accel_g is None or not set(ACCEL_AXES) <= set(rec.accel_axes):
            raise InputError(f"{rec.source}: channels=accel needs accel_x, accel_y and accel_z columns [g]")
        if rec.temperature_degc is None:
            raise InputError(f"{rec.source}: no temperature column; an accelerometer temperature model needs one")
        accel = PreparedRun.of(rec, "accel")
        segments = accel.static_segments(min_duration_s=min_static_s)
        if len(orientations(segments)) > 1:
            pieces += [accel.take(slice(seg.start, seg.stop)) for seg in segments]
            folds += [run] * len(segments)
            split = True
        else:
            pieces.append(accel)
            folds.append(run)
    return pieces, tuple(folds), split


@single_threaded_blas
def fit_accelerometer(recordings: list[Recording], options: FitOptions | None = None) -> Calibration:
    """Temperature models of the accelerometer axes (polynomial or network, lag and hysteresis as for the
    gyro), with a constant per run, or per static segment when a run turns the unit.

    Returns a calibration with only ``accel_axes``; its correction is relative to the middle of the
    calibrated temperature range (``accel_reference_degc``), since at rest the accelerometer's constant
    cannot be told from gravity. ``options`` (:class:`gyrocomp.models.options.FitOptions`, default
    ``FitOptions()``): its temperature model, lag and hysteresis, bin width and shortest static segment; its
    g-sensitivity and folds are the gyro's and not used here. When a run turns the unit, its static segments are
    fitted as separate pieces, and lag and hysteresis (which need each piece's whole temperature history, and a
    validation over dozens of short pieces) are left out unless asked for by name.
    """
    return accelerometer_models(prepare(recordings), checked_options(options))


def accelerometer_models(recordings: list[PreparedRun], options: FitOptions) -> Calibration:
    """:func:`fit_accelerometer` on runs prepared once, with checked options."""
    if options.temperature is None:
        raise InputError(
            "channels=accel: the accelerometer model is a temperature model; "
            "temperature=None leaves nothing to fit (use a polynomial or a network)"
        )
    pieces, folds, split = _accelerometer_pieces(recordings, options.static_min_duration_s)
    fitted = fit_joint(
        pieces,
        dataclasses.replace(
            options,
            hysteresis="none" if split and options.hysteresis == "auto" else options.hysteresis,
            acceleration="none",
            run_folds=folds,
            folds="auto",
        ),
    )
    if fitted.accel_reference_degc is None:
        raise InputError(
            "channels=accel: no temperature model of the accelerometer generalizes across these runs "
            "(every axis is left a constant); their temperatures do not span enough to fit one"
        )
    return dataclasses.replace(
        fitted,
        model=f"accel {fitted.model}",
        provenance=provenance(recordings),
        fit_report={"accel": {**fitted.fit_report, "pieces": len(pieces)}},
    )


def fit_accel_channel(recordings: list[PreparedRun], options: FitOptions) -> Calibration:
    """The accelerometer: temperature models where the runs have a temperature, then bias, scale and
    misalignment from the still poses (of the temperature-compensated accelerations) where the runs turn every
    axis up and down."""
    with_temperature = all(r.temperature_degc is not None for r in recordings)
    accel_cal = None
    if with_temperature:
        try:
            accel_cal = accelerometer_models(recordings, options)
        except InputError:
            if spanning_poses(recordings) is None:  # a multi-position session at one temperature: the triad alone
                raise
        if accel_cal is not None:
            recordings = [dataclasses.replace(rec, accel_g=apply(accel_cal, rec).accel_g) for rec in recordings]
    poses = spanning_poses(recordings)
    if poses is None:
        if accel_cal is None:
            raise InputError(
                "channels=accel: the runs have no temperature (for a temperature model) and do not turn "
                "every accelerometer axis up and down (for a multi-position calibration)"
            )
        return accel_cal
    fit, accel_cal = fit_accel_triad(poses, accel_cal)
    report = {
        "accel_triad": {
            "method": fit.calibration.method,
            "poses": len(poses),
            "norm_rms_before_g": fit.norm_rms_error_before_g,
            "norm_rms_after_g": fit.norm_rms_error_g,
            "degrees_of_freedom": fit.degrees_of_freedom,
            "temperature_order": fit.calibration.temperature_order,
        }
    }
    if accel_cal is None:
        return Calibration(
            axes={},
            model=f"accel {fit.calibration.method}",
            provenance=provenance(recordings),
            fit_report=report,
            accel_triad=fit.calibration,
        )
    return dataclasses.replace(
        accel_cal,
        model=f"{accel_cal.model} + {fit.calibration.method}",
        fit_report={**accel_cal.fit_report, **report},
        accel_triad=fit.calibration,
    )


__all__ = ["accelerometer_models", "fit_accel_channel", "fit_accelerometer"]
