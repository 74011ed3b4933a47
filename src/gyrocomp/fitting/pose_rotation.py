"""Gyro scale factor and misalignment without a rate table: the rotations between still poses.

Between two still poses i and j the gyro's rate, freed of its bias at rest and corrected by C = K^-1,
integrates to the rotation R that took the body from pose i to pose j. Gravity is fixed in the world, so
in the body frame it reads f_j = R^T f_i; the accelerometer measures f_i and f_j at the poses (after its
own multi-position calibration of the same poses). Each move gives two equations in the nine elements of
C (a turn about gravity itself is not seen), and moves about every axis determine them all
(Tedaldi, Pretto & Menegatti, "A robust and easy to implement method for IMU calibration without
external equipments", ICRA 2014; imu_tk). The result is in the accelerometer's corrected frame.

Bias during a move: the gyro's bias at rest modelled over the poses by least squares,

    w_rest = b + G a (+ c (T - T_mean) when the session's temperature changes by more than 1 degC),

G the g-sensitivity [deg/s/g]; the rate of sample k is then w_k = C (g_k - b - G a_k - c (T_k - T_mean)).

Integration: the rate of sample k holds from t_k to t_{k+1}, so R = exp([phi_1]x) ... exp([phi_n]x) with
phi_k = w_k (t_{k+1} - t_k) [rad] exactly for a piecewise constant rate; the product is taken over unit
quaternions by pairwise (tree) reduction, all moves at once.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..errors import DataQualityWarning, InputError, user_stacklevel
from ..recording import Recording
from ..calibration.triad import TriadCalibration
from .triad_fit import MIN_TRIAD_SPAN_DEGC, ORDER_TOLERANCE, Pose, find_poses, fit_accel_multiposition, gyro_triad

#: every axis must be turned at least this far [deg] in some move, about an axis other than gravity
MIN_TURN_DEG = 20.0
#: the turns determine K when no combination of its elements moves the gravity directions by less than this
#: per move [rad per unit of K] (a well-turned session: about 0.5; turns about one axis only once: 0.001)
MIN_TURN_SINGULAR = 0.02
#: a session whose poses' temperatures span more than this [degC] gets a temperature term in its bias at rest
TEMPERATURE_SPAN_DEGC = 1.0
#: a stretch between two still poses longer than this [s] is not taken as a turn
MAX_TURN_S = 60.0
#: a sample interval this many times the median is a pause in the recording
GAP_FACTOR = 5.0
#: a fitted K further than this from I (any element) is no gyro's: the moves did not determine it
MAX_SENSITIVITY_ERROR = 0.5


class TooFewTurns(InputError):
    """The recordings hold fewer recorded turns between still poses than the fit needs (a session recorded
    only while still, or not a multi-position session)."""


@dataclass(frozen=True)
class PoseMove:
    """One turn between two consecutive still poses.

    Attributes
    ----------
    source : str
        The recording.
    start_s, duration_s : float
        When it starts (end of the first pose) and how long until the next pose [s].
    turn_deg : float
        Angle of the rotation the calibrated gyro integrates [deg].
    error_before_deg, error_after_deg : float
        Angle between the gravity direction the accelerometer measures at the second pose and the one the
        gyro predicts from the first pose, with K = I and with the fitted K [deg].
    """

    source: str
    start_s: float
    duration_s: float
    turn_deg: float
    error_before_deg: float
    error_after_deg: float


@dataclass(frozen=True)
class RotationFit:
    """A gyro scale-factor and misalignment calibration from rotations between still poses.

    Attributes
    ----------
    calibration : TriadCalibration
        K with standard errors, in the accelerometer's corrected frame (bias 0: the bias is the axis
        models' part).
    poses : tuple of Pose
        The still poses.
    moves : tuple of PoseMove
        The turns between them.
    bias_at_rest_dps : array (sessions, 3)
        b of each recording's bias at rest (see the module doc) [deg/s].
    g_sensitivity_dps_per_g : array (sessions, 3, 3)
        G of each recording's bias at rest [deg/s/g].
    accel_calibrations : tuple of TriadCalibration or None
        Per recording, the accelerometer calibration its gravity directions were taken through (None: raw
        directions).
    """

    calibration: TriadCalibration
    poses: tuple[Pose, ...]
    moves: tuple[PoseMove, ...]
    bias_at_rest_dps: np.ndarray
    g_sensitivity_dps_per_g: np.ndarray
    accel_calibrations: tuple[TriadCalibration | None, ...]

    @property
    def error_rms_before_deg(self) -> float:
        """RMS over the moves of the predicted gravity direction's error with K = I [deg]."""
        return float(np.sqrt(np.mean([m.error_before_deg**2 for m in self.moves])))

    @property
    def error_rms_after_deg(self) -> float:
        """RMS over the moves of the predicted gravity direction's error with the fitted K [deg]."""
        return float(np.sqrt(np.mean([m.error_after_deg**2 for m in self.moves])))


