"""Fitting a triad's bias, scale factor and misalignment (see :mod:`gyrocomp.calibration.triad` for the model).

Accelerometer, multi-position (no turntable, no known orientations needed):

* ``method="norm"`` (Tedaldi, Pretto & Menegatti, ICRA 2014; imu_tk; Skog & Haendel 2006): at rest the
  corrected specific force has the norm of gravity, so each pose i gives one equation
  ``|| C (a_i - b) || = g`` in the nine unknowns b (3) and the upper-triangular C = K^-1 (6). Weighted
  Levenberg-Marquardt; at least 10 poses, with gravity along both signs of every axis.
* ``method="six-position"`` (Ferraris et al. 1995; imucal): the poses lie along +-x, +-y, +-z of a
  reference frame (a cube on a level table), so ``a_i = K d_i + b`` with d_i the known direction:
  linear least squares for the full K and b; every one of the six directions at least once.
* ``method="auto"``: the norm method with 12 or more poses whose directions determine its nine unknowns
  (:func:`undetermined_norm_term`), else six-position when the six directions are present, else the norm
  method when it has its 10 poses.

Both fits are unweighted (placement errors of hand-held poses, not the sensor noise, set the scatter
of real poses). Standard errors come from the fit's covariance scaled by the residual variance, never
below what the poses' own noise (standard error of each mean) allows.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from ..errors import DataQualityWarning, InputError, user_stacklevel
from ..recording import Recording
from ..runs.prepared import PreparedRun
from ..calibration.triad import TriadCalibration, rows_of

PoseMethod = Literal["auto", "norm", "six-position"]
#: the norm method has 9 unknowns; one more pose than that at the least
MIN_POSES_NORM = 10
#: with this many poses ``auto`` prefers the norm method (a few degrees of freedom to judge the fit)
AUTO_NORM_POSES = 12
#: a pose is along an axis when that axis holds this fraction of the norm (within ~10 deg)
AXIS_ALIGNED_FRACTION = 0.985
#: every axis must point at least this close to up and to down in some pose (fraction of the norm, 60 deg)
SPAN_FRACTION = 0.5
#: poses whose gravity directions are closer than this are one orientation (cosine of 10 deg)
SAME_DIRECTION_COS = 0.985
#: the lowest order whose held-out error is within this factor of the best is chosen (parsimony)
ORDER_TOLERANCE = 1.05
#: poses spanning at least this many degC may give K(T) (six-position method)
MIN_TRIAD_SPAN_DEGC = 5.0
#: a fitted K further than this from I (any element) is no sensor's: the poses did not determine it
MAX_SENSITIVITY_ERROR = 0.5
DEFAULT_POSE_MIN_S = 1.0
DEFAULT_POSE_WINDOW_S = 0.5
#: hand-placed poses are less still than a bench: a window is still up to this many times the median variance
DEFAULT_POSE_FACTOR = 10.0
_DIRECTION_NAMES = ("+x", "-x", "+y", "-y", "+z", "-z")


@dataclass(frozen=True)
class Pose:
    """One still orientation of a multi-position test.

    Attributes
    ----------
    source : str
        The recording it comes from.
    start_s, duration_s : float
        Where it lies in that recording [s].
    samples : int
        Samples averaged.
    accel_g : array (3,)
        Mean specific force [g].
    accel_sem_g : array (3,)
        Standard error of that mean per axis (sample standard deviation / sqrt(samples)) [g].
    gyro_dps : array (k,) or None
        Mean angular rate [deg/s].
    temperature_degc : float or None
        Mean temperature [degC].
    start_index, stop_index : int
        Its samples in the recording, [start_index, stop_index) (0, 0 when it was not taken from one).
    """

    source: str
    start_s: float
    duration_s: float
    samples: int
    accel_g: np.ndarray
    accel_sem_g: np.ndarray
    gyro_dps: np.ndarray | None
    temperature_degc: float | None
    start_index: int = 0
    stop_index: int = 0


def _pose(recording: Recording, start: int, stop: int) -> Pose:
    acc = recording.accel_g[start:stop]
    n = stop - start
    temp = recording.temperature_degc
    return Pose(
        recording.source,
        float(recording.time_s[start]),
        float(recording.time_s[stop - 1] - recording.time_s[start]),
        int(n),
        acc.mean(axis=0),
        acc.std(axis=0, ddof=1) / np.sqrt(n),
        recording.gyro_dps[start:stop].mean(axis=0),
        None if temp is None else float(np.mean(temp[start:stop])),
        start,
        stop,
    )


def find_poses(
    recording: Recording,
    *,
    ranges: list[tuple[int, int]] | None = None,
    min_duration_s: float = DEFAULT_POSE_MIN_S,
    window_s: float = DEFAULT_POSE_WINDOW_S,
    factor: float = DEFAULT_POSE_FACTOR,
) -> list[Pose]:
    """The still poses of a multi-position recording.

    Parameters
    ----------
    recording : Recording
        With an accelerometer [g].
    ranges : list of (start, stop), optional
        Sample index ranges [start, stop) of the poses when they are known (an annotated session);
        default: found as the still segments (:func:`gyrocomp.motion.positions.static_segments`) of at least
        ``min_duration_s`` [s], judged over windows of ``window_s`` [s]: still where the window's
        variance is at most ``factor`` times its median over the recording.
    """
    if recording.accel_g is None or recording.accel_g.shape[1] != 3:
        raise InputError(
            f"{recording.source}: a multi-position calibration needs the three accelerometer axes "
            "(accel_x, accel_y, accel_z)"
        )
    if ranges is None:
        segs = PreparedRun.of(recording).static_segments(
            window_s=window_s, min_duration_s=min_duration_s, factor=factor
        )
        ranges = [(s.start, s.stop) for s in segs]
    out = []
    for start, stop in ranges:
        if not 0 <= start < stop <= recording.n_samples or stop - start < 2:
            raise InputError(
                f"{recording.source}: pose range [{start}, {stop}) is not inside the "
                f"{recording.n_samples} samples or holds fewer than 2"
            )
        out.append(_pose(recording, int(start), int(stop)))
    return out


@dataclass(frozen=True)
class PoseFit:
    """A multi-position accelerometer calibration and how well it holds on its poses.

    Attributes
    ----------
    calibration : TriadCalibration
        Bias [g], K and their standard errors.
    poses : tuple of Pose
        The poses used.
    norm_before_g, norm_after_g : array (poses,)
        |a| of each pose's mean before and after the correction [g].
    reduced_chi_square : float
        Weighted residual sum of squares per degree of freedom (1 when the poses scatter as their
        noise says; NaN with no degree of freedom).
    degrees_of_freedom : int
        Equations minus unknowns.
    poses_left_out : int
        Poses the six-position method could not assign to an axis direction.
    gravity_g : float
        The norm the poses were fitted to [g].
    bias_drift_g : array (order, 3)
        With ``bias_temperature_order``: coefficients of (T - reference_degc)^p, p = 1..order, of the bias
        drift fitted alongside [g/degC^p] (empty otherwise).
    """

    calibration: TriadCalibration
    poses: tuple[Pose, ...]
    norm_before_g: np.ndarray
    norm_after_g: np.ndarray
    reduced_chi_square: float
    degrees_of_freedom: int
    poses_left_out: int = 0
    gravity_g: float = 1.0
    bias_drift_g: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))

    @property
    def norm_rms_error_g(self) -> float:
        """RMS of |a| - g over the poses after the correction [g]."""
        return float(np.sqrt(np.mean((self.norm_after_g - self.gravity_g) ** 2)))

    @property
    def norm_rms_error_before_g(self) -> float:
        """RMS of |a| - g over the poses before the correction [g]."""
        return float(np.sqrt(np.mean((self.norm_before_g - self.gravity_g) ** 2)))


def _directions(means: np.ndarray) -> np.ndarray:
    """Unit vector of each pose mean (n, 3)."""
    norms = np.linalg.norm(means, axis=1)
    if np.any(norms < 0.1):
        k = int(np.flatnonzero(norms < 0.1)[0])
        raise InputError(
            f"pose {k + 1}: mean specific force {norms[k]:.3g} g; a pose at rest reads about 1 g "
            "(are the accelerations in g?)"
        )
    return means / norms[:, None]


def _unturned(units: np.ndarray) -> tuple[int, int] | None:
    """The first (axis, sign) that no pose turns within 60 deg of gravity, or None when every axis points both
    up and down in some pose."""
    for axis in range(3):
        for sign in (1, -1):
            if not np.any(sign * units[:, axis] > SPAN_FRACTION):
                return axis, sign
    return None


def spans_axes(poses: list[Pose]) -> bool:
    """Whether the poses turn every accelerometer axis both up and down (gravity within 60 deg of +-x, +-y, +-z)."""
    means = np.array([p.accel_g for p in poses], dtype=float).reshape(-1, 3)
    norms = np.linalg.norm(means, axis=1)
    if means.size == 0 or np.any(norms < 0.1):
        return False
    return _unturned(means / norms[:, None]) is None


def _require_span(units: np.ndarray) -> None:
    missing = _unturned(units)
    if missing is not None:
        axis, sign = missing
        name, word = "xyz"[axis], "up" if sign > 0 else "down"
        raise InputError(
            f"poses: no pose has the {name} axis pointing {word} (gravity within 60 deg of "
            f"{'+' if sign > 0 else '-'}{name}); the poses must turn every axis both up and down"
        )


def distinct_orientations(units: np.ndarray) -> int:
    """How many of the unit vectors (n, 3) point in different directions (more than 10 deg apart)."""
    kept: list[np.ndarray] = []
    for u in units:
        if not any(float(u @ k) > SAME_DIRECTION_COS for k in kept):
            kept.append(u)
    return len(kept)


#: the norm method's nine unknowns are determined when the poses' directions leave no combination of the terms
#: below nearly unseen: smallest singular value of their design, per pose (1/sqrt(3) for the six faces alone)
MIN_NORM_SINGULAR = 0.02
_NORM_TERMS = ("x*x", "y*y", "z*z", "x*y", "x*z", "y*z", "x", "y", "z")


def undetermined_norm_term(units: np.ndarray, fixed: tuple[str, ...] = ()) -> str | None:
    """The term (``"x*y"``, ...) of the norm method's linearized model that the pose directions (n, 3) leave
    undetermined, or None when they determine all nine unknowns (all but the ``fixed`` terms).

    Near the solution, |C (a - b)|^2 = g^2 changes with the unknowns through the terms u_i u_j (the six of
    C^T C) and u_i (the bias) of each pose direction u; poses that never tilt between two axes (u_x u_y = 0
    for all of them, as in a tumble about two axes only) leave that coupling undetermined.
    """
    x, y, z = np.asarray(units, dtype=float).T
    keep = [k for k, name in enumerate(_NORM_TERMS) if name not in fixed]
    design = np.column_stack([x * x, y * y, z * z, x * y, x * z, y * z, x, y, z])[:, keep]
    if design.shape[0] < design.shape[1]:
        return _NORM_TERMS[keep[int(np.argmin(np.abs(design).sum(axis=0)))]]
    _, sing, vt = np.linalg.svd(design, full_matrices=False)
    if sing[-1] / np.sqrt(design.shape[0]) >= MIN_NORM_SINGULAR:
        return None
    return _NORM_TERMS[keep[int(np.argmax(np.abs(vt[-1])))]]


#: the element of theta (bias 3, then C's upper triangle row by row) each coupling term sets
_COUPLING_INDEX = {"x*y": 4, "x*z": 5, "y*z": 7}


def _fixed_couplings(poses: list[Pose], units: np.ndarray) -> tuple[str, ...]:
    """The axis couplings the poses leave undetermined (fixed at zero, with a warning); refuses when a scale or
    bias term is undetermined."""
    fixed: tuple[str, ...] = ()
    while (term := undetermined_norm_term(units, fixed)) is not None:
        if term not in _COUPLING_INDEX:
            raise InputError(
                f"poses: the {len(poses)} orientations leave the norm method's {term} term undetermined "
                f"(the poses do not vary the {term[0]} axis's share of gravity enough); add poses tilted "
                "between the axes, or use method='six-position'"
            )
        fixed += (term,)
    if fixed:
        pairs = ", ".join(f"{t[0]} and {t[2]}" for t in fixed)
        warnings.warn(
            f"poses: no pose has gravity between the {pairs} axes; that misalignment is not determined and "
            "is taken as zero (add poses tilted between the axes to fit it)",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
    return fixed


def _axis_assignment(units: np.ndarray) -> np.ndarray:
    """Index 0..5 (+x, -x, +y, -y, +z, -z) of each pose's direction, -1 where no axis dominates."""
    axis = np.argmax(np.abs(units), axis=1)
    big = np.abs(units[np.arange(len(units)), axis]) >= AXIS_ALIGNED_FRACTION
    sign = units[np.arange(len(units)), axis] < 0
    return np.where(big, 2 * axis + sign, -1)


