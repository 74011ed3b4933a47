"""Shorter chamber runs: calibrate a new unit from a short run with its fleet's population as the prior.

Empirical Bayes (hierarchical shrinkage). Each calibrated unit's bias curve, written as a cubic in the lagged
temperature, u = (T_lag - T_ref) / t_scale,

    b(T) = c_run + theta_1 u + theta_2 u^2 + theta_3 u^3,

gives one draw theta_i of the part type's coefficients; their mean mu and covariance S (outliers left out) are the
prior theta ~ N(mu, S). The thermal time constant of the lag is the population's median. A new unit's short run is
averaged in blocks of ``block_s`` seconds. Its noise is not white: flicker wanders slowly, and over one short run
whose temperature ramps it looks like curvature; treating the blocks as independent would make the data look far
more certain than they are. The blocks' noise covariance is therefore that of the population's IEEE Std 952 noise:
white, N^2 / t_b on the diagonal (N [deg/s/sqrt(Hz)], t_b the block's length), plus flicker of bias instability B
(the population's median flicker level of the fitted noise model, ``flicker_deg_per_h``),
the 1/f spectrum S(f) = B^2 / (pi f) written as a sum of first-order Gauss-Markov processes of time constants T_k
spaced by a factor R (from a twentieth of a block to twenty times the run), each of variance B^2 ln(R) / pi (the
standard construction of 1/f noise, e.g. Keshner 1982), plus the rate random walk K (covariance K^2 min(s, t)
from the run's start). For a process of covariance v exp(-|t| / T), the means
of blocks of lengths L_i and L_j whose centres lie Delta apart have

    cov = v (2T / L_i) sinh(L_i / 2T) (2T / L_j) sinh(L_j / 2T) exp(-Delta / T)     (disjoint blocks)
    var = 2 v (T / L)^2 (L / T - 1 + exp(-L / T))                                  (one block).

Runs are independent of one another. With C that covariance, the maximum a posteriori coefficients solve

    (X' C^-1 X + P) beta = X' C^-1 y + P beta_0,

beta = (run constants, theta), P the prior's precision S^-1 on theta (none on the run constants, which every
power-on draws afresh), beta_0 = (0, mu). The posterior covariance is (X' W X + P)^-1; the
standard deviation of the fitted curve over the population's temperature range is the unit's stated uncertainty.
Where the short run saw the temperature the data decide; beyond it the population does.

How the short run visits its range matters as much as how much of it: in a run whose temperature only rises (or
only falls), temperature is a function of time, so slow drift (flicker, rate random walk) is indistinguishable
from the bias curve, and a slower ramp only gives the drift longer to grow. A run that comes back (cold, hot,
cold) sees each temperature at different times, which tells the two apart: over the middle third of the range in a
quarter of the chamber time, two round trips instead of one ramp take the held-out drift relative to a full
calibration from 2.8x to 1.9x (median of 40 simulated units in ``benchmarks/bench_prior.py``; the same as with the
simulator's true population as the prior, :func:`prior_from_models`). :func:`fit_with_prior` warns when no run
comes back.

C. N. Morris, *Parametric empirical Bayes inference: theory and applications*, JASA 78 (381), 1983, 47-55;
A. Gelman et al., *Bayesian Data Analysis*, 3rd ed., ch. 5 (hierarchical models), 2013;
M. S. Keshner, *1/f noise*, Proc. IEEE 70 (3), 1982, 212-218.
"""

from __future__ import annotations

import hashlib
import json
import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..calibration import AxisCalibration, Calibration
from ..effects import find_turns, thermal_lag
from ..errors import DataQualityWarning, InputError, user_stacklevel
from ..fitting.provenance import provenance
from ..curves.polynomial import PolynomialCurve
from ..recording import Recording
from ..units import DEG_PER_S_TO_DEG_PER_H
from .unit_figures import REFERENCE_TEMPERATURE_DEGC
from .population import OUTLIER_THRESHOLD, fleet_table
from .store import CalibrationRecord

#: fewest calibrated units a prior is built from
MIN_UNITS_FOR_PRIOR = 10
#: block length the short run is averaged over [s]
PRIOR_BLOCK_S = 30.0
PRIOR_SCHEMA_VERSION = 1
_ORDER = 3
#: ratio of successive time constants of the flicker model
_FLICKER_RATIO = 2.0
#: relative jitter on the prior covariance's diagonal (a coefficient every unit shares exactly, e.g. a cubic
#: term no unit's model chose, would otherwise make it singular)
_JITTER = 1e-9