# -- rotations as unit quaternions (w, x, y, z), Hamilton convention: R(p q) = R(p) R(q) ---------------------
def quaternion_from_rotvec(phi: np.ndarray) -> np.ndarray:
    """Unit quaternion (..., 4) of the rotation vector phi (..., 3) [rad]."""
    phi = np.asarray(phi, dtype=float)
    angle = np.linalg.norm(phi, axis=-1)
    small = angle < 1e-6
    scale = np.where(small, 0.5 - angle**2 / 48.0, np.sin(0.5 * angle) / np.where(small, 1.0, angle))
    return np.concatenate([np.cos(0.5 * angle)[..., None], phi * scale[..., None]], axis=-1)


def quaternion_multiply(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product p q of quaternions (..., 4)."""
    pw, px, py, pz = np.moveaxis(p, -1, 0)
    qw, qx, qy, qz = np.moveaxis(q, -1, 0)
    return np.stack(
        [
            pw * qw - px * qx - py * qy - pz * qz,
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
        ],
        axis=-1,
    )


def ordered_product(q: np.ndarray) -> np.ndarray:
    """q[:, 0] q[:, 1] ... q[:, L-1] for quaternions (m, L, 4), by pairwise reduction (m, 4)."""
    while q.shape[1] > 1:
        if q.shape[1] % 2:
            pad = np.zeros((q.shape[0], 1, 4))
            pad[..., 0] = 1.0
            q = np.concatenate([q, pad], axis=1)
        q = quaternion_multiply(q[:, 0::2], q[:, 1::2])
    return q[:, 0]


def rotation_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of unit quaternions (..., 4)."""
    w, x, y, z = np.moveaxis(q / np.linalg.norm(q, axis=-1, keepdims=True), -1, 0)
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )


