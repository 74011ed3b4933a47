"""Population statistics of a fleet: the fleet table, robust outlier scores, yield.

The outlier score of a unit on one figure is the modified z-score of Iglewicz and Hoaglin,

    z = 0.6745 (x - median) / MAD,   MAD = median |x - median|,

robust to the outliers it looks for (a mean and standard deviation would be pulled towards them). When more than
half of the units share one value (MAD = 0), the mean absolute deviation stands in: z = (x - median) /
(1.253314 MeanAD). Figures that are magnitudes (drifts, spans, noise, g-sensitivity) are scored on their
logarithm, where a spread of parts is closer to normal (a part twice as noisy is as far above as one half as
noisy is below), and one-sided: a part quieter or more stable than its population is not suspect (and the
logarithm of a figure estimated from few samples, such as a standard deviation of three turn-on constants, has a
long lower tail). A unit's score is its largest |z| over the scored figures (``SCORED_FIGURES`` of every axis,
and the temperature range its runs covered); it is an outlier when that passes ``threshold`` (3.5, Iglewicz and
Hoaglin's recommendation). Below ``MIN_UNITS_FOR_OUTLIERS`` fitted units a median is not a population and no
unit is scored. The model's polynomial coefficients are in the table but not scored: which order the model
choice took for a unit is not a property of the part.

B. Iglewicz and D. C. Hoaglin, *How to Detect and Handle Outliers*, ASQC Quality Press, 1993, ch. 3.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .limits import Limits
from .store import CalibrationRecord

OUTLIER_THRESHOLD = 3.5
MIN_UNITS_FOR_OUTLIERS = 10
#: figures a unit is scored on (see the module), by axis; the positive ones on their logarithm
SCORED_FIGURES = (
    "held_out_drift_dps",
    "temperature_sensitivity_dps_per_degc",
    "bias_span_dps",
    "turn_on_bias_dps",
    "turn_on_repeatability_dps",
    "g_sensitivity_dps_per_g",
    "noise_density_dps_per_sqrt_hz",
    "bias_instability_deg_per_h",
)
_SIGNED = ("temperature_sensitivity_dps_per_degc", "turn_on_bias_dps")
_UNIT_SCORED = ("temperature_min_degc", "temperature_max_degc")
_MAD_SCALE = 0.6745
_MEAN_AD_SCALE = 1.253314
#: columns of the table that are not figures
INFO_COLUMNS = (
    "serial",
    "status",
    "verdict",
    "failing",
    "calibrated_utc",
    "error",
    "outlier_score",
    "outlier",
    "outlier_figures",
)


def robust_z(values: np.ndarray) -> np.ndarray:
    """Modified z-scores of ``values`` (see the module); NaN where a value is NaN, zeros when all are equal."""
    x = np.asarray(values, dtype=float)
    finite = x[np.isfinite(x)]
    z = np.full(x.shape, np.nan)
    if finite.size == 0:
        return z
    median = np.median(finite)
    mad = np.median(np.abs(finite - median))
    if mad > 0:
        z = _MAD_SCALE * (x - median) / mad
    else:
        mean_ad = np.mean(np.abs(finite - median))
        z = (x - median) / (_MEAN_AD_SCALE * mean_ad) if mean_ad > 0 else np.where(np.isfinite(x), 0.0, np.nan)
    return z


@dataclass(frozen=True)
class FleetYield:
    """Units in all, fitted (status ok), passing their limits, and the yield = passing / all."""

    units: int
    fitted: int
    passed: int

    @property
    def yield_fraction(self) -> float:
        return self.passed / self.units if self.units else math.nan


def fleet_table(
    records: Sequence[CalibrationRecord], limits: Limits | None = None, *, threshold: float = OUTLIER_THRESHOLD
) -> pd.DataFrame:
    """One row per unit: ``serial``, ``status`` (ok/failed), ``verdict`` (pass/fail by ``limits``, or the verdict
    stored with the calibration when no limits are given; empty for a failed fit), ``failing`` (the failing figures),
    ``calibrated_utc``, ``error``, ``outlier_score``, ``outlier``, ``outlier_figures`` and every figure
    (``gyro_x_noise_density_dps_per_sqrt_hz``, ...; see :mod:`gyrocomp.fleet.unit_figures`)."""
    rows = []
    for r in records:
        verdict = limits.check(r.figures) if (limits is not None and r.figures is not None) else None
        row = {
            "serial": r.serial,
            "status": r.status,
            "verdict": verdict.label if verdict is not None else (r.verdict or ""),
            "failing": verdict.summary()
            if verdict is not None
            else "; ".join(f"{f.figure} {f.reason}" for f in r.failures),
            "calibrated_utc": r.calibrated_utc,
            "error": r.error or "",
        }
        row.update(r.figures.as_row() if r.figures is not None else {})
        rows.append(row)
    table = pd.DataFrame(rows, columns=None if rows else list(INFO_COLUMNS[:6]))
    figures = [c for c in table.columns if c not in INFO_COLUMNS]
    ok = (table["status"] == "ok") if len(table) else pd.Series(dtype=bool)
    scored = [c for c in figures if c in _UNIT_SCORED or any(c.endswith("_" + f) for f in SCORED_FIGURES)]
    if int(ok.sum()) < MIN_UNITS_FOR_OUTLIERS:
        scored = []
    scores = pd.DataFrame({c: _score(c, table[c].where(ok).to_numpy(dtype=float)) for c in scored}, index=table.index)
    magnitude = scores.abs()
    table["outlier_score"] = magnitude.max(axis=1, skipna=True).where(ok) if scored else np.nan
    table["outlier"] = (table["outlier_score"] > threshold).fillna(False).astype(bool)
    table["outlier_figures"] = [
        ", ".join(magnitude.loc[i][magnitude.loc[i] > threshold].sort_values(ascending=False).index)
        if scored and ok[i]
        else ""
        for i in table.index
    ]
    return table[[*INFO_COLUMNS, *figures]]


def _score(column: str, values: np.ndarray) -> np.ndarray:
    """A figure's outlier scores: robust z of a signed figure, of a magnitude's logarithm above the median only
    (non-positive magnitudes: NaN)."""
    if column in _UNIT_SCORED or any(column.endswith("_" + f) for f in _SIGNED):
        return robust_z(values)
    with np.errstate(divide="ignore", invalid="ignore"):
        z = robust_z(np.where(values > 0, np.log(np.where(values > 0, values, 1.0)), np.nan))
    return np.where(np.isnan(z), np.nan, np.maximum(z, 0.0))


def fleet_yield(table: pd.DataFrame) -> FleetYield:
    """Yield of a fleet table (a unit without limits passes when its fit succeeded)."""
    fitted = table["status"] == "ok"
    passed = fitted & (table["verdict"] != "fail")
    return FleetYield(len(table), int(fitted.sum()), int(passed.sum()))


__all__ = [
    "FleetYield",
    "INFO_COLUMNS",
    "MIN_UNITS_FOR_OUTLIERS",
    "OUTLIER_THRESHOLD",
    "SCORED_FIGURES",
    "fleet_table",
    "fleet_yield",
    "robust_z",
]
