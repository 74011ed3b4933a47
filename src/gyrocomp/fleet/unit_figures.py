"""Figures of merit of one unit's calibration: what a production line puts limits on and compares across units.

Per gyro axis (``AxisFigures``):

- ``held_out_drift_dps`` / ``raw_drift_dps``: the RMS drift left on held-out runs (or legs) by the chosen model,
  and by a constant, as the model choice measured them (leave-one-run-out) [deg/s];
- ``temperature_sensitivity_dps_per_degc``: d bias / dT at the reference temperature [deg/s/degC], from the
  fitted curve (central difference over +-0.5 degC); NaN when the reference lies outside the range the unit saw;
- ``tempco_1_dps_per_degc``, ``tempco_2_dps_per_degc2``, ``tempco_3_dps_per_degc3``: the fitted curve as a cubic
  in (T - T_ref) by least squares over the unit's range: bias(T) - bias(T_ref) ~ sum_k c_k (T - T_ref)^k. Every
  unit in the same basis whatever its model, so that coefficients compare across a fleet;
- ``bias_span_dps``: peak-to-peak of the fitted curve over the unit's range [deg/s];
- ``turn_on_bias_dps``: the bias at the reference temperature, mean over the runs (each run's constant plus the
  curve there) [deg/s]; ``turn_on_repeatability_dps``: the sample standard deviation of the per-run constants
  [deg/s] (NaN with one run);
- ``g_sensitivity_dps_per_g``: the norm of the axis's g-sensitivity row [deg/s/g] (NaN when not fitted);
- ``noise_density_dps_per_sqrt_hz``, ``bias_instability_deg_per_h`` and ``rate_random_walk_dps_per_sqrt_s``:
  IEEE Std 952 white noise, bias instability (Allan minimum / 0.664) and rate random walk of the compensated
  longest run (:func:`gyrocomp.measures.noise.analyse_noise`); ``flicker_deg_per_h``: the flicker level B of the noise
  model fitted to the whole Allan curve (on a short run the Allan minimum is not reached and reads low: 11.5
  against 18.9 deg/h on 15 minutes of a 20 deg/h part);
- ``curve_sd_dps``: for a unit fitted with its population's prior (:mod:`gyrocomp.fleet.prior`), the largest
  standard deviation of its fitted curve over the population's range [deg/s] (its stated uncertainty; such a fit
  has no held-out drift); NaN otherwise.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import asdict, dataclass, fields

import numpy as np

from ..calibration import AxisCalibration, Calibration
from ..calibration.compensate import apply
from ..errors import GyrocompError
from ..measures.noise import analyse_noise
from ..recording import Recording

#: the reference temperature of the temperature sensitivity and of the cubic coefficients [degC]
REFERENCE_TEMPERATURE_DEGC = 25.0
_DERIVATIVE_STEP_DEGC = 0.5
_GRID_POINTS = 201


@dataclass(frozen=True)
class AxisFigures:
    """One gyro axis's figures (see the module for each); NaN where a figure does not apply."""

    held_out_drift_dps: float
    raw_drift_dps: float
    temperature_sensitivity_dps_per_degc: float
    tempco_1_dps_per_degc: float
    tempco_2_dps_per_degc2: float
    tempco_3_dps_per_degc3: float
    bias_span_dps: float
    turn_on_bias_dps: float
    turn_on_repeatability_dps: float
    g_sensitivity_dps_per_g: float
    noise_density_dps_per_sqrt_hz: float
    bias_instability_deg_per_h: float
    rate_random_walk_dps_per_sqrt_s: float = math.nan
    flicker_deg_per_h: float = math.nan
    curve_sd_dps: float = math.nan


#: the figure names a limit may name (for every axis, or prefixed by one axis: ``gyro_z_held_out_drift_dps``)
FIGURE_NAMES = tuple(f.name for f in fields(AxisFigures))


@dataclass(frozen=True)
class UnitFigures:
    """Every gyro axis's figures of one unit, and the temperature range its runs covered [degC]."""

    axes: dict[str, AxisFigures]
    temperature_min_degc: float
    temperature_max_degc: float
    runs: int

    def as_row(self) -> dict[str, float]:
        """Flat ``{axis_figure: value}`` (``gyro_x_noise_density_dps_per_sqrt_hz``, ...) for a table."""
        row = {
            "runs": float(self.runs),
            "temperature_min_degc": self.temperature_min_degc,
            "temperature_max_degc": self.temperature_max_degc,
        }
        for axis, figures in self.axes.items():
            row.update({f"{axis}_{name}": value for name, value in asdict(figures).items()})
        return row

    def to_dict(self) -> dict:
        """The figures as a JSON document (a figure not measured, NaN, as null)."""

        def number(v):
            return None if isinstance(v, float) and math.isnan(v) else v

        return {
            "axes": {a: {k: number(v) for k, v in asdict(f).items()} for a, f in self.axes.items()},
            "temperature_min_degc": number(self.temperature_min_degc),
            "temperature_max_degc": number(self.temperature_max_degc),
            "runs": self.runs,
        }

    @classmethod
    def from_dict(cls, d: dict) -> "UnitFigures":
        def number(v):
            return math.nan if v is None else float(v)

        return cls(
            {a: AxisFigures(**{k: number(v) for k, v in f.items()}) for a, f in d["axes"].items()},
            number(d["temperature_min_degc"]),
            number(d["temperature_max_degc"]),
            int(d["runs"]),
        )