# -- the fit ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class _Moves:
    """The moves of the sessions, padded to one length: rates (m, L, 3) [deg/s] freed of the bias at rest,
    sample intervals (m, L) [s] (0 in the padding), temperatures (m, L) [degC] (NaN without), gravity
    directions before and after (m, 3), the session (recording) of each move (m,)."""

    rates_dps: np.ndarray
    dt_s: np.ndarray
    temperature_degc: np.ndarray
    before: np.ndarray
    after: np.ndarray
    session: np.ndarray
    meta: list[tuple[str, float, float]]

    def take(self, which: np.ndarray) -> "_Moves":
        """The moves selected by the boolean mask ``which``."""
        return _Moves(
            self.rates_dps[which],
            self.dt_s[which],
            self.temperature_degc[which],
            self.before[which],
            self.after[which],
            self.session[which],
            [m for m, w in zip(self.meta, which) if w],
        )

    def predicted(self, triad: tuple[np.ndarray, ...], reference_degc: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """(predicted gravity direction after each move (m, 3), rotation angle of each move (m,) [deg]) for
        K(T) = triad[0] + sum_p triad[p] (T - reference_degc)^p."""
        if len(triad) == 1:
            rates = self.rates_dps @ np.linalg.inv(triad[0]).T
        else:
            d = np.nan_to_num(self.temperature_degc - reference_degc)
            k = triad[0] + sum(np.multiply.outer(d**p, triad[p]) for p in range(1, len(triad)))
            rates = np.linalg.solve(k, self.rates_dps[..., None])[..., 0]
        phi = np.radians(rates) * self.dt_s[..., None]
        q = ordered_product(quaternion_from_rotvec(phi))
        angle = np.degrees(2.0 * np.arccos(np.clip(np.abs(q[:, 0]), 0.0, 1.0)))
        return np.einsum("mji,mj->mi", rotation_matrix(q), self.before), angle


def _bias_at_rest(poses: list[Pose]) -> tuple[np.ndarray, float | None]:
    """Coefficients (columns 1, a_x, a_y, a_z[, T - T_mean]) x 3 of the gyro at rest over the poses, and
    T_mean [degC] where the temperature term is used."""
    gyro = np.array([p.gyro_dps for p in poses], dtype=float)
    accel = np.array([p.accel_g for p in poses], dtype=float)
    temps = [p.temperature_degc for p in poses]
    columns = [np.ones(len(poses)), accel]
    t_mean = None
    if all(t is not None for t in temps) and np.ptp(temps) > TEMPERATURE_SPAN_DEGC:
        t_mean = float(np.mean(temps))
        columns.append(np.asarray(temps) - t_mean)
    x = np.column_stack(columns)
    if x.shape[0] <= x.shape[1]:
        raise InputError(
            f"poses: {len(poses)} still poses for the gyro's bias at rest ({x.shape[1]} unknowns per "
            "axis: bias, g-sensitivity, temperature); record more poses"
        )
    return np.linalg.lstsq(x, gyro, rcond=None)[0], t_mean


def _session_moves(
    recording: Recording, poses: list[Pose], coef: np.ndarray, t_mean: float | None, directions: np.ndarray
) -> list[tuple]:
    """(rates freed of the bias at rest [deg/s], dt [s], temperature [degC], before, after, meta) of each move
    between consecutive poses of one recording that was recorded without a pause and lasts at most MAX_TURN_S
    (longer stretches between still poses are motion, not a turn: their bias drift would dominate)."""
    out = []
    time = recording.time_s
    gap = GAP_FACTOR * float(np.median(np.diff(time)))
    temp = (
        None
        if recording.temperature_degc is None
        else recording.temperature_degc.reshape(recording.n_samples, -1).mean(axis=1)
    )
    for k in range(len(poses) - 1):
        a, b = poses[k].stop_index, poses[k + 1].start_index
        if b <= a:
            continue
        bias = coef[0] + recording.accel_g[a:b] @ coef[1:4]
        if t_mean is not None:
            bias = bias + np.outer(temp[a:b] - t_mean, coef[4])
        dt = time[a + 1 : b + 1] - time[a:b]
        if np.any(dt > gap) or time[b] - time[a] > MAX_TURN_S:  # a pause, or not a turn between two poses
            continue
        t = np.full(b - a, np.nan) if temp is None else temp[a:b]
        out.append(
            (
                recording.gyro_dps[a:b] - bias,
                dt,
                t,
                directions[k],
                directions[k + 1],
                (recording.source, float(time[a]), float(time[b] - time[a])),
            )
        )
    return out


def _pad(moves: list[tuple], sessions: list[int]) -> _Moves:
    length = max(len(m[1]) for m in moves)
    rates = np.zeros((len(moves), length, 3))
    dt = np.zeros((len(moves), length))
    temp = np.full((len(moves), length), np.nan)
    for i, m in enumerate(moves):
        rates[i, : len(m[1])] = m[0]
        dt[i, : len(m[1])] = m[1]
        temp[i, : len(m[1])] = m[2]
    return _Moves(
        rates,
        dt,
        temp,
        np.array([m[3] for m in moves]),
        np.array([m[4] for m in moves]),
        np.asarray(sessions),
        [m[5] for m in moves],
    )


def _require_turns(moves: _Moves) -> None:
    """Every axis turned at least MIN_TURN_DEG in some move, about an axis other than gravity (rotation vector
    of the nominal rates, less its component along the gravity direction before the move)."""
    turn = np.degrees(np.sum(np.radians(moves.rates_dps) * moves.dt_s[..., None], axis=1))
    across = turn - np.sum(turn * moves.before, axis=1)[:, None] * moves.before
    for j, name in enumerate("xyz"):
        if not np.any(np.abs(across[:, j]) >= MIN_TURN_DEG):
            raise InputError(
                f"moves between poses: none turns about the {name} axis by {MIN_TURN_DEG:g} deg or more "
                f"(other than about gravity); the gyro's scale factor needs a turn about every axis"
            )


def _require_determined(jacobian: np.ndarray, moves: int) -> None:
    """Refuse when some combination of K's elements barely moves the predicted gravity directions: smallest
    singular value of the Jacobian (radians of direction per unit of K) per sqrt(move) below MIN_TURN_SINGULAR."""
    _, sing, vt = np.linalg.svd(jacobian, full_matrices=False)
    if sing[-1] / np.sqrt(moves) >= MIN_TURN_SINGULAR:
        return
    block, element = divmod(int(np.argmax(np.abs(vt[-1]))), 9)
    row, col = divmod(element, 3)
    what = "" if block == 0 else ", its change with temperature"
    raise InputError(
        f"moves between poses: the turns leave the gyro's K undetermined (the {'xyz'[row]} output's "
        f"response to turns about {'xyz'[col]}{what}); turn the unit about its {'xyz'[col]} axis more, from "
        f"poses with gravity off that axis"
    )


def _angle_deg(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Angle between the rows of u and v [deg]."""
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(u, v), axis=1), np.sum(u * v, axis=1)))


def _directions(poses: list[Pose], accel_calibration: TriadCalibration | None) -> np.ndarray:
    means = np.array([p.accel_g for p in poses], dtype=float)
    temps = [p.temperature_degc for p in poses]
    if accel_calibration is not None:
        t = np.array(temps, dtype=float) if accel_calibration.sensitivity_per_degc else None
        means = accel_calibration.correct(means, t)
    return means / np.linalg.norm(means, axis=1)[:, None]


def _session_accels(sessions: list[tuple[Recording, list[Pose]]]) -> list[TriadCalibration | None]:
    """The accelerometer calibration of each session from its own poses (its bias changes with temperature and
    power-on), or from all the sessions' poses where one alone cannot give it; None (raw directions, with a
    warning) where neither can."""
    joint: list = []
    out = []
    for _, poses in sessions:
        try:
            out.append(fit_accel_multiposition(poses).calibration)
            continue
        except InputError:
            pass
        if not joint:
            try:
                joint.append(fit_accel_multiposition([p for _, ps in sessions for p in ps]).calibration)
            except InputError as exc:
                warnings.warn(
                    f"accelerometer not calibrated from the poses ({exc}); the gravity directions carry its "
                    "bias and scale errors, and so does the gyro's K",
                    DataQualityWarning,
                    stacklevel=user_stacklevel(),
                )
                joint.append(None)
        out.append(joint[0])
    return out


@dataclass(frozen=True)
class _Session:
    """The poses of the recordings, the accelerometer calibration each recording's directions come through, the
    bias at rest of each recording (coefficients, see ``_bias_at_rest``) and the moves."""

    poses: list[Pose]
    accels: tuple[TriadCalibration | None, ...]
    coefficients: list[np.ndarray]
    moves: _Moves


def _prepare(recordings: list[Recording] | Recording, accel_calibration: TriadCalibration | None) -> _Session:
    if isinstance(recordings, Recording):
        recordings = [recordings]
    sessions = []
    for rec in recordings:
        if rec.gyro_axes != ("gyro_x", "gyro_y", "gyro_z"):
            raise InputError(f"{rec.source}: a scale-factor and misalignment calibration needs all three gyro axes")
        sessions.append((rec, find_poses(rec)))
    all_poses = [p for _, poses in sessions for p in poses]
    accels = [accel_calibration] * len(sessions) if accel_calibration is not None else _session_accels(sessions)
    moves, coefs, index = [], [], []
    for k, (rec, poses) in enumerate(sessions):
        if len(poses) < 2:
            continue
        coef, t_mean = _bias_at_rest(poses)
        coefs.append(coef)
        found = _session_moves(rec, poses, coef, t_mean, _directions(poses, accels[k]))
        moves += found
        index += [k] * len(found)
    if len(moves) < 5:
        raise TooFewTurns(
            f"moves between poses: {len(moves)} found; the gyro's scale factor and misalignment (nine "
            "unknowns, two equations per move) need at least 5 turns between still poses"
        )
    return _Session(all_poses, tuple(accels), coefs, _pad(moves, index))


def _move_table(moves: _Moves, triad: tuple[np.ndarray, ...], reference_degc: float = 0.0) -> tuple[PoseMove, ...]:
    before, _ = moves.predicted((np.eye(3),))
    after, turn = moves.predicted(triad, reference_degc)
    return tuple(
        PoseMove(src, start, length, float(t), float(e0), float(e1))
        for (src, start, length), t, e0, e1 in zip(
            moves.meta, turn, _angle_deg(before, moves.after), _angle_deg(after, moves.after)
        )
    )


def _solve(moves: _Moves, order: int, reference_degc: float):
    """Least squares for K(T) of the given order: (the fit's solution, the triad's blocks)."""

    def residuals(theta: np.ndarray) -> np.ndarray:
        return (moves.predicted(tuple(theta.reshape(-1, 3, 3)), reference_degc)[0] - moves.after).ravel()

    start = np.concatenate([np.eye(3).ravel(), np.zeros(9 * order)])
    from scipy import optimize  # slow to import; only the between-poses fit needs it

    sol = optimize.least_squares(residuals, start, method="lm", jac="3-point", xtol=1e-12, ftol=1e-12)
    return sol, tuple(sol.x.reshape(-1, 3, 3))


def _session_temperatures(moves: _Moves) -> np.ndarray:
    """Mean temperature of each session's turns [degC] (NaN without temperature)."""
    with np.errstate(invalid="ignore"):
        return np.array(
            [
                np.nanmean(moves.temperature_degc[moves.session == k])
                if np.any(moves.session == k) and np.any(np.isfinite(moves.temperature_degc[moves.session == k]))
                else np.nan
                for k in np.unique(moves.session)
            ]
        )


def _held_out_error(moves: _Moves, order: int, reference_degc: float) -> float:
    """RMS gravity-direction error [rad] of each session's turns predicted by K(T) fitted on the other sessions."""
    errors = []
    for k in np.unique(moves.session):
        held = moves.session == k
        _, triad = _solve(moves.take(~held), order, reference_degc)
        predicted, _ = moves.take(held).predicted(triad, reference_degc)
        errors.append(predicted - moves.after[held])
    return float(np.sqrt(np.mean(np.concatenate(errors) ** 2)))


def _rotation_order(moves: _Moves, reference_degc: float, temperature_order: int | Literal["auto"]) -> int:
    temps = _session_temperatures(moves)
    distinct = len(np.unique(np.round(temps[np.isfinite(temps)])))
    span = float(np.ptp(temps)) if distinct else 0.0
    if temperature_order == "auto":
        if distinct < 3 or span < MIN_TRIAD_SPAN_DEGC:
            return 0
        scores = [_held_out_error(moves, q, reference_degc) for q in (0, 1)]
        return 1 if scores[1] < scores[0] / ORDER_TOLERANCE else 0
    if temperature_order not in (0, 1):
        raise InputError(f"temperature_order: {temperature_order!r}; use 'auto', 0 or 1")
    if temperature_order == 1 and (distinct < 2 or span < MIN_TRIAD_SPAN_DEGC):
        raise InputError(
            f"temperature_order: 1 needs turning sessions at temperatures at least {MIN_TRIAD_SPAN_DEGC:g} "
            f"degC apart; these span {span:.1f} degC"
        )
    return temperature_order


def _require_plausible(sensitivity: np.ndarray) -> None:
    """Refuse a fitted sensitivity matrix [1] further from the identity than :data:`MAX_SENSITIVITY_ERROR`."""
    if np.max(np.abs(sensitivity - np.eye(3))) > MAX_SENSITIVITY_ERROR:
        raise InputError(
            f"moves between poses: the fit found no plausible gyro triad (scale or misalignment beyond "
            f"{MAX_SENSITIVITY_ERROR:.0%}); the turns do not determine it"
        )


def _standard_errors(sol, n_moves: int) -> np.ndarray:
    """The standard errors of the least-squares solution ``sol`` (two residuals per move), one 3x3 per term."""
    dof = 2 * n_moves - sol.x.size
    variance = float(np.sum(sol.fun**2) / max(dof, 1))
    return np.sqrt(np.diag(np.linalg.pinv(sol.jac.T @ sol.jac)) * variance).reshape(-1, 3, 3)


def fit_gyro_between_poses(
    recordings: list[Recording] | Recording,
    *,
    accel_calibration: TriadCalibration | None = None,
    temperature_order: int | Literal["auto"] = "auto",
) -> RotationFit:
    """Scale factor and misalignment of a gyro triad from the rotations between still poses (no rate table).

    Parameters
    ----------
    recordings : Recording or list of Recording
        Multi-position sessions with three gyro axes [deg/s] and three accelerometer axes [g], turned by hand
        (or otherwise) between still poses, the turns recorded; each recording is one power-on (its own bias
        at rest). The poses are found as in :func:`find_poses`.
    accel_calibration : TriadCalibration, optional
        The accelerometer calibration the gravity directions are taken through; default: fitted from each
        recording's poses (:func:`fit_accel_multiposition`; its bias moves with temperature and power-on), from
        all of them where one recording's cannot, raw directions with a warning where neither can.
    temperature_order : int or "auto"
        K constant (0) or linear in temperature (1: sessions at temperatures at least 5 degC apart, the
        sample's temperature read during each turn); ``auto``: by leave-one-session-out error with sessions
        at three or more temperatures (the lowest order within 5 % of the best), else 0.

    Returns
    -------
    RotationFit
        K(T) and its standard errors, the moves with the gravity direction's error before and after.
    """
    session = _prepare(recordings, accel_calibration)
    moves = session.moves
    _require_turns(moves)
    temps = _session_temperatures(moves)
    reference = float(np.round(0.5 * (np.nanmin(temps) + np.nanmax(temps)), 1)) if np.any(np.isfinite(temps)) else 0.0
    order = _rotation_order(moves, reference, temperature_order)
    sol, triad = _solve(moves, order, reference)
    _require_determined(sol.jac, len(moves.meta))
    _require_plausible(triad[0])
    se = _standard_errors(sol, len(moves.meta))
    cal = gyro_triad(triad, se, "rotation", reference)
    coefs = session.coefficients
    return RotationFit(
        cal,
        tuple(session.poses),
        _move_table(moves, triad, reference),
        np.array([c[0] for c in coefs]),
        np.array([c[1:4].T for c in coefs]),
        session.accels,
    )


def rotation_errors(
    recordings: list[Recording] | Recording,
    gyro_calibration: TriadCalibration,
    *,
    accel_calibration: TriadCalibration | None = None,
) -> tuple[PoseMove, ...]:
    """The turns between the still poses of ``recordings`` and how well ``gyro_calibration`` (its K(T) at each
    sample's temperature) predicts each one's gravity direction: a held-out check of a calibration on another
    session. ``accel_calibration`` as in :func:`fit_gyro_between_poses`."""
    session = _prepare(recordings, accel_calibration)
    triad = tuple(
        np.asarray(k, dtype=float) for k in (gyro_calibration.sensitivity, *gyro_calibration.sensitivity_per_degc)
    )
    if len(triad) > 1 and not np.all(np.isfinite(session.moves.temperature_degc[session.moves.dt_s > 0])):
        raise InputError("recordings: the calibration's K depends on temperature; the sessions have no temperature")
    return _move_table(session.moves, triad, gyro_calibration.reference_degc or 0.0)


__all__ = [
    "PoseMove",
    "RotationFit",
    "TooFewTurns",
    "fit_gyro_between_poses",
    "ordered_product",
    "quaternion_from_rotvec",
    "quaternion_multiply",
    "rotation_errors",
    "rotation_matrix",
]