@dataclass(frozen=True)
class AxisPrior:
    """The population of one gyro axis: mean and covariance of (theta_1, theta_2, theta_3) [deg/s, (deg/s)^2],
    median thermal lag [s], median held-out drift [deg/s], white-noise density [deg/s/sqrt(Hz)], bias
    instability [deg/h] and rate random walk [deg/s/sqrt(s)]."""

    mean_dps: tuple[float, ...]
    covariance_dps2: tuple[tuple[float, ...], ...]
    lag_time_constant_s: float
    residual_drift_dps: float
    noise_density_dps_per_sqrt_hz: float
    bias_instability_deg_per_h: float
    rate_random_walk_dps_per_sqrt_s: float = 0.0


@dataclass(frozen=True)
class PopulationPrior:
    """A fleet's prior (see the module): per axis, and the temperature basis and range it is stated on [degC]."""

    axes: dict[str, AxisPrior]
    reference_temperature_degc: float
    temperature_scale_degc: float
    temperature_min_degc: float
    temperature_max_degc: float
    units: int

    def to_dict(self) -> dict:
        return {
            "schema_version": PRIOR_SCHEMA_VERSION,
            "axes": {
                a: {
                    "mean_dps": list(p.mean_dps),
                    "covariance_dps2": [list(r) for r in p.covariance_dps2],
                    "lag_time_constant_s": p.lag_time_constant_s,
                    "residual_drift_dps": p.residual_drift_dps,
                    "noise_density_dps_per_sqrt_hz": p.noise_density_dps_per_sqrt_hz,
                    "bias_instability_deg_per_h": p.bias_instability_deg_per_h,
                    "rate_random_walk_dps_per_sqrt_s": p.rate_random_walk_dps_per_sqrt_s,
                }
                for a, p in self.axes.items()
            },
            "reference_temperature_degc": self.reference_temperature_degc,
            "temperature_scale_degc": self.temperature_scale_degc,
            "temperature_min_degc": self.temperature_min_degc,
            "temperature_max_degc": self.temperature_max_degc,
            "units": self.units,
        }

    def digest(self) -> str:
        """SHA-256 of the prior (part of the input hash of units fitted with it)."""
        return hashlib.sha256(json.dumps(self.to_dict(), sort_keys=True).encode()).hexdigest()


def _scaled_tempcos(figures: list, scale: float) -> np.ndarray:
    """The units' temperature coefficients times ``scale`` [degC] to their power (one row per unit with all three
    finite) [deg/s]."""
    theta = np.array(
        [
            [f.tempco_1_dps_per_degc * scale, f.tempco_2_dps_per_degc2 * scale**2, f.tempco_3_dps_per_degc3 * scale**3]
            for f in figures
        ]
    )
    return theta[np.all(np.isfinite(theta), axis=1)]


def population_prior(
    records: Sequence[CalibrationRecord],
    *,
    threshold: float = OUTLIER_THRESHOLD,
    reference_temperature_degc: float = REFERENCE_TEMPERATURE_DEGC,
) -> PopulationPrior:
    """The prior of a calibrated fleet: its units' newest successful calibrations, outliers (robust score above
    ``threshold``) and units themselves fitted with a prior left out.

    Parameters
    ----------
    records : sequence of CalibrationRecord
        One per unit (:meth:`CalibrationStore.latest_rows`).
    threshold : float
        Outlier score above which a unit does not inform the prior.
    reference_temperature_degc : float
        T_ref of the basis [degC].
    """
    # units fitted with a prior are shrunk towards it: they would narrow the next prior without new evidence
    records = [
        r for r in records if r.figures is None or all(math.isnan(f.curve_sd_dps) for f in r.figures.axes.values())
    ]
    table = fleet_table(records)
    keep = set(table.loc[(table["status"] == "ok") & ~table["outlier"], "serial"])
    good = [r for r in records if r.serial in keep and r.figures is not None and r.model_json is not None]
    if len(good) < MIN_UNITS_FOR_PRIOR:
        raise InputError(
            f"prior: {len(good)} calibrated unit(s) that are not outliers; a population prior needs at "
            f"least {MIN_UNITS_FOR_PRIOR}"
        )
    t_min = float(np.median([r.figures.temperature_min_degc for r in good]))
    t_max = float(np.median([r.figures.temperature_max_degc for r in good]))
    scale = max(abs(t_max - reference_temperature_degc), abs(t_min - reference_temperature_degc), 1.0)
    models = [r.calibration() for r in good]
    axes = {}
    for axis in good[0].figures.axes:
        figures = [r.figures.axes[axis] for r in good if axis in r.figures.axes]
        theta = _scaled_tempcos(figures, scale)
        if theta.shape[0] < MIN_UNITS_FOR_PRIOR:
            continue
        lags = [m.axes[axis].lag_time_constant_s for m in models if axis in m.axes]
        axes[axis] = AxisPrior(
            mean_dps=tuple(map(float, theta.mean(axis=0))),
            covariance_dps2=tuple(tuple(map(float, row)) for row in np.cov(theta, rowvar=False)),
            lag_time_constant_s=float(np.median(lags)),
            residual_drift_dps=float(np.nanmedian([f.held_out_drift_dps for f in figures])),
            noise_density_dps_per_sqrt_hz=float(np.nanmedian([f.noise_density_dps_per_sqrt_hz for f in figures])),
            bias_instability_deg_per_h=_median_or_zero([f.flicker_deg_per_h for f in figures]),
            rate_random_walk_dps_per_sqrt_s=_median_or_zero([f.rate_random_walk_dps_per_sqrt_s for f in figures]),
        )
    if not axes:
        raise InputError("prior: no axis has a temperature curve in enough units")
    return PopulationPrior(axes, reference_temperature_degc, scale, t_min, t_max, len(good))


