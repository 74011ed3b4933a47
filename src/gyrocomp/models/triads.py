"""The triads' part of a fit: the gyro's scale factor and misalignment from rate-table runs or from the turns
between the still poses of a multi-position session, and the accelerometer's from its still poses (with the
temperature models it completes). Used by :func:`gyrocomp.models.fit.fit`."""

from __future__ import annotations

import dataclasses
import warnings
from typing import Literal, get_args

import numpy as np

from ..calibration import Calibration
from ..calibration.triad import TriadCalibration
from ..errors import DataQualityWarning, InputError, user_stacklevel
from ..fitting.pose_rotation import TooFewTurns, fit_gyro_between_poses
from ..fitting.rate_table import MIN_REFERENCE_RATE_DPS, fit_gyro_rate_table
from ..fitting.triad_fit import MIN_TRIAD_SPAN_DEGC, Pose, PoseFit, find_poses, fit_accel_multiposition, spans_axes
from ..recording import ACCEL_AXES, GYRO_AXES, Recording

#: how ``fit_channels`` treats the gyro's scale factor and misalignment
ScaleFactor = Literal["auto", "none", "matrix", "matrix-temperature"]
SCALE_FACTOR_CHOICES: tuple[str, ...] = get_args(ScaleFactor)


def _turning_sessions(recordings: list[Recording]) -> list[Recording]:
    """The runs that are multi-position sessions with the turns between their poses recorded (three gyro and
    three accelerometer axes, still poses turning every accelerometer axis up and down)."""
    out = []
    for rec in recordings:
        if (
            rec.reference_rate_dps is None
            and rec.gyro_axes == GYRO_AXES
            and rec.accel_g is not None
            and set(ACCEL_AXES) <= set(rec.accel_axes)
            and spanning_poses([rec]) is not None
        ):
            out.append(rec)
    return out


def fit_gyro_triad(
    recordings: list[Recording], scale_factor: str, wants_temperature: bool = True
) -> tuple[TriadCalibration | None, list[Recording]]:
    """The gyro's scale factor and misalignment K(T), and the runs left for the bias model.

    From the runs that carry reference rates (a rate table; those runs then leave the bias model), or, without
    them, K from the turns between the still poses of multi-position sessions.

    Parameters
    ----------
    recordings : list of Recording
        The calibration runs [s, deg/s, g, degC].
    scale_factor : {"auto", "none", "matrix", "matrix-temperature"}
        What to fit (``auto``: K where the runs can tell it, ``matrix-temperature``: K and its temperature terms).
    wants_temperature : bool
        Whether K may carry temperature terms (the sessions span temperatures).

    Returns
    -------
    triad : TriadCalibration or None
        None where the runs cannot tell K (or ``scale_factor`` is ``none``).
    runs : list of Recording
        The runs for the bias model.
    """
    if scale_factor not in SCALE_FACTOR_CHOICES:
        raise InputError(f"scale_factor: {scale_factor!r}; use one of {', '.join(SCALE_FACTOR_CHOICES)}")
    if scale_factor == "none":
        return None, recordings
    rate_runs = [r for r in recordings if r.reference_rate_dps is not None]
    if not rate_runs:
        sessions = _turning_sessions(recordings)
        if scale_factor != "auto" and not sessions:
            raise InputError(
                f"scale_factor={scale_factor!r}: no run carries reference rates (ref_rate_x, ref_rate_y, "
                "ref_rate_z [deg/s]) or turns between still poses; a scale-factor calibration needs "
                "rate-table runs or a multi-position session with the turns recorded"
            )
        if not sessions:
            return None, recordings
        order = {"auto": "auto", "matrix": 0, "matrix-temperature": 1}[scale_factor]
        try:
            return fit_gyro_between_poses(sessions, temperature_order=order).calibration, recordings
        except InputError as exc:
            if scale_factor != "auto":
                raise
            if isinstance(exc, TooFewTurns):  # the turns were not recorded: nothing to say
                return None, recordings
            warnings.warn(
                f"scale factor not fitted from the multi-position runs: {exc}",
                DataQualityWarning,
                stacklevel=user_stacklevel(),
            )
            return None, recordings
    rest = [r for r in recordings if r.reference_rate_dps is None]
    order = {"auto": "auto", "matrix": 0, "matrix-temperature": 1}[scale_factor]
    triad = fit_gyro_rate_table(rate_runs, temperature_order=order).calibration
    if not rest:  # rate-table runs alone: their still stretches carry the bias (one constant per run at least)
        rest = _still_stretches(rate_runs)
        if not rest:
            raise InputError(
                "scale_factor: every run is a rate-table run and none holds still between its rates; "
                "the bias needs still stretches or runs at rest"
            )
        if wants_temperature and any(r.temperature_degc is not None and np.ptp(r.temperature_degc) < 5.0 for r in rest):
            warnings.warn(
                "the bias comes from the rate-table runs' still stretches, each held near a single "
                "temperature, so their drift with temperature cannot be told from their turn-on biases (one "
                "constant per run); fit no temperature model, or add runs at rest through a range",
                DataQualityWarning,
                stacklevel=user_stacklevel(),
            )
    return triad, rest


