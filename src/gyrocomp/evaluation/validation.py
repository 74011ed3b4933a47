"""The proof a user reruns on their own runs: held-out drift of gyrocomp's default against what they have.

Every method is fitted on the training part of each fold and applied to the held-out part, and the drift left
there is measured: the RMS, about its mean, of the ``window_s`` moving average of the compensated output
[deg/s] (the sensor at rest, so what remains is drift and noise). Folds are those of the model choice
(:mod:`gyrocomp.fitting.selection`): each run with three runs or more; with fewer, each heating or cooling leg
(split at confirmed temperature reversals), or contiguous time blocks when the runs do not reverse. A held-out
leg is compensated as part of its whole run (the lag and the turning points need its history), and only its
own rows are scored. Each method's score is the mean over folds, with its standard error.

Methods: ``raw`` (the run's constant removed only), ``PX4 cubic`` and ``ArduPilot cubic`` (what the autopilots'
calibration scripts fit, :mod:`gyrocomp.evaluation.comparison`), ``cubic + run constants`` (ordinary least squares on every
sample, one constant per run, extrapolated as a cubic: the field's hand-written baseline) and ``gyrocomp default``,
plus any candidates named.
"""

from __future__ import annotations

import contextlib
import math
import warnings
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from ..rounding import with_error
from ..calibration import AxisCalibration, Calibration
from ..calibration.compensate import apply
from ..errors import DataQualityWarning, InputError, ModelChoiceWarning, TemperatureRangeWarning
from ..measures.merit import smoothed_residual_rms
from ..fitting.provenance import provenance
from ..curves.hysteresis import turn_threshold_degc
from ..models.options import FitOptions, FoldChoice
from ..fitting.folds import BLOCKS_PER_RUN, FOLD_KINDS, MIN_FOLDS, WINDOW_MIN_S, drift_window_s, leg_labels
from ..fitting.scores import fold_mean, fold_standard_error
from ..curves.polynomial import PolynomialCurve
from ..measures.data_check import repeated_findings
from ..measures.plausibility import require_temperature_span
from ..runs.prepared import prepare
from ..threads import single_threaded_blas
from ..recording import Recording
from .comparison import Method, fit_ardupilot_style, fit_method, fit_px4_style

#: the plain cubic's reference temperature is the middle of the runs' range
PLAIN_CUBIC_ORDER = 3


def fit_plain_cubic(recordings: list[Recording]) -> Calibration:
    """Ordinary least squares on every sample: a cubic in T - T_mid shared by the runs, one constant per run,
    extrapolated as the cubic itself (no clamp). The baseline a user writes by hand."""
    axes = {}
    for axis in recordings[0].gyro_axes:
        temps = [r.temperature_for(axis) for r in recordings]
        mid = 0.5 * (min(float(t.min()) for t in temps) + max(float(t.max()) for t in temps))
        rows = []
        for k, t in enumerate(temps):
            onehot = np.zeros((t.size, len(recordings)))
            onehot[:, k] = 1.0
            rows.append(np.hstack([onehot, (t - mid)[:, None] ** np.arange(1, PLAIN_CUBIC_ORDER + 1)]))
        y = np.concatenate([r.gyro(axis) for r in recordings])
        coef, *_ = np.linalg.lstsq(np.vstack(rows), y, rcond=None)
        n = len(recordings)
        axes[axis] = AxisCalibration(
            PolynomialCurve(tuple(float(c) for c in coef[n:]), mid, 1.0, -math.inf, math.inf),
            tuple(float(c) for c in coef[:n]),
        )
    return Calibration(
        axes=axes,
        model="cubic + run constants",
        provenance=provenance(recordings),
        fit_report={"temperature": "cubic + run constants"},
    )


#: the methods every validation compares: name -> fit_calibration options, or a function of the training runs
BASELINES: dict[str, Method | None] = {
    "raw": None,
    "PX4 cubic": fit_px4_style,
    "ArduPilot cubic": fit_ardupilot_style,
    "cubic + run constants": fit_plain_cubic,
    "gyrocomp default": FitOptions(),
    # the best model PX4's and ArduPilot's files carry (a cubic at most, clamped): what the firmware costs
    "gyrocomp for firmware": FitOptions(target="px4"),
}


@dataclass(frozen=True)
class Fold:
    """One held-out piece: its name, the run it belongs to, and its rows in that run."""

    name: str
    run: int
    rows: np.ndarray