def _sigma_of_norm(poses: list[Pose], units: np.ndarray) -> np.ndarray:
    """Standard error of each pose's |a| from its per-axis standard errors [g] (never zero)."""
    sem = np.array([p.accel_sem_g for p in poses])
    sigma = np.sqrt(np.sum((units * sem) ** 2, axis=1))
    return np.maximum(sigma, 1e-9)


def _upper(theta: np.ndarray) -> np.ndarray:
    c = np.zeros((3, 3))
    c[np.triu_indices(3)] = theta[3:]
    return c


def _norm_residuals(theta: np.ndarray, means: np.ndarray, gravity_g: float) -> np.ndarray:
    w = (means - theta[:3]) @ _upper(theta).T
    return np.linalg.norm(w, axis=1) - gravity_g


def _norm_jacobian(theta: np.ndarray, means: np.ndarray, gravity_g: float) -> np.ndarray:
    c = _upper(theta)
    v = means - theta[:3]
    w = v @ c.T
    u = w / np.linalg.norm(w, axis=1)[:, None]
    d_bias = -u @ c
    rows, cols = np.triu_indices(3)
    d_c = u[:, rows] * v[:, cols]
    return np.hstack([d_bias, d_c])


def _sphere_start(means: np.ndarray, gravity_g: float) -> np.ndarray:
    """Start of the norm fit: the centre and radius of the sphere through the poses."""
    x = np.column_stack([2.0 * means, np.ones(len(means))])
    sol = np.linalg.lstsq(x, np.sum(means**2, axis=1), rcond=None)[0]
    centre = sol[:3]
    radius = np.sqrt(max(sol[3] + centre @ centre, 1e-12))
    return np.concatenate([centre, (gravity_g / radius) * np.eye(3)[np.triu_indices(3)]])


