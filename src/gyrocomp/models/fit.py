"""The one way to fit: :func:`fit` (``gyrocomp.fit``), calibration runs and typed options in, a frozen
:class:`~gyrocomp.calibration.Calibration` out. It prepares the runs once (:func:`gyrocomp.runs.prepared.prepare`)
and checks the options once, then fits the gyro's scale factor (:mod:`.triads`), the accelerometer
(:mod:`.accelerometer`) and the gyro's pipeline (:mod:`.pipelines`, the joint fit in :mod:`.joint`) on them.

The other entry points are the same path with their arguments in other forms, kept for the calls written
against them: :func:`fit_channels` (this function's arguments in another order),
:func:`~gyrocomp.models.pipelines.fit_pipeline` (one channel, no scale factor) and
:func:`~gyrocomp.models.joint.fit_calibration` (the joint fit, options as keywords).
"""

from __future__ import annotations

import dataclasses

from ..calibration import Calibration
from ..calibration.compensate import apply
from ..errors import InputError
from ..recording import Recording
from ..runs.prepared import CHANNELS, Channel, prepare
from ..threads import single_threaded_blas
from .accelerometer import fit_accel_channel
from .joint import checked_options
from .options import FitOptions
from .pipelines import Pipeline, run_pipeline
from .triads import ScaleFactor, fit_gyro_triad


def check_channels(channels: tuple[Channel, ...]) -> tuple[Channel, ...]:
    """The channels a fit models (a tuple of ``"gyro"`` and/or ``"accel"``), checked, in that order."""
    if not isinstance(channels, (tuple, list)) or not channels:
        raise InputError(f"channels: a tuple of 'gyro' and/or 'accel', e.g. ('gyro', 'accel'); got {channels!r}")
    unknown = [c for c in channels if c not in CHANNELS]
    if unknown:
        raise InputError(f"channels: {', '.join(map(repr, unknown))}: use 'gyro', 'accel' or both")
    return tuple(c for c in CHANNELS if c in channels)


@single_threaded_blas
def fit(
    runs: list[Recording] | Recording,
    options: FitOptions | None = None,
    *,
    channels: tuple[Channel, ...] = ("gyro",),
    pipeline: Pipeline = "joint",
    scale_factor: ScaleFactor = "auto",
) -> Calibration:
    """Fit a compensation on calibration runs.

    Parameters
    ----------
    runs : list of Recording, or one
        Calibration runs, each one power-on (its own turn-on constant) [deg/s, g, degC, s].
    options : FitOptions, optional
        What to fit and how to choose (:class:`gyrocomp.models.options.FitOptions`; default ``FitOptions()``:
        every candidate the data can identify, chosen by held-out drift).
    channels : tuple of {"gyro", "accel"}
        What is modelled: the gyro (default), the accelerometer, or both (the accelerometer first, the gyro's
        g-sensitivity then reading its compensated accelerations).
    pipeline : {"joint", "poly>matrix", "matrix>poly", "mlp>matrix", "mlp>mlp-accel", "joint-mlp"}
        How the gyro's stages are fitted: together (``joint``, the default) or in the thesis's cascades
        (:func:`gyrocomp.models.pipelines.fit_pipeline`).
    scale_factor : {"auto", "none", "matrix", "matrix-temperature"}
        The gyro's scale factor and misalignment K(T), from rate-table runs or turns between still poses.

    Notes
    -----
    The accelerometer gets temperature models (``fit_accelerometer``) when the runs have a temperature, and
    bias, scale factor and misalignment (``fit_accel_multiposition``) when they turn its every axis up and
    down. With both channels the accelerometer is modelled first and the gyro's g-sensitivity stage is fitted
    on the temperature-compensated accelerations (the same ones the compensation will feed it).

    ``scale_factor``: runs that carry a rate table's reference rates (``reference_rate_dps``) give the gyro's
    scale factor and misalignment K(T) (:func:`fit_gyro_rate_table`) and the other runs the bias model;
    without them, multi-position sessions whose turns between still poses are recorded give K(T)
    (:func:`fit_gyro_between_poses`; they stay bias runs too). ``"auto"`` when such runs are given (a warning
    when their turns do not determine K), the order by leave-one-run-out; ``"matrix"`` K constant,
    ``"matrix-temperature"`` K linear in temperature, ``"none"`` no K (every run is then a bias run).

    Examples
    --------
    >>> model = gyrocomp.fit(runs)                                                # doctest: +SKIP
    >>> model = gyrocomp.fit(runs, FitOptions(hysteresis="none"), channels=("gyro", "accel"))  # doctest: +SKIP
    """
    recordings = prepare([runs] if isinstance(runs, Recording) else runs)
    channels = check_channels(channels)
    options = checked_options(options)
    gyro_triad, recordings = (
        fit_gyro_triad(recordings, scale_factor, options.temperature is not None)
        if "gyro" in channels
        else (None, recordings)
    )
    if "accel" not in channels:
        return dataclasses.replace(run_pipeline(recordings, pipeline, options), gyro_triad=gyro_triad)
    accel_cal = fit_accel_channel(recordings, options)
    if "gyro" not in channels:
        return accel_cal
    gyro_cal = run_pipeline(_accel_compensated(recordings, accel_cal), pipeline, options)
    return _combined(gyro_cal, accel_cal, gyro_triad)


def _accel_compensated(recordings: list[Recording], accel_cal: Calibration) -> list[Recording]:
    """The runs with their accelerations [g] temperature-compensated (as the compensation will feed the gyro's
    g-sensitivity stage)."""
    if not accel_cal.accel_axes:
        return recordings
    return [dataclasses.replace(rec, accel_g=apply(accel_cal.without_accel_triad(), rec).accel_g) for rec in recordings]


def _combined(gyro_cal: Calibration, accel_cal: Calibration, gyro_triad) -> Calibration:
    """The gyro's calibration with the accelerometer's models and the gyro's triad."""
    return dataclasses.replace(
        gyro_cal,
        model=f"{gyro_cal.model}; {accel_cal.model}",
        fit_report={**gyro_cal.fit_report, **accel_cal.fit_report},
        accel_axes=accel_cal.accel_axes,
        accel_reference_degc=accel_cal.accel_reference_degc,
        gyro_triad=gyro_triad,
        accel_triad=accel_cal.accel_triad,
    )


def fit_channels(
    recordings: list[Recording] | Recording,
    channels: tuple[Channel, ...] = ("gyro",),
    pipeline: Pipeline = "joint",
    *,
    scale_factor: ScaleFactor = "auto",
    options: FitOptions | None = None,
) -> Calibration:
    """:func:`fit` with its arguments in another order (release 0.1's form)."""
    return fit(recordings, options, channels=channels, pipeline=pipeline, scale_factor=scale_factor)


__all__ = ["check_channels", "fit", "fit_channels"]