@dataclass(frozen=True)
class MethodScore:
    """Held-out drift of one method on one gyro axis, per fold and on average [deg/s]."""

    method: str
    axis: str
    fold_drift_dps: tuple[float, ...]

    @property
    def mean_drift_dps(self) -> float:
        return fold_mean(self.fold_drift_dps)

    @property
    def standard_error_dps(self) -> float:
        """Standard error of the mean over the folds [deg/s] (NaN with one fold)."""
        return fold_standard_error(self.fold_drift_dps)

    def to_dict(self) -> dict:
        return {
            "method": self.method,
            "axis": self.axis,
            "mean_drift_dps": self.mean_drift_dps,
            "standard_error_dps": self.standard_error_dps,
            "fold_drift_dps": list(self.fold_drift_dps),
        }


@dataclass(frozen=True)
class ValidationResult:
    """Every method's held-out drift on every axis, with the folds and window used."""

    fold_kind: str
    folds: tuple[str, ...]
    window_s: float
    methods: tuple[str, ...]
    axes: tuple[str, ...]
    scores: tuple[MethodScore, ...]

    def score(self, method: str, axis: str) -> MethodScore:
        return next(s for s in self.scores if s.method == method and s.axis == axis)

    def mean_over_axes(self, method: str) -> float:
        """A method's held-out drift averaged over the axes [deg/s]."""
        return float(np.mean([self.score(method, a).mean_drift_dps for a in self.axes]))

    @property
    def title(self) -> str:
        """What the table shows: the quantity, window, statistic and folds."""
        return (
            f"held-out drift [deg/s], {self.window_s:g} s moving average, mean +- standard error over "
            f"{len(self.folds)} folds ({self.fold_kind})"
        )

    def table_rows(self) -> tuple[list[str], list[list[str]]]:
        """(header, rows) of the table ``gyrocomp validate`` prints and the report shows: per method, each axis's
        mean +- standard error [deg/s], the mean over the axes and its ratio to the plain cubic's."""
        cubic = self.mean_over_axes("cubic + run constants") if "cubic + run constants" in self.methods else 0.0
        rows = []
        for method in self.methods:
            cells = [
                with_error(self.score(method, a).mean_drift_dps, self.score(method, a).standard_error_dps)
                for a in self.axes
            ]
            mean = self.mean_over_axes(method)
            rows.append([method, *cells, f"{mean:.4g}", f"{mean / cubic:.2f}x" if cubic > 0 else "-"])
        return ["method", *self.axes, "mean", "vs cubic"], rows

    def to_dict(self) -> dict:
        return {
            "fold_kind": self.fold_kind,
            "folds": list(self.folds),
            "window_s": self.window_s,
            "methods": list(self.methods),
            "axes": list(self.axes),
            "mean_over_axes_dps": {m: self.mean_over_axes(m) for m in self.methods},
            "scores": [s.to_dict() for s in self.scores],
        }


def make_sample_folds(recordings: list[Recording], kind: str = "auto") -> tuple[str, list[Fold]]:
    """The folds of a validation, on samples: each run (``runs``), each heating or cooling leg (``legs``),
    or ``BLOCKS_PER_RUN`` contiguous blocks per run (``blocks``); ``auto`` as the model choice does."""
    if kind not in FOLD_KINDS:
        raise InputError(f"folds: {kind!r}; use one of {', '.join(FOLD_KINDS)}")
    if kind == "auto":
        kind = "runs" if len(recordings) >= MIN_FOLDS else "legs"
    if kind == "runs":
        if len(recordings) < 2:
            raise InputError("folds='runs' needs two runs or more; use 'legs' or 'blocks' for one run")
        return "runs", [Fold(f"run {k + 1}", k, np.arange(r.n_samples)) for k, r in enumerate(recordings)]
    if kind == "legs":
        folds = []
        for k, rec in enumerate(recordings):
            t = rec.temperature_for(rec.gyro_axes[0])
            labels, directions = leg_labels(t, turn_threshold_degc(t), _shortest_leg(rec))
            for j, d in enumerate(directions):
                folds.append(
                    Fold(
                        f"run {k + 1} leg {j + 1}" + {1: " (heating)", -1: " (cooling)"}.get(d, ""),
                        k,
                        np.flatnonzero(labels == j),
                    )
                )
        if len(folds) >= MIN_FOLDS:
            return "legs", folds
    per_run = max(BLOCKS_PER_RUN, math.ceil(MIN_FOLDS / len(recordings)))
    folds = []
    for k, rec in enumerate(recordings):
        parts = np.array_split(np.arange(rec.n_samples), per_run)
        folds += [Fold(f"run {k + 1} block {j + 1}", k, rows) for j, rows in enumerate(parts)]
    return "blocks", folds


