"""The error model of a simulated gyro (and its accelerometer), and the random errors.

Output of gyro axis i, sample k (every term switchable; units in brackets):

    w_out = Q_lsb( w_i + (s_i + c_i (T_s - T_ref)) 1e-6 w_i + sum_{j != i} M_ij w_j      scale factor, misalignment
                   + b0_i + p_i(T_s - T_ref)                                            turn-on bias, temperature
                   + h_i(|T_s - T_turn|)   (after a reversal, chosen branches/band)     hysteresis
                   + sum_j G_ij a_j + sum_m Q_im (a a)_m                               g and g x g sensitivity
                   + n_white + n_flicker + n_rrw )                                      noise

with w the true body rate [deg/s], a the specific force [g], T_s the temperature of the MEMS
structure, which lags the reported temperature T through a first-order time constant [s], and
Q_lsb rounding to the output LSB. The reported temperature itself gets the sensor's noise and
quantization (some parts report whole degrees).

Noise terms follow IEEE Std 952-1997 Annex C. For rate samples taken every dt = 1/rate_hz:

- angle random walk N [deg/s/sqrt(Hz)]: white noise of standard deviation N sqrt(rate_hz);
  Allan variance N^2 / tau;
- bias instability B [deg/h]: flicker noise with one-sided PSD B^2 / (pi f), built as a bank of
  first-order Gauss-Markov processes with log-spaced correlation times T_i = T_0 r^i, each of
  variance (B^2 / pi) ln r, whose PSDs add up to 1/f between the bank's corner frequencies
  (dt/2 up to ten times the run, so the floor stays flat from 2 samples to the longest tau); the slow
  processes are drawn on coarser grids (50 steps per correlation time) and interpolated, which
  keeps a 24-hour 100 Hz run to seconds; Allan floor (2 ln 2 / pi)^(1/2) B = 0.664 B;
- rate random walk K [deg/s/sqrt(s)]: integrated white noise, Allan variance K^2 tau / 3.

What real logs show beyond these (the real one-cycle chamber log of ``tofupilot-imu-thermal``: after a cubic in
temperature fitted on the whole run, its axes keep 0.05-0.23 deg/s of drift, correlated over 200-500 s, that no
temperature curve follows), each off by default:

- a non-repeatable drift per power-on: sigma_d h(t) + sigma_c g(t) (T_s - T_ref), h and g independent smooth
  stationary processes of unit variance (two first-order lags of time constant T_d in cascade, driven by white
  noise), so that part of the drift follows the temperature, by a relation that differs from run to run and
  wanders within one;
- a warm-up transient after power-on: A exp(-t / T_w), A drawn per power-on with standard deviation sigma_w;
- a bias that depends on the rate of change of the structure temperature: k_i dT_s/dt (a thermal gradient across
  the die while it heats or cools), deterministic, so that heating and cooling differ by 2 k_i times the ramp rate.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import asdict, dataclass, field

import numpy as np

from ..effects import (
    HYSTERESIS_DIRECTIONS,
    branch_position,
    find_turns,
    g_sensitivity_offset,
    hysteresis_offset,
    lazy_lfilter,
    thermal_lag,
)
from ..errors import InputError
from ..recording import GYRO_AXES
from ..units import DEG_PER_S_TO_DEG_PER_H

GM_RATIO = 3.0  # spacing of the Gauss-Markov correlation times
GM_STEPS_PER_TIME_CONSTANT = 50  # grid of the slow Gauss-Markov processes
GM_LONGEST_PER_RUN = 10.0  # longest correlation time, in run lengths
#: turning points of the (noise-free) structure temperature are confirmed past this [degC],
#: which only keeps round-off in the lag filter from making reversals
TURN_THRESHOLD_DEGC = 1e-6


@dataclass(frozen=True)
class Hysteresis:
    """Offset on the temperature branch after a reversal (thesis section 2.6).

    Parameters
    ----------
    coefficients_dps : tuple of tuples
        Per gyro axis, h_1..h_p of offset = sum_j h_j |T_s - T_turn|^j [deg/s/degC^j].
    direction : {"descending", "ascending", "both"}
        Branches that carry the offset.
    band_degc : (lo, hi), optional
        Structure-temperature band [degC] outside which there is none.
    fade_degc : float, optional
        A bump instead of the polynomial: per axis h_1 (1 - exp(-8 d / F)) (1 - d / F)^2 for d < F, zero beyond
        (F = ``fade_degc``): it starts at the turning point, peaks about F / 5 after it and fades out smoothly over
        F degrees; only h_1 [deg/s] of each axis is read. A shape the turning-point polynomial only approximates.
    transition_degc : float, optional
        Heating and cooling branches instead: per axis the half difference between the heating and the cooling
        curve, sum_k h_k (T_s - T_ref)^k with k from 0 [deg/s/degC^k], times the branch position
        (:func:`gyrocomp.effects.branch_position`, crossing over within about ``transition_degc`` after each
        turn); ``direction`` and ``band_degc`` are not read.
    """

    coefficients_dps: tuple[tuple[float, ...], ...]
    direction: str = "descending"
    band_degc: tuple[float, float] | None = None
    fade_degc: float | None = None
    transition_degc: float | None = None

    def __post_init__(self) -> None:
        if self.direction not in HYSTERESIS_DIRECTIONS:
            raise InputError(f"hysteresis direction: {self.direction!r}; use one of {', '.join(HYSTERESIS_DIRECTIONS)}")
        if self.band_degc is not None and not self.band_degc[0] < self.band_degc[1]:
            raise InputError(f"hysteresis band_degc: {self.band_degc}; give (low, high) with low < high")
        if self.fade_degc is not None and not 0 < self.fade_degc < math.inf:
            raise InputError(f"hysteresis fade_degc: must be positive and finite, got {self.fade_degc}")
        if self.transition_degc is not None and not 0 < self.transition_degc < math.inf:
            raise InputError(f"hysteresis transition_degc: must be positive and finite, got {self.transition_degc}")

    def offset_dps(self, d_degc: np.ndarray, coefficients_dps: tuple[float, ...]) -> np.ndarray:
        """The offset at distance ``d_degc`` from the turning point [degC] on a branch that carries it [deg/s]."""
        d = np.asarray(d_degc, dtype=float)
        if self.fade_degc is None:
            out = np.zeros_like(d)
            for h in reversed(tuple(coefficients_dps)):
                out = (out + h) * d
            return out
        f = self.fade_degc
        return np.where(d < f, coefficients_dps[0] * (1 - np.exp(-8 * d / f)) * (1 - d / f) ** 2, 0.0)


@dataclass(frozen=True)
class AccelErrorModel:
    """Errors of the accelerometer triad (x, y, z).

    Parameters
    ----------
    bias_g : 3 floats
        Constant bias [g].
    bias_tempco_g_per_degc : 3 floats
        Bias change per degree of structure temperature from the gyro's T_ref [g/degC].
    noise_density_g_per_sqrt_hz : float
        White noise (velocity random walk) [g/sqrt(Hz)].
    quantization_g : float
        Output LSB [g]; 0 for none.
    scale_misalignment : 3 rows of 3 floats, optional
        E of the output a_out = (I + E) f + bias + noise: scale-factor errors on the diagonal,
        axis misalignments (cross-coupling) off it [dimensionless]; None for a perfect triad.
    scale_misalignment_per_degc : 3 rows of 3 floats, optional
        E1 of E(T) = E + E1 (T_s - T_ref), structure temperature from the gyro's T_ref [1/degC]; None for
        none.
    """

    bias_g: tuple[float, float, float] = (0.0, 0.0, 0.0)
    bias_tempco_g_per_degc: tuple[float, float, float] = (0.0, 0.0, 0.0)
    noise_density_g_per_sqrt_hz: float = 0.0
    quantization_g: float = 0.0
    scale_misalignment: tuple[tuple[float, float, float], ...] | None = None
    scale_misalignment_per_degc: tuple[tuple[float, float, float], ...] | None = None

    def __post_init__(self) -> None:
        for name in ("scale_misalignment", "scale_misalignment_per_degc"):
            value = getattr(self, name)
            if value is not None and np.shape(value) != (3, 3):
                raise InputError(f"{name}: shape {np.shape(value)}; give 3 rows of 3 values")

    @property
    def sensitivity(self) -> np.ndarray:
        """K = I + E, the matrix the triad applies to the specific force (3, 3) [dimensionless]."""
        e = np.zeros((3, 3)) if self.scale_misalignment is None else np.asarray(self.scale_misalignment, dtype=float)
        return np.eye(3) + e

    @property
    def sensitivity_per_degc(self) -> np.ndarray:
        """E1, the change of K per degree of structure temperature (3, 3) [1/degC]."""
        e1 = self.scale_misalignment_per_degc
        return np.zeros((3, 3)) if e1 is None else np.asarray(e1, dtype=float)


def _per_axis(name: str, value, k: int, width: int | None = None) -> np.ndarray | None:
    if value is None:
        return None
    arr = np.asarray(value, dtype=float)
    shape = (k,) if width is None else (k, width)
    if arr.shape != shape:
        raise InputError(f"{name}: shape {arr.shape}, expected {shape} (one entry per gyro axis)")
    return arr


@dataclass(frozen=True)
class GyroErrorModel:
    """Error parameters of a gyro, per axis (see the module doc for the equation).

    Parameters
    ----------
    axes : tuple of str
        Gyro axes simulated, e.g. ``("gyro_z",)``.
    temperature_coefficients : tuple of tuples
        Per axis, coefficients of (T_s - t_ref_degc)^k for k = 1, 2, ... [deg/s/degC^k].
    t_ref_degc : float
        Reference temperature [degC].
    thermal_time_constant_s : float
        Lag of the structure temperature behind the reported one [s]; 0 for none.
    hysteresis : Hysteresis, optional
    g_sensitivity_dps_per_g : tuple of 3-tuples, optional
        Per axis, the row of the g-sensitivity matrix G [deg/s/g].
    g_squared_dps_per_g2 : tuple of 6-tuples, optional
        Per axis, g x g sensitivities to xx, yy, zz, xy, xz, yz [deg/s/g^2].
    scale_factor_error_ppm : tuple of float, optional
        Per axis, scale factor error at t_ref [ppm].
    scale_factor_tempco_ppm_per_degc : tuple of float, optional
        Per axis, its temperature coefficient [ppm/degC].
    misalignment_rad : tuple of 3-tuples, optional
        Per axis, sensitivity to the body rates about x, y, z [rad]; the entry of the axis itself is ignored.
    turn_on_bias_sigma_dps : float
        Standard deviation of the random constant bias of each power-on [deg/s].
    noise_density_dps_per_sqrt_hz : float
        Angle random walk N [deg/s/sqrt(Hz)].
    bias_instability_deg_per_h : float
        Bias instability B [deg/h].
    rate_random_walk_dps_per_sqrt_s : float
        Rate random walk K [deg/s/sqrt(s)].
    quantization_dps : float
        Output LSB [deg/s]; 0 for none.
    temperature_noise_degc : float
        Standard deviation of the temperature sensor's white noise [degC].
    temperature_quantization_degc : float
        Temperature output LSB [degC] (1.0: whole degrees); 0 for none.
    accelerometer : AccelErrorModel, optional
        None for a part without accelerometer (no accel columns are written).
    run_drift_dps : float
        Standard deviation of the non-repeatable smooth drift of each power-on, sigma_d [deg/s].
    run_tempco_sigma_dps_per_degc : float
        Standard deviation of the non-repeatable temperature coefficient, sigma_c [deg/s/degC]: a relation to the
        temperature that differs from run to run and wanders within one.
    run_drift_time_s : float
        Time constant T_d of both non-repeatable processes [s].
    warm_up_sigma_dps : float
        Standard deviation of the amplitude of the warm-up transient after power-on, sigma_w [deg/s].
    warm_up_time_s : float
        Its time constant T_w [s].
    temperature_rate_dps_per_degc_per_min : tuple of float, optional
        Per axis, the bias per unit rate of change of the structure temperature, k_i [deg/s per degC/min].
    noise_tempco_per_degc : float
        The white noise's and the flicker's relative change per degC of the structure temperature from
        ``t_ref_degc``, c [1/degC]: both are scaled by max(0.1, 1 + c (T - t_ref)) (0: noise that does not change
        with temperature).
    """

    axes: tuple[str, ...] = GYRO_AXES
    temperature_coefficients: tuple[tuple[float, ...], ...] = (
        (4e-4, 6e-6, -8e-8),
        (-3e-4, 4e-6, 5e-8),
        (5e-4, -5e-6, 6e-8),
    )
    t_ref_degc: float = 25.0
    thermal_time_constant_s: float = 0.0
    hysteresis: Hysteresis | None = None
    g_sensitivity_dps_per_g: tuple[tuple[float, float, float], ...] | None = None
    g_squared_dps_per_g2: tuple[tuple[float, ...], ...] | None = None
    scale_factor_error_ppm: tuple[float, ...] | None = None
    scale_factor_tempco_ppm_per_degc: tuple[float, ...] | None = None
    misalignment_rad: tuple[tuple[float, float, float], ...] | None = None
    turn_on_bias_sigma_dps: float = 0.02
    noise_density_dps_per_sqrt_hz: float = 0.01
    bias_instability_deg_per_h: float = 10.0
    rate_random_walk_dps_per_sqrt_s: float = 0.0
    quantization_dps: float = 0.0
    temperature_noise_degc: float = 0.0
    temperature_quantization_degc: float = 0.0
    accelerometer: AccelErrorModel | None = field(default_factory=AccelErrorModel)
    run_drift_dps: float = 0.0
    run_tempco_sigma_dps_per_degc: float = 0.0
    run_drift_time_s: float = 600.0
    warm_up_sigma_dps: float = 0.0
    warm_up_time_s: float = 300.0
    temperature_rate_dps_per_degc_per_min: tuple[float, ...] | None = None
    noise_tempco_per_degc: float = 0.0

    def noise_scale(self, structure_degc) -> np.ndarray:
        """The factor on the white noise and flicker at ``structure_degc`` [degC] (see ``noise_tempco_per_degc``)."""
        above = np.asarray(structure_degc, dtype=float) - self.t_ref_degc
        return np.maximum(0.1, 1.0 + self.noise_tempco_per_degc * above)

    def __post_init__(self) -> None:
        k = len(self.axes)
        if not k or any(a not in GYRO_AXES for a in self.axes) or len(set(self.axes)) != k:
            raise InputError(f"axes: {self.axes}; use distinct names from {', '.join(GYRO_AXES)}")
        if len(self.temperature_coefficients) != k:
            raise InputError(f"temperature_coefficients: {len(self.temperature_coefficients)} sets for {k} axes")
        for name in (
            "turn_on_bias_sigma_dps",
            "noise_density_dps_per_sqrt_hz",
            "bias_instability_deg_per_h",
            "rate_random_walk_dps_per_sqrt_s",
            "quantization_dps",
            "temperature_noise_degc",
            "temperature_quantization_degc",
            "thermal_time_constant_s",
            "run_drift_dps",
            "run_tempco_sigma_dps_per_degc",
            "warm_up_sigma_dps",
        ):
            if getattr(self, name) < 0:
                raise InputError(f"{name}: must not be negative")
        if not math.isfinite(self.noise_tempco_per_degc):
            raise InputError(f"noise_tempco_per_degc: must be finite, got {self.noise_tempco_per_degc}")
        for name in ("run_drift_time_s", "warm_up_time_s"):
            if not 0 < getattr(self, name) < math.inf:
                raise InputError(f"{name}: must be positive and finite, got {getattr(self, name)}")
        _per_axis("temperature_rate_dps_per_degc_per_min", self.temperature_rate_dps_per_degc_per_min, k)
        _per_axis("g_sensitivity_dps_per_g", self.g_sensitivity_dps_per_g, k, 3)
        _per_axis("g_squared_dps_per_g2", self.g_squared_dps_per_g2, k, 6)
        _per_axis("scale_factor_error_ppm", self.scale_factor_error_ppm, k)
        _per_axis("scale_factor_tempco_ppm_per_degc", self.scale_factor_tempco_ppm_per_degc, k)
        _per_axis("misalignment_rad", self.misalignment_rad, k, 3)
        if self.hysteresis is not None and len(self.hysteresis.coefficients_dps) != k:
            raise InputError(f"hysteresis coefficients_dps: {len(self.hysteresis.coefficients_dps)} sets for {k} axes")

    @property
    def body_index(self) -> list[int]:
        """Index (0, 1, 2 for x, y, z) of each simulated axis in the body frame."""
        return [GYRO_AXES.index(a) for a in self.axes]

    # -- deterministic effects (pure functions of the trajectory) ---------------------------------
    def temperature_error_dps(self, temperature_degc: np.ndarray) -> np.ndarray:
        """Temperature bias (n, k) [deg/s] at the structure temperature (without the turn-on constant)."""
        d = np.asarray(temperature_degc, dtype=float) - self.t_ref_degc
        cols = []
        for coefs in self.temperature_coefficients:
            out = np.zeros_like(d)
            for c in reversed(coefs):
                out = (out + c) * d
            cols.append(out)
        return np.column_stack(cols)

    def hysteresis_error_dps(self, structure_degc: np.ndarray) -> np.ndarray:
        """Hysteresis offset (n, k) [deg/s] of the structure-temperature history."""
        n, k = structure_degc.size, len(self.axes)
        if self.hysteresis is None:
            return np.zeros((n, k))
        turns = find_turns(structure_degc, TURN_THRESHOLD_DEGC)
        h = self.hysteresis
        if h.transition_degc is not None:  # heating and cooling branches
            position = branch_position(structure_degc, turns, h.transition_degc)
            dt = structure_degc - self.t_ref_degc
            return np.column_stack(
                [position * sum(c * dt**k for k, c in enumerate(coefs)) for coefs in h.coefficients_dps]
            )
        # the distance from the turning point on the branches that carry the offset (zero elsewhere), then its shape
        d = hysteresis_offset(structure_degc, turns, (1.0,), direction=h.direction, band_degc=h.band_degc)
        return np.column_stack([np.where(d > 0, h.offset_dps(d, c), 0.0) for c in h.coefficients_dps])

    def temperature_rate_error_dps(self, time_s: np.ndarray, structure_degc: np.ndarray) -> np.ndarray:
        """Bias from the rate of change of the structure temperature (n, k) [deg/s]: k_i dT_s/dt, the rate in
        degC/min."""
        n, k = structure_degc.size, len(self.axes)
        if self.temperature_rate_dps_per_degc_per_min is None or n < 2:
            return np.zeros((n, k))
        rate_per_min = np.gradient(structure_degc, time_s) * 60.0
        return np.outer(rate_per_min, np.asarray(self.temperature_rate_dps_per_degc_per_min, dtype=float))

    def acceleration_error_dps(self, specific_force_g: np.ndarray) -> np.ndarray:
        """g and g x g sensitive bias (n, k) [deg/s]."""
        k = len(self.axes)
        if self.g_sensitivity_dps_per_g is None and self.g_squared_dps_per_g2 is None:
            return np.zeros((specific_force_g.shape[0], k))
        g = np.zeros((k, 3)) if self.g_sensitivity_dps_per_g is None else np.asarray(self.g_sensitivity_dps_per_g)
        q = None if self.g_squared_dps_per_g2 is None else np.asarray(self.g_squared_dps_per_g2)
        return g_sensitivity_offset(specific_force_g, g, q)

    def scale_error_dps(self, angular_rate_dps: np.ndarray, structure_degc: np.ndarray) -> np.ndarray:
        """Scale factor and misalignment error on the true rate (n, k) [deg/s]."""
        n, k = angular_rate_dps.shape[0], len(self.axes)
        out = np.zeros((n, k))
        if not np.any(angular_rate_dps):
            return out
        own = angular_rate_dps[:, self.body_index]
        if self.scale_factor_error_ppm is not None:
            out += own * np.asarray(self.scale_factor_error_ppm) * 1e-6
        if self.scale_factor_tempco_ppm_per_degc is not None:
            out += (
                own
                * np.outer(structure_degc - self.t_ref_degc, np.asarray(self.scale_factor_tempco_ppm_per_degc))
                * 1e-6
            )
        if self.misalignment_rad is not None:
            m = np.array(self.misalignment_rad, dtype=float)
            m[np.arange(k), self.body_index] = 0.0
            out += angular_rate_dps @ m.T
        return out

    def without(self, *terms: str) -> "GyroErrorModel":
        """The same part with the named terms switched off (see ``SWITCHABLE_TERMS``)."""
        unknown = [t for t in terms if t not in SWITCHABLE_TERMS]
        if unknown:
            raise InputError(f"disable: unknown term {unknown[0]!r}; use any of {', '.join(SWITCHABLE_TERMS)}")
        changes: dict = {}
        for term in terms:
            changes.update(SWITCHABLE_TERMS[term](self))
        return dataclasses.replace(self, **changes)

    def subset(self, axes: tuple[str, ...]) -> "GyroErrorModel":
        """The same part with only ``axes`` simulated (every per-axis parameter picked accordingly)."""
        missing = [a for a in axes if a not in self.axes]
        if missing or not axes:
            raise InputError(f"axes: {', '.join(missing) or 'none given'}; this part has {', '.join(self.axes)}")
        idx = [self.axes.index(a) for a in axes]
        pick = lambda rows: None if rows is None else tuple(rows[i] for i in idx)  # noqa: E731
        hyst = self.hysteresis
        if hyst is not None:
            hyst = dataclasses.replace(hyst, coefficients_dps=pick(hyst.coefficients_dps))
        return dataclasses.replace(
            self,
            axes=tuple(axes),
            temperature_coefficients=pick(self.temperature_coefficients),
            hysteresis=hyst,
            g_sensitivity_dps_per_g=pick(self.g_sensitivity_dps_per_g),
            g_squared_dps_per_g2=pick(self.g_squared_dps_per_g2),
            scale_factor_error_ppm=pick(self.scale_factor_error_ppm),
            scale_factor_tempco_ppm_per_degc=pick(self.scale_factor_tempco_ppm_per_degc),
            misalignment_rad=pick(self.misalignment_rad),
        )

    def to_dict(self) -> dict:
        return asdict(self)


#: what ``GyroErrorModel.without`` (and ``gyrocomp simulate --disable``) can switch off
SWITCHABLE_TERMS = {
    "temperature": lambda m: {
        "temperature_coefficients": tuple((0.0,) for _ in m.axes),
        "temperature_rate_dps_per_degc_per_min": None,
    },
    "lag": lambda m: {"thermal_time_constant_s": 0.0},
    "hysteresis": lambda m: {"hysteresis": None},
    "g-sensitivity": lambda m: {"g_sensitivity_dps_per_g": None, "g_squared_dps_per_g2": None},
    "scale-factor": lambda m: {"scale_factor_error_ppm": None, "scale_factor_tempco_ppm_per_degc": None},
    "misalignment": lambda m: {"misalignment_rad": None},
    "turn-on": lambda m: {"turn_on_bias_sigma_dps": 0.0},
    "noise": lambda m: {
        "noise_density_dps_per_sqrt_hz": 0.0,
        "bias_instability_deg_per_h": 0.0,
        "rate_random_walk_dps_per_sqrt_s": 0.0,
    },
    "quantization": lambda m: {"quantization_dps": 0.0, "temperature_quantization_degc": 0.0},
    "temperature-noise": lambda m: {"temperature_noise_degc": 0.0},
    "drift": lambda m: {"run_drift_dps": 0.0, "run_tempco_sigma_dps_per_degc": 0.0},
    "warm-up": lambda m: {"warm_up_sigma_dps": 0.0},
    "temperature-rate": lambda m: {"temperature_rate_dps_per_degc_per_min": None},
}


@dataclass(frozen=True)
class NoiseTruth:
    """The random errors that were added, per axis (n, k) [deg/s]; quantization is the rounding of the output;
    ``drift_dps`` the non-repeatable drift and ``warm_up_dps`` the warm-up transient of this power-on (None where
    the part has none)."""

    white_dps: np.ndarray = field(repr=False)
    flicker_dps: np.ndarray = field(repr=False)
    random_walk_dps: np.ndarray = field(repr=False)
    quantization_dps: np.ndarray | None = field(default=None, repr=False)
    drift_dps: np.ndarray | None = field(default=None, repr=False)
    warm_up_dps: np.ndarray | None = field(default=None, repr=False)

    @property
    def total_dps(self) -> np.ndarray:
        total = self.white_dps + self.flicker_dps + self.random_walk_dps
        for extra in (self.quantization_dps, self.drift_dps, self.warm_up_dps):
            if extra is not None:
                total = total + extra
        return total

    def take(self, index) -> "NoiseTruth":
        pick = lambda a: None if a is None else a[index]  # noqa: E731
        return NoiseTruth(
            self.white_dps[index],
            self.flicker_dps[index],
            self.random_walk_dps[index],
            pick(self.quantization_dps),
            pick(self.drift_dps),
            pick(self.warm_up_dps),
        )


def _gauss_markov(
    m: int, step_s: float, time_constant_s: float, variance: float, rng: np.random.Generator
) -> np.ndarray:
    """A stationary first-order Gauss-Markov process of ``m`` samples ``step_s`` apart."""
    phi = math.exp(-step_s / time_constant_s)
    drive = rng.standard_normal(m) * math.sqrt(variance * -math.expm1(-2.0 * step_s / time_constant_s))
    drive[0] = rng.standard_normal() * math.sqrt(variance)  # start in the stationary distribution
    return lazy_lfilter([1.0], [1.0, -phi], drive)


def flicker_bank(
    n: int,
    rate_hz: float,
    bias_instability_deg_per_h: float,
    rng: np.random.Generator,
    shortest_s: float | None = None,
    longest_s: float | None = None,
) -> np.ndarray:
    """Flicker (bias instability) noise [deg/s] from a bank of Gauss-Markov processes (see module doc).

    Processes whose correlation time spans more than ``GM_STEPS_PER_TIME_CONSTANT`` samples are
    drawn on a grid of 4^j samples (the coarsest that keeps that many steps per correlation time)
    and the slow part is built coarse to fine, interpolating linearly once per level.
    """
    if bias_instability_deg_per_h == 0 or n == 0:
        return np.zeros(n)
    dt = 1.0 / rate_hz
    b_dps = bias_instability_deg_per_h / DEG_PER_S_TO_DEG_PER_H
    shortest = shortest_s or 0.5 * dt
    longest = longest_s or max(GM_LONGEST_PER_RUN * n * dt, shortest * GM_RATIO)
    count = int(math.ceil(math.log(longest / shortest) / math.log(GM_RATIO))) + 1
    variance = b_dps**2 / math.pi * math.log(GM_RATIO)
    levels: dict[int, list[float]] = {}
    for i in range(count):
        tc = shortest * GM_RATIO**i
        steps = tc / (GM_STEPS_PER_TIME_CONSTANT * dt)
        level = 0 if steps < 4 else int(math.log(steps, 4))
        while 4**level > max(1, (n - 1) // 2):  # keep at least three nodes on the grid
            level -= 1
        levels.setdefault(max(level, 0), []).append(tc)
    acc: np.ndarray | None = None
    acc_step = 0
    for level in sorted(levels, reverse=True):
        step = 4**level
        m = (n - 1 + step - 1) // step + 1  # nodes 0, step, ..., covering n - 1
        here = np.zeros(m)
        for tc in levels[level]:
            here += _gauss_markov(m, step * dt, tc, variance, rng)
        if acc is not None:
            here += np.interp(np.arange(m) * step, np.arange(acc.size) * acc_step, acc)
        acc, acc_step = here, step
    if acc_step != 1:
        acc = np.interp(np.arange(n), np.arange(acc.size) * acc_step, acc)
    return acc[:n]


def smooth_process(n: int, rate_hz: float, time_constant_s: float, rng: np.random.Generator) -> np.ndarray:
    """A stationary smooth random process of unit variance [dimensionless], ``n`` samples at ``rate_hz`` [Hz]:
    white noise through two first-order lags of time constant ``time_constant_s`` [s] in cascade (a critically
    damped second-order Gauss-Markov process, whose variogram grows as dt^2 well below the time constant and levels
    off above it), drawn on a grid of :data:`GM_STEPS_PER_TIME_CONSTANT` steps per time constant from a start
    ten time constants earlier and interpolated.

    With phi = exp(-step / T), the cascade's impulse response is (j + 1) phi^j, whose squares sum to
    (1 + phi^2) / (1 - phi^2)^3: the drive is scaled by the inverse of its square root."""
    if n == 0:
        return np.zeros(0)
    dt = 1.0 / rate_hz
    step = min(time_constant_s / GM_STEPS_PER_TIME_CONSTANT, max(dt * (n - 1), dt))
    step = max(step, dt)
    burn = int(math.ceil(10 * time_constant_s / step))
    m = int(math.ceil((n - 1) * dt / step)) + 1
    phi = math.exp(-step / time_constant_s)
    drive = rng.standard_normal(burn + m) * math.sqrt((1 - phi**2) ** 3 / (1 + phi**2))
    coarse = lazy_lfilter([1.0], [1.0, -phi], lazy_lfilter([1.0], [1.0, -phi], drive))[burn:]
    return np.interp(np.arange(n) * dt, np.arange(m) * step, coarse)


def simulate_noise(
    n: int, rate_hz: float, model: GyroErrorModel, rng: np.random.Generator, structure_degc: np.ndarray | None = None
) -> NoiseTruth:
    """Draw the random errors of every axis (without quantization, which depends on the output); the
    non-repeatable drift's temperature part reads ``structure_degc`` [degC] (the reference temperature where it is
    not given)."""
    k = len(model.axes)
    white = rng.standard_normal((n, k)) * model.noise_density_dps_per_sqrt_hz * math.sqrt(rate_hz)
    flicker = np.column_stack([flicker_bank(n, rate_hz, model.bias_instability_deg_per_h, rng) for _ in range(k)])
    if model.noise_tempco_per_degc != 0.0 and structure_degc is not None:
        scale = model.noise_scale(structure_degc)[:, None]
        white, flicker = white * scale, flicker * scale
    if model.rate_random_walk_dps_per_sqrt_s > 0:
        steps = rng.standard_normal((n, k)) * model.rate_random_walk_dps_per_sqrt_s * math.sqrt(1.0 / rate_hz)
        walk = np.cumsum(steps, axis=0)
    else:
        walk = np.zeros((n, k))
    drift = warm_up = None
    if model.run_drift_dps > 0 or model.run_tempco_sigma_dps_per_degc > 0:
        above = np.zeros(n) if structure_degc is None else np.asarray(structure_degc, dtype=float) - model.t_ref_degc
        drift = np.column_stack(
            [
                model.run_drift_dps * smooth_process(n, rate_hz, model.run_drift_time_s, rng)
                + model.run_tempco_sigma_dps_per_degc * smooth_process(n, rate_hz, model.run_drift_time_s, rng) * above
                for _ in range(k)
            ]
        )
    if model.warm_up_sigma_dps > 0:
        amplitude = rng.standard_normal(k) * model.warm_up_sigma_dps
        warm_up = np.outer(np.exp(-np.arange(n) / rate_hz / model.warm_up_time_s), amplitude)
    return NoiseTruth(white, flicker, walk, None, drift, warm_up)


def structure_temperature(
    model: GyroErrorModel, time_s: np.ndarray, temperature_degc: np.ndarray, rate_hz: float
) -> np.ndarray:
    """Temperature of the MEMS structure [degC]: the reported temperature through the thermal lag."""
    lagged, _ = thermal_lag(time_s, temperature_degc, model.thermal_time_constant_s, period_s=1.0 / rate_hz)
    return lagged