def _still_stretches(rate_runs: list[Recording]) -> list[Recording]:
    """The samples of each rate-table run where the table stands still (every reference rate below
    MIN_REFERENCE_RATE_DPS), as runs at rest for the bias model (their reference rates dropped)."""
    out = []
    for rec in rate_runs:
        still = np.all(np.abs(rec.reference_rate_dps) < MIN_REFERENCE_RATE_DPS, axis=1)
        if np.count_nonzero(still) >= 10:
            out.append(dataclasses.replace(rec.take(still), reference_rate_dps=None))
    return out


def spanning_poses(recordings: list[Recording]) -> list[Pose] | None:
    """The still poses of runs that turn the accelerometer's every axis up and down (a multi-position test).

    Parameters
    ----------
    recordings : list of Recording
        The calibration runs, with accelerometer columns [g].

    Returns
    -------
    list of Pose or None
        Every still pose of those runs, or None when the runs do not turn each axis both ways.
    """
    turned = [
        rec
        for rec in recordings
        if rec.accel_g is not None and set(ACCEL_AXES) <= set(rec.accel_axes) and _reaches_both_ways(rec)
    ]
    poses = [p for rec in turned for p in find_poses(rec)]
    return poses if len(poses) >= 6 and spans_axes(poses) else None


def _reaches_both_ways(recording: Recording) -> bool:
    """Whether some sample has each accelerometer axis beyond +-0.4 g: without it no pose can turn that axis
    within 60 deg of up and of down (half of gravity; 0.4 leaves room for a scale error), and the still-pose
    search (on every run of every fit) is not worth doing."""
    order = [recording.accel_axes.index(a) for a in ACCEL_AXES]  # the columns' extremes: no copy of the samples
    accel = recording.accel_g
    return bool(np.all(accel.max(axis=0)[order] > 0.4) and np.all(accel.min(axis=0)[order] < -0.4))


def fit_accel_triad(poses: list[Pose], accel_cal: Calibration | None) -> tuple[PoseFit, Calibration | None]:
    """The accelerometer triad from the (temperature-compensated) poses, and the temperature models it completes.

    Where the poses span temperatures (a six-face session through a temperature profile), the six-position fit
    takes a linear bias drift alongside K(T): what the per-axis temperature models left of the bias's slope
    (they take the bias to be the same in every pose, so a scale factor changing with temperature, which moves
    each axis by dK/dT f (T - T_ref), leaves them a slope error of its mean over the poses).
    That slope is added to the polynomial temperature models (exact: the correction is a difference from the
    reference temperature) and the triad's bias is moved to their reference, so the compensation is whole."""
    temps = [p.temperature_degc for p in poses]
    if accel_cal is None or any(t is None for t in temps) or np.ptp(temps) < MIN_TRIAD_SPAN_DEGC:
        return fit_accel_multiposition(poses), accel_cal
    try:
        fit = fit_accel_multiposition(poses, method="six-position", bias_temperature_order=1)
    except InputError:
        return fit_accel_multiposition(poses), accel_cal
    triad = fit.calibration
    t_six = float(np.round(0.5 * (min(temps) + max(temps)), 1))
    slope = fit.bias_drift_g[0]
    axes = dict(accel_cal.accel_axes)
    for j, name in enumerate(ACCEL_AXES):
        curve = None if name not in axes else axes[name].temperature
        sloped = None if curve is None else curve.plus_slope(float(slope[j]))
        if sloped is None:
            return fit_accel_multiposition(poses), accel_cal  # a network cannot take the slope: K constant
        axes[name] = dataclasses.replace(axes[name], temperature=sloped)
    bias = np.asarray(triad.bias) + slope * (accel_cal.accel_reference_degc - t_six)
    fit = dataclasses.replace(fit, calibration=dataclasses.replace(triad, bias=tuple(float(b) for b in bias)))
    return fit, dataclasses.replace(accel_cal, accel_axes=axes)