def prior_from_models(models: Sequence, like: PopulationPrior) -> PopulationPrior:
    """The prior of a population whose parts are known, on the basis of ``like`` (its reference temperature,
    scale and range): the oracle an empirical prior is judged against, e.g. the simulator's own parts.

    Each part's true bias curve over ``like``'s range, least-squares fitted as the cubic in u, gives one draw of
    theta; their mean and covariance are the prior's, and the thermal lag and noise are the first part's.

    Parameters
    ----------
    models : sequence of gyrocomp.simulation.GyroErrorModel
        The parts (at least ``MIN_UNITS_FOR_PRIOR``); anything with ``axes``,
        ``temperature_error_dps(temperature_degc) -> (n, axes) [deg/s]``, ``thermal_time_constant_s`` [s],
        ``noise_density_dps_per_sqrt_hz``, ``bias_instability_deg_per_h`` and ``rate_random_walk_dps_per_sqrt_s``.
    like : PopulationPrior
        The prior whose basis (and axes) the result shares.
    """
    models = list(models)
    if len(models) < MIN_UNITS_FOR_PRIOR:
        raise InputError(f"models: {len(models)} part(s); a population prior needs at least {MIN_UNITS_FOR_PRIOR}")
    grid = np.linspace(like.temperature_min_degc, like.temperature_max_degc, 91)
    u = (grid - like.reference_temperature_degc) / like.temperature_scale_degc
    basis = u[:, None] ** np.arange(_ORDER + 1)
    curves = np.stack([m.temperature_error_dps(grid) for m in models])  # (parts, grid, axes)
    first = models[0]
    axes = {}
    for j, axis in enumerate(first.axes):
        if axis not in like.axes:
            continue
        theta = np.linalg.lstsq(basis, curves[:, :, j].T, rcond=None)[0][1:].T  # the constant is each run's
        axes[axis] = AxisPrior(
            tuple(map(float, theta.mean(axis=0))),
            tuple(tuple(map(float, row)) for row in np.cov(theta, rowvar=False)),
            float(first.thermal_time_constant_s),
            like.axes[axis].residual_drift_dps,
            float(first.noise_density_dps_per_sqrt_hz),
            float(first.bias_instability_deg_per_h),
            float(first.rate_random_walk_dps_per_sqrt_s),
        )
    return PopulationPrior(
        axes,
        like.reference_temperature_degc,
        like.temperature_scale_degc,
        like.temperature_min_degc,
        like.temperature_max_degc,
        len(models),
    )


def _median_or_zero(values: list[float]) -> float:
    finite = [v for v in values if math.isfinite(v)]
    return float(np.median(finite)) if finite else 0.0


def _blocks(recording: Recording, axis: str, lag_s: float, block_s: float):
    """Block means of the rate and the lagged temperature, and each block's duration [s]."""
    t = recording.time_s
    temperature = recording.temperature_for(axis)  # the axis's own column when the log has one per axis
    if lag_s > 0:
        temperature = thermal_lag(t, temperature, lag_s)[0]
    index = np.floor((t - t[0]) / block_s).astype(np.int64)
    counts = np.bincount(index)
    used = counts > 0
    rate = recording.gyro(axis)
    mean_rate = np.bincount(index, weights=rate)[used] / counts[used]
    mean_temperature = np.bincount(index, weights=temperature)[used] / counts[used]
    return mean_rate, mean_temperature, counts[used] / recording.rate_hz