def propagate_stderr(fun, theta: np.ndarray, cov: np.ndarray) -> np.ndarray:
    """Standard errors of fun(theta) given the covariance ``cov`` of theta, by linear propagation (central
    differences)."""
    base = np.asarray(fun(theta), dtype=float).ravel()
    jac = np.empty((base.size, theta.size))
    for j in range(theta.size):
        h = 1e-6 * max(1.0, abs(theta[j]))
        up, down = theta.copy(), theta.copy()
        up[j] += h
        down[j] -= h
        jac[:, j] = (np.asarray(fun(up)).ravel() - np.asarray(fun(down)).ravel()) / (2 * h)
    return np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", jac, cov, jac), 0.0))


def _residual_variance(ssr: float, dof: int, noise_variance: float) -> tuple[float, float]:
    """(reduced chi-square against the poses' own noise, the variance the covariance is scaled by).

    The poses scatter by their noise and by what the model leaves (placement, a non-rigid mount); the
    residual variance ssr / dof measures both, the noise alone is the floor when there are few degrees
    of freedom."""
    noise_variance = max(noise_variance, 1e-30)
    if dof <= 0:
        return float("nan"), noise_variance
    return float(ssr / dof / noise_variance), max(ssr / dof, noise_variance)


def _fit_norm(poses: list[Pose], means: np.ndarray, units: np.ndarray, gravity_g: float):
    distinct = distinct_orientations(units)
    if distinct < MIN_POSES_NORM:
        raise InputError(
            f"poses: {distinct} distinct orientations (of {len(poses)} still poses); the norm method "
            f"needs at least {MIN_POSES_NORM} (nine unknowns: bias, scale and misalignment)"
        )
    fixed = _fixed_couplings(poses, units)
    free = np.array([k for k in range(9) if k not in [_COUPLING_INDEX[t] for t in fixed]])
    start = _sphere_start(means, gravity_g)

    def full(t: np.ndarray) -> np.ndarray:
        theta = start.copy()
        theta[free] = t
        return theta

    from scipy import optimize  # slow to import; only the multi-position fit needs it

    sol = optimize.least_squares(
        lambda t: _norm_residuals(full(t), means, gravity_g),
        start[free],
        jac=lambda t: _norm_jacobian(full(t), means, gravity_g)[:, free],
        method="lm",
        xtol=1e-15,
        ftol=1e-15,
        gtol=1e-15,
    )
    theta = full(sol.x)
    sens = np.linalg.inv(_upper(theta)) if abs(np.linalg.det(_upper(theta))) > 1e-9 else np.full((3, 3), np.inf)
    if np.any(np.diag(_upper(theta)) <= 0) or np.max(np.abs(sens - np.eye(3))) > MAX_SENSITIVITY_ERROR:
        raise InputError(
            f"poses: the norm fit over {len(poses)} poses found no plausible triad (scale or "
            f"misalignment beyond {MAX_SENSITIVITY_ERROR:.0%}); the orientations do not determine it"
        )
    dof = len(poses) - free.size
    red, variance = _residual_variance(
        float(np.sum(sol.fun**2)), dof, float(np.mean(_sigma_of_norm(poses, units) ** 2))
    )
    cov = np.zeros((9, 9))
    cov[np.ix_(free, free)] = np.linalg.pinv(sol.jac.T @ sol.jac) * variance
    sens = lambda t: np.linalg.inv(_upper(t))  # noqa: E731
    return (
        theta[:3],
        sens(theta),
        np.sqrt(np.diag(cov))[:3],
        propagate_stderr(sens, theta, cov).reshape(3, 3),
        red,
        dof,
        0,
    )


