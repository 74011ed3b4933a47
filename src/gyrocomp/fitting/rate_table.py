"""Fitting a gyro triad's scale factor and misalignment K(T) on a rate table (see
:mod:`gyrocomp.calibration.triad` for the model): runs with the table's reference rates, their constant-rate
stretches as means, K linear in the reference rate with each run's own bias, its order in temperature chosen by
leave-one-run-out."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..errors import InputError
from ..recording import Recording
from ..calibration.triad import TriadCalibration
from .triad_fit import ORDER_TOLERANCE, gyro_triad

#: the highest order of K(T) in temperature the rate-table fit considers
MAX_TRIAD_TEMPERATURE_ORDER = 2
#: a reference rate at least this fast [deg/s] makes a segment informative about K
MIN_REFERENCE_RATE_DPS = 1.0


@dataclass(frozen=True)
class RateSegment:
    """One stretch of a rate-table run at a constant reference rate.

    Attributes
    ----------
    run : int
        Index of the run (recording) it belongs to.
    reference_dps : array (3,)
        The table's rate in the sensor frame [deg/s].
    gyro_dps : array (3,)
        Mean gyro output [deg/s].
    temperature_degc : float
        Mean temperature [degC].
    samples : int
        Samples averaged.
    """

    run: int
    reference_dps: np.ndarray
    gyro_dps: np.ndarray
    temperature_degc: float
    samples: int


def rate_segments(recordings: list[Recording], *, settle_s: float = 1.0) -> list[RateSegment]:
    """The constant-rate stretches of rate-table runs (where ``reference_rate_dps`` holds still), less
    ``settle_s`` [s] at each end (the table accelerating), as means."""
    out = []
    for run, rec in enumerate(recordings):
        if rec.reference_rate_dps is None:
            raise InputError(
                f"{rec.source}: no reference rates (ref_rate_x, ref_rate_y, ref_rate_z); a rate-table "
                "calibration needs the rate the table applied in each row"
            )
        if rec.gyro_axes != ("gyro_x", "gyro_y", "gyro_z"):
            raise InputError(f"{rec.source}: a scale-factor and misalignment calibration needs all three gyro axes")
        if rec.temperature_degc is None:
            raise InputError(f"{rec.source}: no temperature column; the rate-table fit reads the temperature")
        ref = rec.reference_rate_dps
        temp = rec.temperature_degc.reshape(rec.n_samples, -1).mean(axis=1)
        change = np.flatnonzero(np.any(np.diff(ref, axis=0) != 0, axis=1)) + 1
        trim = int(round(settle_s * rec.rate_hz))
        for a, b in zip(np.r_[0, change], np.r_[change, rec.n_samples]):
            a, b = a + trim, b - trim
            if b - a < 2:
                continue
            out.append(RateSegment(run, ref[a], rec.gyro_dps[a:b].mean(axis=0), float(temp[a:b].mean()), int(b - a)))
    return out


def _rate_design(segments: list[RateSegment], runs: int, order: int, t_ref: float) -> np.ndarray:
    """Columns: one constant per run, then w_j (T - t_ref)^p for p = 0..order, j = x, y, z."""
    n = len(segments)
    x = np.zeros((n, runs + 3 * (order + 1)))
    for i, seg in enumerate(segments):
        x[i, seg.run] = 1.0
        d = seg.temperature_degc - t_ref
        for p in range(order + 1):
            x[i, runs + 3 * p : runs + 3 * p + 3] = seg.reference_dps * d**p
    return x


def _held_out_rms(segments: list[RateSegment], runs: int, order: int, t_ref: float) -> float:
    """RMS error [deg/s] of each run's moving segments predicted by K(T) fitted on the other runs (its own
    constant taken from its own segments, as a turn-on bias would be)."""
    y = np.array([s.gyro_dps for s in segments])
    x = _rate_design(segments, runs, order, t_ref)
    run_of = np.array([s.run for s in segments])
    moving = np.linalg.norm(np.array([s.reference_dps for s in segments]), axis=1) >= MIN_REFERENCE_RATE_DPS
    errors = []
    for r in range(runs):
        train = run_of != r
        coef = np.linalg.lstsq(x[train], y[train], rcond=None)[0]
        resid = y[~train] - x[~train][:, runs:] @ coef[runs:]
        resid -= resid.mean(axis=0)
        errors.append(resid[moving[~train]])
    return float(np.sqrt(np.mean(np.concatenate(errors) ** 2)))


@dataclass(frozen=True)
class RateTableFit:
    """A gyro scale-factor and misalignment calibration from rate-table runs.

    Attributes
    ----------
    calibration : TriadCalibration
        K(T) with standard errors (bias 0: the temperature bias is the axis models' part).
    segments : tuple of RateSegment
        The constant-rate stretches used.
    turn_on_biases_dps : array (runs, 3)
        Each run's constant [deg/s].
    held_out_rms_dps : dict of int to float
        Leave-one-run-out RMS error of the moving segments for each K(T) order tried [deg/s].
    residual_rms_dps : float
        RMS residual of the segments of the chosen fit [deg/s].
    """

    calibration: TriadCalibration
    segments: tuple[RateSegment, ...]
    turn_on_biases_dps: np.ndarray
    held_out_rms_dps: dict[int, float]
    residual_rms_dps: float


def _choose_order(
    segments: list[RateSegment],
    runs: int,
    temperatures: np.ndarray,
    t_ref: float,
    temperature_order: int | Literal["auto"],
) -> tuple[int, dict[int, float]]:
    distinct = len(np.unique(np.round(temperatures, 1)))
    possible = min(MAX_TRIAD_TEMPERATURE_ORDER, distinct - 1)
    if temperature_order == "auto":  # leaving a run out must leave enough temperatures for the order
        possible = min(possible, distinct - 2)
    else:
        if not isinstance(temperature_order, int) or not 0 <= temperature_order <= MAX_TRIAD_TEMPERATURE_ORDER:
            raise InputError(
                f"temperature_order: {temperature_order!r}; use 'auto' or 0..{MAX_TRIAD_TEMPERATURE_ORDER}"
            )
        if temperature_order > possible:
            raise InputError(
                f"temperature_order: {temperature_order} needs runs at {temperature_order + 1} or more "
                f"temperatures; these runs have {distinct}"
            )
        return temperature_order, {}
    if runs < 3 or possible < 1:
        return 0, {}
    scores = {q: _held_out_rms(segments, runs, q, t_ref) for q in range(possible + 1)}
    best = min(scores.values())
    return min(q for q, v in scores.items() if v <= ORDER_TOLERANCE * best), scores


def fit_gyro_rate_table(
    recordings: list[Recording], *, temperature_order: int | Literal["auto"] = "auto", settle_s: float = 1.0
) -> RateTableFit:
    """Scale factor and misalignment of a gyro triad, K(T), from rate-table runs.

    Each run holds constant rates about each axis (both directions) with the table's rate in the sensor
    frame as ``reference_rate_dps``; runs at several temperatures give K's temperature coefficients.
    The segment means obey ``gyro = c_run + K(T) w_ref`` with one constant per run (turn-on bias plus the
    temperature bias at that run's temperature), solved by least squares; the order of K(T) in
    temperature (0 .. 2) is chosen by leave-one-run-out error with three or more runs (parsimony: the
    lowest order within 5 % of the best).

    Parameters
    ----------
    recordings : list of Recording
        Rate-table runs with ``reference_rate_dps`` [deg/s], three gyro axes and a temperature [degC].
    temperature_order : int or "auto"
        Order of K(T) in (T - T_ref); ``auto`` chooses it as above.
    settle_s : float
        Time left out at each end of a constant-rate stretch [s].
    """
    segments = rate_segments(recordings, settle_s=settle_s)
    ref = np.array([s.reference_dps for s in segments]) if segments else np.zeros((0, 3))
    moving = np.abs(ref) >= MIN_REFERENCE_RATE_DPS
    for j, name in enumerate("xyz"):
        if not (np.any(moving[:, j] & (ref[:, j] > 0)) and np.any(moving[:, j] & (ref[:, j] < 0))):
            raise InputError(
                f"rate table: no constant-rate stretch turning about {name} in both directions "
                f"(at least {MIN_REFERENCE_RATE_DPS:g} deg/s each way); K needs every axis turned"
            )
    runs = len(recordings)
    temperatures = np.array([s.temperature_degc for s in segments])
    t_ref = float(np.round(np.mean(temperatures), 1))
    order, scores = _choose_order(segments, runs, temperatures, t_ref, temperature_order)
    x = _rate_design(segments, runs, order, t_ref)
    y = np.array([s.gyro_dps for s in segments])
    coef, *_ = np.linalg.lstsq(x, y, rcond=None)
    resid = y - x @ coef
    dof = x.shape[0] - x.shape[1]
    if dof <= 0:
        raise InputError(
            f"rate table: {x.shape[0]} constant-rate stretches for {x.shape[1]} unknowns; record more rates or runs"
        )
    variance = float(np.sum(resid**2) / (3 * dof))
    se = np.sqrt(np.outer(np.diag(np.linalg.pinv(x.T @ x)), np.ones(3)) * variance)
    blocks = [coef[runs + 3 * p : runs + 3 * p + 3].T for p in range(order + 1)]  # K row i = output axis i
    block_se = [se[runs + 3 * p : runs + 3 * p + 3].T for p in range(order + 1)]
    cal = gyro_triad(blocks, block_se, "rate-table", t_ref)
    return RateTableFit(cal, tuple(segments), coef[:runs], scores, float(np.sqrt(np.mean(resid**2))))


__all__ = [
    "MAX_TRIAD_TEMPERATURE_ORDER",
    "MIN_REFERENCE_RATE_DPS",
    "RateSegment",
    "RateTableFit",
    "fit_gyro_rate_table",
    "rate_segments",
]
