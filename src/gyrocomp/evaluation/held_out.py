"""The held-out residual of a calibration and its 95 % band: what a unit's certificate states.

The runs are split into folds as the model choice splits them (each run, each heating or cooling leg, or time
blocks: :func:`gyrocomp.evaluation.validation.make_sample_folds`); for each fold the fit is made without it
(the same fit, :func:`gyrocomp.evaluation.comparison.fit_method`) and the fold compensated with it. The held-out
residual of an axis is the fold's compensated output, moving-averaged over the drift window and taken about its
mean (a new power-on's constant bias is the run constant the model cannot know):

    r(t) = MA_w[comp](t) - mean(MA_w[comp])

The band is split-conformal: the ``BAND_LEVEL`` quantile of |r| over every held-out sample of every fold,

    band = Q_0.95(|r|),

so that on a new run of the unit, exchangeable with the folds, |r| stays within the band 95 % of the time
(the final model, fitted on every run, does a little better than the folds' models; the band is then slightly
wide). ``benchmarks/bench_certificate_band.py`` measures the coverage over a simulated fleet.

References: V. Vovk, A. Gammerman, G. Shafer, *Algorithmic Learning in a Random World*, Springer 2005 (split
conformal prediction); the fold scheme of :mod:`gyrocomp.fitting.folds`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..calibration.compensate import apply
from ..effects import moving_average
from ..measures.merit import smoothed_about_mean
from ..models.options import FitOptions
from ..recording import Recording
from ..runs.prepared import prepare
from ..threads import single_threaded_blas
from .comparison import Method, fit_method
from .validation import fold_window_s, make_sample_folds, quiet_fold_fit, training_runs

#: the coverage the band is made for
BAND_LEVEL = 0.95


@dataclass(frozen=True)
class AxisResidual:
    """One axis's held-out residual: the samples' temperature [degC] (moving-averaged as the residual is) and
    residual [deg/s] over every fold (:func:`gyrocomp.measures.merit.smoothed_about_mean`), its RMS [deg/s] and
    the band [deg/s] (|r| below it with probability BAND_LEVEL)."""

    temperature_degc: np.ndarray
    residual_dps: np.ndarray
    rms_dps: float
    band_dps: float


@dataclass(frozen=True)
class HeldOut:
    """The held-out residual of each axis, the folds' kind and count, and the drift window [s]."""

    axes: dict[str, AxisResidual]
    folds: str
    fold_count: int
    window_s: float


@single_threaded_blas
def held_out_residuals(recordings: list[Recording], method: Method | None = None) -> HeldOut:
    """The held-out residual and its band of the fit ``method`` (default: gyrocomp's default fit) on
    ``recordings`` [s, deg/s, degC] (see the module)."""
    method = method or FitOptions()
    recordings = prepare(recordings)
    kind, folds = make_sample_folds(recordings, "auto")
    window_s = fold_window_s(recordings, folds)
    axes = recordings[0].gyro_axes
    temps: dict[str, list[np.ndarray]] = {a: [] for a in axes}
    residuals: dict[str, list[np.ndarray]] = {a: [] for a in axes}
    for fold in folds:
        held = recordings[fold.run]
        with quiet_fold_fit():
            comp = apply(fit_method(method, training_runs(recordings, fold, kind)), held).gyro_dps
        w = max(1, int(round(window_s * held.rate_hz)))
        for j, axis in enumerate(axes):
            residuals[axis].append(smoothed_about_mean(comp[fold.rows, j], w))
            temps[axis].append(moving_average(np.asarray(held.temperature_for(axis), dtype=float)[fold.rows], w))
    out = {}
    for axis in axes:
        r = np.concatenate(residuals[axis])
        out[axis] = AxisResidual(
            np.concatenate(temps[axis]), r, float(np.sqrt(np.mean(r**2))), float(np.quantile(np.abs(r), BAND_LEVEL))
        )
    return HeldOut(out, kind, len(folds), window_s)


__all__ = ["BAND_LEVEL", "AxisResidual", "HeldOut", "held_out_residuals"]