def _six_position_design(
    d: np.ndarray, temperatures: np.ndarray | None, order: int, t_ref: float, bias_order: int = 0
) -> np.ndarray:
    """Columns: the direction (3), then (T - t_ref)^p times it for p = 1..order, then 1 (the bias), then
    (T - t_ref)^p for p = 1..bias_order (a bias still drifting with temperature)."""
    blocks = [d] + [d * ((temperatures - t_ref) ** p)[:, None] for p in range(1, order + 1)]
    drift = [(temperatures - t_ref) ** p for p in range(1, bias_order + 1)]
    return np.column_stack(blocks + [np.ones(d.shape[0])] + drift)


def _press(x: np.ndarray, y: np.ndarray) -> float:
    """Leave-one-pose-out prediction error sum of squares of a linear least-squares fit (hat-matrix form)."""
    coef, *_ = np.linalg.lstsq(x, y, rcond=None)
    hat = np.einsum("ij,jk,ik->i", x, np.linalg.pinv(x.T @ x), x)
    if np.any(hat > 1 - 1e-9):
        return float("inf")
    return float(np.sum(((y - x @ coef) / (1.0 - hat)[:, None]) ** 2))


def _six_position_order(
    d: np.ndarray,
    y: np.ndarray,
    temperatures: np.ndarray | None,
    t_ref: float,
    temperature_order: int | Literal["auto"],
    bias_order: int,
) -> int:
    """0 (K constant) or 1 (K linear in temperature): as asked, or by leave-one-pose-out error when the poses
    span MIN_TRIAD_SPAN_DEGC (the lowest order within 5 % of the best)."""
    span = 0.0 if temperatures is None else float(np.ptp(temperatures))
    if temperature_order == "auto":
        if span < MIN_TRIAD_SPAN_DEGC or d.shape[0] < 14 + bias_order:
            return 0
        scores = [_press(_six_position_design(d, temperatures, q, t_ref, bias_order), y) for q in (0, 1)]
        return 1 if scores[1] < scores[0] / ORDER_TOLERANCE else 0
    if temperature_order not in (0, 1):
        raise InputError(f"temperature_order: {temperature_order!r}; use 'auto', 0 or 1")
    if temperature_order == 1 and span < MIN_TRIAD_SPAN_DEGC:
        raise InputError(
            f"temperature_order: 1 needs poses over at least {MIN_TRIAD_SPAN_DEGC:g} degC; these span {span:.1f} degC"
        )
    return temperature_order


