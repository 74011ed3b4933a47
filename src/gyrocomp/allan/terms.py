"""IEEE Std 952-1997 (Annex C) noise terms read from, and fitted to, an Allan deviation curve."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..errors import InputError
from ..units import STANDARD_GRAVITY_M_PER_S2
from .estimators import AllanResult

#: the flicker (bias instability) floor of the Allan deviation is B sqrt(2 ln2 / pi) = 0.664 B
BIAS_INSTABILITY_FACTOR = math.sqrt(2.0 * math.log(2.0) / math.pi)
#: how far a local log-log slope may be from -1/2 (or +1/2) for a read-off on that line
READOFF_SLOPE_TOLERANCE = 0.25
#: relative uncertainty in variance below which no point of the curve is weighted in the noise fit
MODEL_UNCERTAINTY = 0.1


@dataclass(frozen=True)
class NoiseTerms:
    """The five IEEE Std 952 (Annex C) terms in the unit u of the data (u = deg/s for gyros, g for
    accelerometers), and the read-offs users compare them with.

    Attributes
    ----------
    quantization : float
        Q [u*s], from 3 Q^2 / tau^2.
    white_noise_density : float
        N [u/sqrt(Hz)] (= u*sqrt(s)), from N^2 / tau.
    bias_instability : float
        B [u]: the Allan minimum / 0.664 (the definition the thesis and datasheets use).
    integration_time_s : float
        tau at that minimum [s].
    random_walk : float
        K [u*sqrt(Hz)] (= u/sqrt(s)), from K^2 tau / 3.
    ramp : float
        R [u/s], from R^2 tau^2 / 2.
    bias_instability_fit : float
        B [u] from the weighted least-squares fit of the five-term model.
    white_noise_readoff, random_walk_readoff : float or None
        N read on the -1/2 line at tau = 1 s and K on the +1/2 line at tau = 3 s, through the point whose
        local slope is closest to the line's (None when no slope is within 0.25 of it).
    floor_reached : bool
        False when the smallest deviation is at the longest tau, so B is only an upper bound.
    fit_rms_log_residual : float
        RMS of ln(model deviation / measured deviation) over the fitted taus: 0.1 is a 10 % misfit.
    """

    quantization: float
    white_noise_density: float
    bias_instability: float
    integration_time_s: float
    random_walk: float
    ramp: float
    bias_instability_fit: float
    white_noise_readoff: float | None
    random_walk_readoff: float | None
    floor_reached: bool
    fit_rms_log_residual: float

    def model_deviation(self, tau_s) -> np.ndarray:
        """The fitted five-term model's deviation at ``tau_s`` [s], in the data's unit."""
        coefficients = (
            np.array(
                [self.quantization, self.white_noise_density, self.bias_instability_fit, self.random_walk, self.ramp]
            )
            ** 2
        )
        return np.sqrt(_model_basis(np.asarray(tau_s, dtype=float)) @ coefficients)


@dataclass(frozen=True)
class GyroNoise:
    """Gyro noise parameters in the units they are quoted in (see :class:`NoiseTerms`)."""

    noise_density_dps_per_sqrt_hz: float
    arw_deg_per_sqrt_h: float
    bias_instability_deg_per_h: float
    integration_time_s: float
    rrw_deg_per_h_per_sqrt_h: float
    rrw_dps_sqrt_hz: float
    quantization_deg: float
    rate_ramp_deg_per_h2: float
    bias_instability_fit_deg_per_h: float
    noise_density_readoff_dps_per_sqrt_hz: float | None
    rrw_readoff_deg_per_h_per_sqrt_h: float | None
    floor_reached: bool
    fit_rms_log_residual: float

    #: the keys of ``gyrocomp allan --json``
    SUMMARY_KEYS = (
        "noise_density_dps_per_sqrt_hz",
        "arw_deg_per_sqrt_h",
        "bias_instability_deg_per_h",
        "integration_time_s",
        "rrw_deg_per_h_per_sqrt_h",
        "quantization_deg",
        "rate_ramp_deg_per_h2",
    )

    @classmethod
    def from_terms(cls, t: NoiseTerms) -> "GyroNoise":
        """Convert terms of [deg/s] data."""
        readoff_k = None if t.random_walk_readoff is None else t.random_walk_readoff * 216000.0
        return cls(
            noise_density_dps_per_sqrt_hz=t.white_noise_density,
            arw_deg_per_sqrt_h=t.white_noise_density * 60.0,
            bias_instability_deg_per_h=t.bias_instability * 3600.0,
            integration_time_s=t.integration_time_s,
            rrw_deg_per_h_per_sqrt_h=t.random_walk * 216000.0,  # 3600 [deg/h per deg/s] * 60 [sqrt(s/h)]
            rrw_dps_sqrt_hz=t.random_walk,
            quantization_deg=t.quantization,
            rate_ramp_deg_per_h2=t.ramp * 3600.0**2,
            bias_instability_fit_deg_per_h=t.bias_instability_fit * 3600.0,
            noise_density_readoff_dps_per_sqrt_hz=t.white_noise_readoff,
            rrw_readoff_deg_per_h_per_sqrt_h=readoff_k,
            floor_reached=t.floor_reached,
            fit_rms_log_residual=t.fit_rms_log_residual,
        )

    def summary(self) -> dict:
        return {k: getattr(self, k) for k in self.SUMMARY_KEYS}


@dataclass(frozen=True)
class AccelNoise:
    """Accelerometer noise parameters in the units they are quoted in (see :class:`NoiseTerms`)."""

    noise_density_g_per_sqrt_hz: float
    vrw_m_per_s_per_sqrt_h: float
    bias_instability_micro_g: float
    integration_time_s: float
    random_walk_m_per_s3_per_sqrt_hz: float
    quantization_m_per_s: float
    ramp_m_per_s3: float
    bias_instability_fit_micro_g: float
    noise_density_readoff_g_per_sqrt_hz: float | None
    random_walk_readoff_m_per_s3_per_sqrt_hz: float | None
    floor_reached: bool
    fit_rms_log_residual: float

    SUMMARY_KEYS = (
        "noise_density_g_per_sqrt_hz",
        "vrw_m_per_s_per_sqrt_h",
        "bias_instability_micro_g",
        "integration_time_s",
        "random_walk_m_per_s3_per_sqrt_hz",
        "quantization_m_per_s",
        "ramp_m_per_s3",
    )

    @classmethod
    def from_terms(cls, t: NoiseTerms) -> "AccelNoise":
        """Convert terms of [g] data."""
        g = STANDARD_GRAVITY_M_PER_S2
        return cls(
            noise_density_g_per_sqrt_hz=t.white_noise_density,
            vrw_m_per_s_per_sqrt_h=t.white_noise_density * g * 60.0,
            bias_instability_micro_g=t.bias_instability * 1e6,
            integration_time_s=t.integration_time_s,
            random_walk_m_per_s3_per_sqrt_hz=t.random_walk * g,
            quantization_m_per_s=t.quantization * g,
            ramp_m_per_s3=t.ramp * g,
            bias_instability_fit_micro_g=t.bias_instability_fit * 1e6,
            noise_density_readoff_g_per_sqrt_hz=t.white_noise_readoff,
            random_walk_readoff_m_per_s3_per_sqrt_hz=None
            if t.random_walk_readoff is None
            else t.random_walk_readoff * g,
            floor_reached=t.floor_reached,
            fit_rms_log_residual=t.fit_rms_log_residual,
        )

    def summary(self) -> dict:
        return {k: getattr(self, k) for k in self.SUMMARY_KEYS}


def _model_basis(tau: np.ndarray) -> np.ndarray:
    """Columns of sigma^2(tau) = 3Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2."""
    return np.stack(
        [3.0 / tau**2, 1.0 / tau, np.full_like(tau, BIAS_INSTABILITY_FACTOR**2), tau / 3.0, tau**2 / 2.0], axis=1
    )


def _readoff(tau: np.ndarray, dev: np.ndarray, slope: float) -> tuple[float, float] | None:
    """(tau, deviation) of the point whose local log-log slope is closest to ``slope``."""
    if tau.size < 3:
        return None
    log_tau, log_dev = np.log(tau), np.log(dev)
    local = np.gradient(log_dev, log_tau)
    i = int(np.argmin(np.abs(local - slope)))
    if abs(local[i] - slope) > READOFF_SLOPE_TOLERANCE:
        return None
    return float(tau[i]), float(dev[i])


def noise_terms(result: AllanResult, fit_taus_s: tuple[float, float] | None = None) -> NoiseTerms:
    """IEEE Std 952 noise terms of an overlapping (or plain) Allan deviation curve.

    The five-term model sigma^2(tau) = 3Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2
    is fitted with non-negative coefficients by weighted least squares (scipy NNLS), each point weighted
    by the half-width of its confidence interval in variance (IEEE Std 952-1997, Annex C; the thesis,
    section 2). B itself is the minimum deviation / 0.664, at the integration time where it lies.

    ``fit_taus_s = (low, high)`` [s] restricts the fit (not the minimum or the read-offs) to those taus,
    e.g. to leave out the short taus an anti-alias filter has flattened.
    """
    if result.kind not in ("oadev", "adev"):
        raise InputError(f"kind: noise terms need an Allan deviation (oadev or adev), not {result.kind}")
    finite = np.isfinite(result.deviation) & (result.n >= 1)
    if finite.sum() >= 2 and not np.any(result.deviation[finite] > 0):
        return NoiseTerms(0.0, 0.0, 0.0, float(result.tau[finite][0]), 0.0, 0.0, 0.0, None, None, False, 0.0)
    good = finite & (result.deviation > 0)
    if good.sum() < 2:
        raise InputError("data: too short for noise terms; need at least two averaging times")
    fitted = good.copy()
    if fit_taus_s is not None:
        fitted &= (result.tau >= fit_taus_s[0]) & (result.tau <= fit_taus_s[1])
        if fitted.sum() < 2:
            raise InputError(f"fit_taus_s: fewer than two taus between {fit_taus_s[0]:g} and {fit_taus_s[1]:g} s")
    tau, dev = result.tau[fitted], result.deviation[fitted]
    variance = dev**2
    half_width = (result.ci_high[fitted] ** 2 - result.ci_low[fitted] ** 2) / 2.0
    fallback = variance * np.sqrt(2.0 / np.maximum(result.n[fitted], 1))
    half_width = np.where(np.isfinite(half_width) & (half_width > 0), half_width, fallback)
    # the five-term model is itself an idealization (anti-alias filters, the flicker floor's shape), so no
    # point is trusted beyond MODEL_UNCERTAINTY in variance; otherwise the tightest short-tau points
    # would dictate the whole fit
    half_width = np.maximum(half_width, MODEL_UNCERTAINTY * variance)
    basis = _model_basis(tau) / half_width[:, None]
    scale = np.linalg.norm(basis, axis=0)
    from scipy.optimize import nnls  # scipy.optimize is slow to import; only the noise terms need it

    solution, _ = nnls(basis / scale, variance / half_width)
    q2, n2, b2, k2, r2 = coefficients = solution / scale
    with np.errstate(divide="ignore"):
        misfit = float(np.sqrt(np.mean(np.log(_model_basis(tau) @ coefficients / variance) ** 2)) / 2.0)
    tau, dev = result.tau[good], result.deviation[good]
    lowest = int(np.argmin(dev))
    white = _readoff(tau, dev, -0.5)
    walk = _readoff(tau, dev, 0.5)
    return NoiseTerms(
        quantization=math.sqrt(q2),
        white_noise_density=math.sqrt(n2),
        bias_instability=float(dev[lowest]) / BIAS_INSTABILITY_FACTOR,
        integration_time_s=float(tau[lowest]),
        random_walk=math.sqrt(k2),
        ramp=math.sqrt(r2),
        bias_instability_fit=math.sqrt(b2),
        white_noise_readoff=None if white is None else white[1] * math.sqrt(white[0]),
        random_walk_readoff=None if walk is None else walk[1] * math.sqrt(3.0 / walk[0]),
        floor_reached=lowest < tau.size - 1,
        fit_rms_log_residual=misfit,
    )


def noise_parameters(
    result: AllanResult, sensor: Literal["gyro", "accel"] = "gyro", fit_taus_s: tuple[float, float] | None = None
) -> GyroNoise | AccelNoise:
    """Noise parameters of a gyro curve in [deg/s] (``sensor="gyro"``) or an accelerometer curve in [g]."""
    terms = noise_terms(result, fit_taus_s)
    if sensor == "gyro":
        return GyroNoise.from_terms(terms)
    if sensor == "accel":
        return AccelNoise.from_terms(terms)
    raise InputError(f"sensor: {sensor!r}; use 'gyro' or 'accel'")