def fit_with_prior(
    recordings: Sequence[Recording] | Recording, prior: PopulationPrior, *, block_s: float = PRIOR_BLOCK_S
) -> Calibration:
    """A unit's calibration from (short) runs and its population's prior (see the module).

    Parameters
    ----------
    recordings : Recording or sequence of Recording
        The unit's runs at rest, with temperature [s, deg/s, degC]; each gets its own constant.
    prior : PopulationPrior
        From :func:`population_prior`.
    block_s : float
        Averaging block [s].

    Returns a :class:`Calibration` whose curves span the population's temperature range; its ``fit_report``
    gives, per axis, the standard deviation of the fitted curve (largest over the range) and the number of blocks.
    """
    recordings = [recordings] if isinstance(recordings, Recording) else list(recordings)
    if not recordings:
        raise InputError("recordings: give at least one run")
    for rec in recordings:
        if rec.temperature_degc is None:
            raise InputError(f"{rec.source}: no temperature column; a prior fit models the bias against temperature")
    if not block_s > 0:
        raise InputError(f"block_s: must be positive, got {block_s}")
    if not any(comes_back(rec.temperature_degc) for rec in recordings):
        names = ", ".join(str(rec.source) for rec in recordings)
        warnings.warn(
            f"recordings: the temperature only rises or only falls in every run ({names}): slow drift "
            "cannot be told from the temperature curve; a run that comes back (cold, hot, cold) tells "
            "them apart",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
    axes, report = {}, {}
    for axis, p in prior.axes.items():
        if not all(axis in rec.gyro_axes for rec in recordings):
            continue
        axes[axis], report[axis] = _fit_axis(recordings, axis, p, prior, block_s)
    if not axes:
        raise InputError(f"recordings: none of the prior's axes ({', '.join(prior.axes)}) is in every run")
    name = f"population prior ({prior.units} units): cubic in the lagged temperature, constant per run"
    return Calibration(
        axes=axes,
        model=name,
        provenance=provenance(recordings),
        fit_report={"temperature": "population prior", "prior": report},
    )


def comes_back(temperature_degc: np.ndarray) -> bool:
    """Whether a run's temperature [degC] turns back by at least half its span (e.g. cold, hot, cold), so that it
    visits its temperatures at two different times; False for a run that only rises or only falls."""
    t = np.asarray(temperature_degc, dtype=float)
    t = t[np.isfinite(t)]
    if t.size < 2:
        return False
    span = float(t.max() - t.min())
    return span > 0 and find_turns(t, span / 2).turn_index.size > 0


def block_covariance(
    duration_s: np.ndarray,
    noise_density_dps_per_sqrt_hz: float,
    bias_instability_deg_per_h: float,
    rate_random_walk_dps_per_sqrt_s: float = 0.0,
) -> np.ndarray:
    """Covariance [(deg/s)^2] of the means of consecutive blocks of ``duration_s`` [s] from the start of a run,
    under white noise of density N [deg/s/sqrt(Hz)], flicker of bias instability B [deg/h] and a rate random walk
    K [deg/s/sqrt(s)] from the run's start (see the module)."""
    length = np.asarray(duration_s, dtype=float)
    centre = np.cumsum(length) - length / 2
    cov = np.diag(noise_density_dps_per_sqrt_hz**2 / length)
    if rate_random_walk_dps_per_sqrt_s > 0:
        # W(t) of variance K^2 t: cov(W(s), W(t)) = K^2 min(s, t); averaged over two disjoint blocks, K^2 times the
        # earlier block's centre; over one block [a, a + L], K^2 (a + L / 3)
        walk = np.minimum(centre[:, None], centre[None, :])
        np.fill_diagonal(walk, centre - length / 2 + length / 3)
        cov = cov + rate_random_walk_dps_per_sqrt_s**2 * walk
    b_dps = bias_instability_deg_per_h / DEG_PER_S_TO_DEG_PER_H
    if b_dps <= 0:
        return cov
    variance = b_dps**2 * math.log(_FLICKER_RATIO) / math.pi
    shortest, longest = float(length.min()) / 20, 20 * float(length.sum())
    count = int(math.ceil(math.log(longest / shortest) / math.log(_FLICKER_RATIO))) + 1
    gap = np.abs(centre[:, None] - centre[None, :])
    for k in range(count):
        tc = shortest * _FLICKER_RATIO**k
        x = length / (2 * tc)
        # log((2T/L) sinh(L/2T)), computed without overflow
        log_shape = x + np.log1p(-np.exp(-2 * x)) - np.log(2 * x)
        off = variance * np.exp(log_shape[:, None] + log_shape[None, :] - gap / tc)
        r = length / tc
        np.fill_diagonal(off, variance * 2 * (r - 1 + np.exp(-r)) / r**2)
        cov = cov + off
    return cov


def _map(
    design: np.ndarray, y: np.ndarray, noise: np.ndarray, precision: np.ndarray, prior_mean: np.ndarray
) -> tuple[np.ndarray, np.ndarray, float]:
    """MAP coefficients, their posterior covariance and the noise inflation: when the residuals scatter more than
    the noise model says (Birge ratio r' C^-1 r / (n - p) above 1), C is scaled up by it and the fit repeated, so
    that a unit noisier than its population gets wider uncertainties rather than false confidence."""
    inflation = 1.0
    for _ in range(2):
        weighted = np.linalg.solve(noise * inflation, design)
        normal = design.T @ weighted + precision
        beta = np.linalg.solve(normal, weighted.T @ y + precision @ prior_mean)
        residual = y - design @ beta
        dof = max(y.size - design.shape[1], 1)
        ratio = float(residual @ np.linalg.solve(noise * inflation, residual)) / dof
        if ratio <= 1.0:
            break
        inflation *= ratio
    return beta, np.linalg.inv(normal), inflation


def _fit_axis(
    recordings: list[Recording], axis: str, p: AxisPrior, prior: PopulationPrior, block_s: float
) -> tuple[AxisCalibration, dict]:
    runs = len(recordings)
    ys, us, columns, covariances = [], [], [], []
    for r, rec in enumerate(recordings):
        rate, temperature, duration_s = _blocks(rec, axis, p.lag_time_constant_s, block_s)
        ys.append(rate)
        us.append((temperature - prior.reference_temperature_degc) / prior.temperature_scale_degc)
        columns.append(np.full(rate.size, r))
        covariances.append(
            block_covariance(
                duration_s,
                p.noise_density_dps_per_sqrt_hz,
                p.bias_instability_deg_per_h,
                p.rate_random_walk_dps_per_sqrt_s,
            )
        )
    y, u, run = (np.concatenate(v) for v in (ys, us, columns))
    design = np.column_stack([(run[:, None] == np.arange(runs)).astype(float), *(u**k for k in range(1, _ORDER + 1))])
    noise = np.zeros((y.size, y.size))
    start = 0
    for c in covariances:
        noise[start : start + c.shape[0], start : start + c.shape[0]] = c
        start += c.shape[0]
    covariance = np.asarray(p.covariance_dps2, dtype=float)
    covariance = covariance + np.eye(_ORDER) * _JITTER * max(float(np.max(np.diag(covariance))), 1e-30)
    precision = np.zeros((runs + _ORDER, runs + _ORDER))
    precision[runs:, runs:] = np.linalg.inv(covariance)
    prior_mean = np.concatenate([np.zeros(runs), p.mean_dps])
    beta, posterior, inflation = _map(design, y, noise, precision, prior_mean)
    posterior = posterior[runs:, runs:]
    grid = np.linspace(prior.temperature_min_degc, prior.temperature_max_degc, 91)
    g = (grid - prior.reference_temperature_degc) / prior.temperature_scale_degc
    basis = np.column_stack([g**k for k in range(1, _ORDER + 1)])
    curve_sd = np.sqrt(np.einsum("ij,jk,ik->i", basis, posterior, basis))
    curve = PolynomialCurve(
        tuple(map(float, beta[runs:])),
        prior.reference_temperature_degc,
        prior.temperature_scale_degc,
        prior.temperature_min_degc,
        prior.temperature_max_degc,
    )
    calibrated = AxisCalibration(curve, tuple(map(float, beta[:runs])), lag_time_constant_s=p.lag_time_constant_s)
    seen = (
        float(np.min(u)) * prior.temperature_scale_degc + prior.reference_temperature_degc,
        float(np.max(u)) * prior.temperature_scale_degc + prior.reference_temperature_degc,
    )
    return calibrated, {
        "curve_sd_max_dps": float(curve_sd.max()),
        "blocks": int(y.size),
        "seen_degc": list(seen),
        "noise_inflation": inflation,
        "posterior_sd_dps": [math.sqrt(v) for v in np.diag(posterior)],
    }


__all__ = [
    "MIN_UNITS_FOR_PRIOR",
    "PRIOR_BLOCK_S",
    "AxisPrior",
    "PopulationPrior",
    "block_covariance",
    "comes_back",
    "fit_with_prior",
    "population_prior",
    "prior_from_models",
]