def training_runs(recordings: list[Recording], fold: Fold, kind: str) -> list[Recording]:
    """The runs a fit without ``fold`` is made on: the other runs (``runs``), or every run with the fold's rows
    taken out (``legs``, ``blocks``); a run the fold holds whole or all but a sliver of (a run of one leg: less
    than a leg's shortest length left) is left out."""
    if kind == "runs":
        return [r for k, r in enumerate(recordings) if k != fold.run]
    out = []
    for k, rec in enumerate(recordings):
        if k == fold.run:
            keep = np.ones(rec.n_samples, dtype=bool)
            keep[fold.rows] = False
            if np.count_nonzero(keep) < _shortest_leg(rec):
                continue
            rec = rec.take(keep)
        out.append(rec)
    return out


def _shortest_leg(rec: Recording) -> int:
    """The fewest samples a leg of ``rec`` holds (as :func:`make_sample_folds` cuts them)."""
    return max(10, int(rec.rate_hz * WINDOW_MIN_S))


def fold_window_s(recordings: list[Recording], folds: list[Fold]) -> float:
    """The drift window of held-out folds [s], as the model choice takes it
    (:func:`gyrocomp.fitting.folds.drift_window_s` of the folds' lengths)."""
    lengths = [fold.rows.size / recordings[fold.run].rate_hz for fold in folds]
    return drift_window_s(lengths, max(1.0 / rec.rate_hz for rec in recordings))


@contextlib.contextmanager
def quiet_fold_fit() -> Iterator[None]:
    """The warnings of a fold's fit kept quiet (a range, data-quality or model-choice warning of a fit on part of
    the runs says nothing the user can act on)."""
    with warnings.catch_warnings():
        for category in (TemperatureRangeWarning, DataQualityWarning, ModelChoiceWarning):
            warnings.simplefilter("ignore", category)
        yield


def _fit(method: Method | None, train: list[Recording]) -> Calibration | None:
    return None if method is None else fit_method(method, train)


@single_threaded_blas
def validate(
    recordings: list[Recording],
    *,
    folds: FoldChoice = "auto",
    window_s: float | None = None,
    candidates: dict[str, Method] | None = None,
) -> ValidationResult:
    """Held-out drift of the baselines, gyrocomp's default and ``candidates`` on folds of ``recordings``.

    Parameters
    ----------
    recordings : list of Recording
        Calibration runs of one sensor at rest (each one power-on).
    folds : {"auto", "runs", "legs", "blocks"}
    window_s : float, optional
        Moving-average window of the drift [s]; default :func:`gyrocomp.fitting.folds.drift_window_s` of the
        folds (the model choice's): a tenth of the median fold, within 60..600 s, at most a quarter of the shortest.
    candidates : dict, optional
        Further methods: name -> :class:`~gyrocomp.models.options.FitOptions` of gyrocomp's fit (or a function of
        the training runs returning a Calibration).
    """
    # prepared once: every method and fold reads each run's still segments and block means from it
    recordings = prepare([recordings] if isinstance(recordings, Recording) else recordings)
    if not recordings:
        raise InputError("validate: give at least one calibration run")
    for rec in recordings:
        if rec.temperature_degc is None:
            raise InputError(f"{rec.source}: no temperature column; validation compares temperature models")
    require_temperature_span(recordings, "validate")
    for findings in repeated_findings(recordings).values():  # a run held out against itself
        raise InputError(findings[0].message)
    kind, fold_list = make_sample_folds(recordings, folds)
    if window_s is None:
        window_s = fold_window_s(recordings, fold_list)
    if not window_s > 0:
        raise InputError(f"window_s: must be positive, got {window_s}")
    methods = {**BASELINES, **(candidates or {})}
    axes = recordings[0].gyro_axes
    drift = {(m, a): [] for m in methods for a in axes}
    for fold in fold_list:
        train = training_runs(recordings, fold, kind)
        held = recordings[fold.run]
        w = max(1, int(round(window_s * held.rate_hz)))
        for name, method in methods.items():
            with quiet_fold_fit():
                cal = _fit(method, train)
                comp = held.gyro_dps if cal is None else apply(cal, held).gyro_dps
            for j, axis in enumerate(axes):
                drift[(name, axis)].append(smoothed_residual_rms(comp[fold.rows, j], w))
    scores = tuple(MethodScore(m, a, tuple(drift[(m, a)])) for m in methods for a in axes)
    return ValidationResult(kind, tuple(f.name for f in fold_list), window_s, tuple(methods), tuple(axes), scores)


__all__ = [
    "BASELINES",
    "Fold",
    "MethodScore",
    "ValidationResult",
    "fit_plain_cubic",
    "fold_window_s",
    "make_sample_folds",
    "quiet_fold_fit",
    "training_runs",
    "validate",
]