def unit_figures(
    calibration: Calibration,
    recordings: list[Recording],
    *,
    reference_temperature_degc: float = REFERENCE_TEMPERATURE_DEGC,
) -> UnitFigures:
    """The figures of merit of ``calibration`` fitted on ``recordings`` (see the module).

    Parameters
    ----------
    calibration : Calibration
        The unit's model (from :func:`gyrocomp.fit` on ``recordings``).
    recordings : list of Recording
        The runs it was fitted on [s, deg/s, g, degC].
    reference_temperature_degc : float
        Where the temperature sensitivity is taken and the cubic coefficients are centred [degC].
    """
    temps = [r.temperature_degc for r in recordings if r.temperature_degc is not None]
    t_lo = float(min(np.nanmin(t) for t in temps)) if temps else math.nan
    t_hi = float(max(np.nanmax(t) for t in temps)) if temps else math.nan
    noise = _noise(calibration, max(recordings, key=lambda r: r.n_samples))
    report = calibration.report
    prior_fit = report.sections.get("prior", {})
    axes = {}
    for name, axis in calibration.axes.items():
        chosen = report.selection.get(name)
        axes[name] = AxisFigures(
            held_out_drift_dps=_number(None if chosen is None else chosen.chosen_drift_dps),
            raw_drift_dps=_number(None if chosen is None else chosen.raw_drift_dps),
            **_curve_figures(axis, t_lo, t_hi, reference_temperature_degc),
            **_constants(axis, reference_temperature_degc),
            g_sensitivity_dps_per_g=(
                float(np.linalg.norm(axis.g_sensitivity_dps_per_g))
                if axis.g_sensitivity_dps_per_g is not None
                else math.nan
            ),
            **noise.get(
                name,
                {
                    "noise_density_dps_per_sqrt_hz": math.nan,
                    "bias_instability_deg_per_h": math.nan,
                    "rate_random_walk_dps_per_sqrt_s": math.nan,
                    "flicker_deg_per_h": math.nan,
                },
            ),
            curve_sd_dps=_number(prior_fit.get(name, {}).get("curve_sd_max_dps")),
        )
    return UnitFigures(axes, t_lo, t_hi, len(recordings))


def _number(value) -> float:
    return float(value) if isinstance(value, (int, float)) and value is not None else math.nan


def _curve_figures(axis: AxisCalibration, t_lo: float, t_hi: float, t_ref: float) -> dict[str, float]:
    """Temperature sensitivity at ``t_ref``, the cubic in (T - t_ref) and the span over [t_lo, t_hi]."""
    nan = {
        "temperature_sensitivity_dps_per_degc": math.nan,
        "tempco_1_dps_per_degc": math.nan,
        "tempco_2_dps_per_degc2": math.nan,
        "tempco_3_dps_per_degc3": math.nan,
        "bias_span_dps": math.nan,
    }
    if axis.temperature is None or not t_hi > t_lo:
        return {**nan, "bias_span_dps": 0.0} if axis.temperature is None else nan
    grid = np.linspace(t_lo, t_hi, _GRID_POINTS)
    curve = np.asarray(axis.shape_dps(grid), dtype=float)
    inside = t_lo <= t_ref <= t_hi
    slope = math.nan
    if inside:
        h = _DERIVATIVE_STEP_DEGC
        ends = np.asarray(axis.shape_dps(np.array([t_ref - h, t_ref + h])), dtype=float)
        slope = float(ends[1] - ends[0]) / (2 * h)
    d = grid - t_ref
    basis = np.column_stack([np.ones_like(d), d, d**2, d**3])
    coefficients = np.linalg.lstsq(basis, curve, rcond=None)[0]
    return {
        "temperature_sensitivity_dps_per_degc": slope,
        "tempco_1_dps_per_degc": float(coefficients[1]),
        "tempco_2_dps_per_degc2": float(coefficients[2]),
        "tempco_3_dps_per_degc3": float(coefficients[3]),
        "bias_span_dps": float(np.ptp(curve)),
    }


def _constants(axis: AxisCalibration, t_ref: float) -> dict[str, float]:
    c = np.asarray(axis.turn_on_biases_dps, dtype=float)
    at_reference = float(np.asarray(axis.shape_dps(np.array([t_ref])), dtype=float).reshape(-1)[0])
    return {
        "turn_on_bias_dps": float(c.mean()) + at_reference if c.size else math.nan,
        "turn_on_repeatability_dps": float(c.std(ddof=1)) if c.size > 1 else math.nan,
    }


def _noise(calibration: Calibration, recording: Recording) -> dict[str, dict[str, float]]:
    """White noise density, bias instability and rate random walk of each modelled axis of the compensated
    ``recording``."""
    axes = [a for a in calibration.axes if a in recording.gyro_axes]
    if not axes:
        return {}
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # a poor noise-model fit still gives the figures; the fit warns itself
            compensated = apply(calibration, recording)
            # warnings are ignored here: the motion check's stillness search would be work for nothing per unit
            analysis = analyse_noise(compensated, axes, split_gaps=True, motion_check=False)
    except GyrocompError:
        return {}
    return {
        name: {
            "noise_density_dps_per_sqrt_hz": float(a.noise.noise_density_dps_per_sqrt_hz),
            "bias_instability_deg_per_h": float(a.noise.bias_instability_deg_per_h),
            "rate_random_walk_dps_per_sqrt_s": float(a.noise.rrw_dps_sqrt_hz),
            "flicker_deg_per_h": float(a.noise.bias_instability_fit_deg_per_h),
        }
        for name, a in analysis.axes.items()
    }


__all__ = ["FIGURE_NAMES", "REFERENCE_TEMPERATURE_DEGC", "AxisFigures", "UnitFigures", "unit_figures"]