def _fit_six_position(
    poses: list[Pose],
    means: np.ndarray,
    units: np.ndarray,
    temperature_order: int | Literal["auto"] = 0,
    bias_order: int = 0,
):
    which = _axis_assignment(units)
    missing = [_DIRECTION_NAMES[k] for k in range(6) if not np.any(which == k)]
    if missing:
        raise InputError(
            f"poses: no pose along {', '.join(missing)}; the six-position method needs the unit "
            f"resting on each of its six faces (or give {MIN_POSES_NORM} or more poses for the norm method)"
        )
    keep = which >= 0
    d = np.zeros((int(keep.sum()), 3))
    d[np.arange(d.shape[0]), which[keep] // 2] = np.where(which[keep] % 2, -1.0, 1.0)
    y = means[keep]
    temps = [p.temperature_degc for p, k in zip(poses, keep) if k]
    temperatures = None if any(t is None for t in temps) else np.asarray(temps, dtype=float)
    t_ref = 0.0 if temperatures is None else float(np.round(0.5 * (temperatures.min() + temperatures.max()), 1))
    if bias_order and (temperatures is None or np.ptp(temperatures) < MIN_TRIAD_SPAN_DEGC):
        raise InputError(
            f"bias_temperature_order: {bias_order} needs poses with temperatures over at least "
            f"{MIN_TRIAD_SPAN_DEGC:g} degC"
        )
    order = _six_position_order(d, y, temperatures, t_ref, temperature_order, bias_order)
    x = _six_position_design(d, temperatures, order, t_ref, bias_order)
    sem = np.array([p.accel_sem_g for p in poses])[keep]
    # ordinary least squares: with one pose per face and K constant this is Ferraris's closed form (b the mean
    # of the six, column k of K half the difference of +k and -k)
    coef = np.linalg.lstsq(x, y, rcond=None)[0]
    ssr = float(np.sum((y - x @ coef) ** 2))
    dof = 3 * (d.shape[0] - x.shape[1])
    red, variance = _residual_variance(ssr, dof, float(np.mean(sem**2)))
    unscaled = np.diag(np.linalg.pinv(x.T @ x))
    se = np.sqrt(np.outer(np.ones(3), unscaled) * variance)
    blocks = [coef[3 * p : 3 * p + 3].T for p in range(order + 1)]
    block_se = [se[:, 3 * p : 3 * p + 3] for p in range(order + 1)]
    constant = 3 * (order + 1)
    return SixPosition(
        coef[constant],
        blocks,
        se[:, constant],
        block_se,
        red,
        dof,
        int((~keep).sum()),
        t_ref if order or bias_order else None,
        coef[constant + 1 :],
    )


@dataclass(frozen=True)
class SixPosition:
    """What the six-position least squares finds: bias [g], K and its temperature coefficients (blocks[0] = K at
    ``reference_degc``, blocks[p] the coefficient of (T - reference)^p) with standard errors."""

    bias: np.ndarray
    blocks: list
    bias_se: np.ndarray
    blocks_se: list
    reduced_chi_square: float
    dof: int
    left_out: int
    reference_degc: float | None
    bias_drift: np.ndarray  # (bias_order, 3): coefficients of (T - reference)^p, p = 1.. [g/degC^p]


def fit_accel_multiposition(
    poses: list[Pose],
    *,
    method: PoseMethod = "auto",
    gravity_g: float = 1.0,
    temperature_order: int | Literal["auto"] = "auto",
    bias_temperature_order: int = 0,
) -> PoseFit:
    """Bias, scale factor and misalignment of an accelerometer from still poses (see the module doc).

    Parameters
    ----------
    poses : list of Pose
        From :func:`find_poses`, of one or more recordings of the same power-on.
    method : {"auto", "norm", "six-position"}
        See the module doc.
    gravity_g : float
        The norm of the specific force at rest [g]: 1.0 unless the accelerations were scaled with a
        different local gravity.
    temperature_order : int or "auto"
        Six-position method: K constant (0) or linear in temperature (1; the poses must span at least
        5 degC, each face visited across it); ``auto`` chooses by leave-one-pose-out error when the poses
        span 5 degC (the lowest order within 5 % of the best), else 0. The norm method fits K constant.
    bias_temperature_order : int
        Six-position method on poses whose bias still drifts with temperature (no temperature model removed
        it): a polynomial of this order in (T - reference) fitted alongside, in ``PoseFit.bias_drift_g``;
        the calibration keeps the constant only.

    Returns
    -------
    PoseFit
        The calibration (``correct`` gives the specific force [g]) and its residual on the poses.
    """
    means, units = _checked_poses(poses, method, gravity_g)
    method = _auto_method(units) if method == "auto" else method
    if method == "norm":
        if temperature_order not in ("auto", 0) or bias_temperature_order:
            raise InputError(
                "temperature_order: the norm method fits K constant; K(T) needs the six-position method "
                "(the unit on its six faces across the temperatures)"
            )
        return _norm_pose_fit(poses, means, units, gravity_g)
    return _six_position_pose_fit(poses, means, units, gravity_g, temperature_order, bias_temperature_order)


def _norm_pose_fit(poses: list[Pose], means: np.ndarray, units: np.ndarray, gravity_g: float) -> PoseFit:
    """The norm method's fit of the poses (their mean specific forces ``means`` [g], directions ``units``)."""
    bias, sens, bias_se, sens_se, red, dof, left = _fit_norm(poses, means, units, gravity_g)
    cal = TriadCalibration(
        sensitivity=rows_of(sens),
        bias=tuple(float(b) for b in bias),
        method="norm",
        sensitivity_stderr=rows_of(sens_se),
        bias_stderr=tuple(float(b) for b in bias_se),
        unit="g",
    )
    after = np.linalg.norm(cal.correct(means), axis=1)
    return PoseFit(cal, tuple(poses), np.linalg.norm(means, axis=1), after, red, dof, left, float(gravity_g))


def _six_position_pose_fit(
    poses: list[Pose],
    means: np.ndarray,
    units: np.ndarray,
    gravity_g: float,
    temperature_order: int | Literal["auto"],
    bias_temperature_order: int,
) -> PoseFit:
    """The six-position method's fit of the poses (their mean specific forces ``means`` [g], directions
    ``units``), K(T) of ``temperature_order`` and the bias drift of ``bias_temperature_order``."""
    fit = _fit_six_position(poses, means / gravity_g, units, temperature_order, bias_temperature_order)
    drift = fit.bias_drift * gravity_g
    blocks = fit.blocks[1:]
    cal = TriadCalibration(
        sensitivity=rows_of(fit.blocks[0]),
        bias=tuple(float(b) * gravity_g for b in fit.bias),
        method="six-position",
        sensitivity_stderr=rows_of(fit.blocks_se[0]),
        bias_stderr=tuple(float(b) * gravity_g for b in fit.bias_se),
        unit="g",
        reference_degc=fit.reference_degc if blocks else None,
        sensitivity_per_degc=tuple(rows_of(b) for b in blocks),
        sensitivity_per_degc_stderr=tuple(rows_of(b) for b in fit.blocks_se[1:]),
    )
    seen, temperatures = means, None
    if fit.reference_degc is not None:
        temperatures = np.array([p.temperature_degc for p in poses], dtype=float)
        d = temperatures - fit.reference_degc  # the pose means less the fitted drift: what the calibration sees
        seen = means - sum((np.outer(d ** (p + 1), drift[p]) for p in range(drift.shape[0])), np.zeros_like(means))
    after = cal.correct(seen, temperatures if cal.temperature_order else None)
    return PoseFit(
        cal,
        tuple(poses),
        np.linalg.norm(means, axis=1),
        np.linalg.norm(after, axis=1),
        fit.reduced_chi_square,
        fit.dof,
        fit.left_out,
        float(gravity_g),
        drift,
    )


def _checked_poses(poses: list[Pose], method: str, gravity_g: float) -> tuple[np.ndarray, np.ndarray]:
    """The poses' mean specific forces [g] and their directions, once the arguments are checked and the poses
    turn every axis up and down."""
    if method not in ("auto", "norm", "six-position"):
        raise InputError(f"method: {method!r}; use 'auto', 'norm' or 'six-position'")
    if not gravity_g > 0:
        raise InputError(f"gravity_g: {gravity_g}; must be positive")
    if len(poses) < 6:
        raise InputError(
            f"poses: {len(poses)} still poses found; a multi-position calibration needs at least 6 "
            "(each axis up and down), better 10 or more"
        )
    means = np.array([p.accel_g for p in poses], dtype=float)
    units = _directions(means)
    _require_span(units)
    return means, units


def _auto_method(units: np.ndarray) -> str:
    """``norm`` with 12 or more orientations that determine it (or 10 without the six faces), else
    ``six-position``."""
    six = bool(np.all(np.isin(np.arange(6), _axis_assignment(units))))
    distinct = distinct_orientations(units)
    norm_possible = undetermined_norm_term(units) is None or not six
    if norm_possible and (distinct >= AUTO_NORM_POSES or (not six and distinct >= MIN_POSES_NORM)):
        return "norm"
    return "six-position"


def gyro_triad(blocks, stderr, method: str, reference_degc: float) -> TriadCalibration:
    """A gyro triad's scale factor and misalignment K(T) [1, 1/degC^p] from its fitted blocks (K at the reference
    temperature, then each power of (T - ``reference_degc``)) and their standard errors; no bias (each run keeps its
    own)."""
    return TriadCalibration(
        sensitivity=rows_of(blocks[0]),
        bias=(0.0, 0.0, 0.0),
        method=method,
        sensitivity_stderr=rows_of(stderr[0]),
        bias_stderr=(0.0, 0.0, 0.0),
        unit="deg/s",
        reference_degc=reference_degc if len(blocks) > 1 else None,
        sensitivity_per_degc=tuple(rows_of(b) for b in blocks[1:]),
        sensitivity_per_degc_stderr=tuple(rows_of(b) for b in stderr[1:]),
    )


def rq_upper(sensitivity: np.ndarray) -> np.ndarray:
    """The upper-triangular factor R (positive diagonal) of K = R Q: the K the norm method can see of a
    triad whose true K is ``sensitivity`` (the rest is a rotation of the reference frame)."""
    from scipy import linalg  # slow to import; only this decomposition needs it

    r, q = linalg.rq(np.asarray(sensitivity, dtype=float))
    signs = np.sign(np.diag(r))
    return r * signs[None, :]


__all__ = [
    "AUTO_NORM_POSES",
    "MIN_POSES_NORM",
    "Pose",
    "PoseFit",
    "PoseMethod",
    "distinct_orientations",
    "find_poses",
    "spans_axes",
    "fit_accel_multiposition",
    "gyro_triad",
    "propagate_stderr",
    "rq_upper",
    "undetermined_norm_term",
]
