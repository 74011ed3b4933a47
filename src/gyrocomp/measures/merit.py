"""The reference thesis's figures of merit for a compensation.

- *bias offset*: peak-to-peak of the moving average of the gyro output over a run [deg/s];
- *bias instability*: minimum of the overlapping Allan deviation divided by 0.664 [deg/h]
  (IEEE Std 952-1997, C.1: sigma_min = sqrt(2 ln 2 / pi) B), and the tau at that minimum,
  the *integration time* [s];
- *residual RMS*: RMS of the moving-averaged compensated output about its mean [deg/s].

M. Ali, *Correction of temperature and acceleration effects on MEMS gyro output signals*,
MS thesis, METU, 2014, sections 2.5.1 and 4.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Literal

import numpy as np

from ..allan import BIAS_INSTABILITY_FACTOR, AllanResult, allan_deviation, allan_deviation_segments
from ..effects import moving_average, moving_average_range
from ..errors import DataQualityWarning, InputError, user_stacklevel
from .plausibility import MAX_ACCEL_G, MAX_RATE_DPS
from ..recording import Recording
from ..units import AXIS_UNITS, DEG_PER_S_TO_DEG_PER_H, AxisUnit, check_axis_unit, in_unit

MIN_WINDOW_S = 1.0


def bias_offset(x: np.ndarray, window_samples: int) -> float:
    """Peak-to-peak of the moving average [unit of x] (:func:`gyrocomp.effects.moving_average`, its extremes
    found block by block: no array of the average's length)."""
    return moving_average_range(x, window_samples)


@dataclass(frozen=True)
class BiasInstability:
    """Bias instability [deg/h] and the averaging time at the Allan minimum [s]."""

    bias_instability_deg_per_h: float
    integration_time_s: float


def bias_instability(rate_dps: np.ndarray, rate_hz: float, stretches: list[slice] | None = None) -> BiasInstability:
    """Bias instability from the minimum of the octave overlapping Allan deviation of rate data [deg/s].

    With ``stretches`` (the pieces of a recording between time gaps), the Allan sums are pooled over
    them so that no difference spans a gap.
    """
    low = _allan_minimum(rate_dps, rate_hz, stretches)
    return BiasInstability(low.deviation / BIAS_INSTABILITY_FACTOR * DEG_PER_S_TO_DEG_PER_H, low.tau_s)


def _allan_minimum(x: np.ndarray, rate_hz: float, stretches: list[slice] | None):
    """The minimum of the octave overlapping Allan deviation [unit of x], pooled over ``stretches``."""
    if stretches is not None and len(stretches) > 1:
        return allan_deviation_segments([x[s] for s in stretches], rate_hz, taus="octave", confidence=None).minimum()
    return allan_deviation(x, rate_hz, taus="octave", confidence=None).minimum()


def default_window_s(recording: Recording) -> float:
    """The moving-average window the thesis uses: tau at the raw data's Allan minimum, at least 1 s.

    With several axes, the longest of their Allan-minimum taus.
    """
    stretches = recording.contiguous_stretches()
    taus = [
        bias_instability(recording.gyro_dps[:, j], recording.rate_hz, stretches).integration_time_s
        for j in range(len(recording.gyro_axes))
    ]
    return max(MIN_WINDOW_S, max(taus))


#: the unit of an axis's bias instability, by the unit of its values (:data:`gyrocomp.units.AXIS_UNITS`)
BIAS_INSTABILITY_UNITS = {"deg/s": "deg/h", "g": "ug"}
#: each figure under the name that says its unit, for a gyro axis and for an accelerometer axis
_NAMED = {
    "offset_raw": ("bias_offset_raw_dps", "bias_offset_raw_g"),
    "offset_comp": ("bias_offset_comp_dps", "bias_offset_comp_g"),
    "bias_instability_raw": ("bias_instability_raw_dph", "bias_instability_raw_ug"),
    "bias_instability_comp": ("bias_instability_comp_dph", "bias_instability_comp_ug"),
    "residual_rms": ("residual_rms_dps", "residual_rms_g"),
}


def _in_unit(name: str, unit: str) -> property:
    """A figure read under the name of its unit (:data:`_NAMED`), refusing an axis of the other unit."""
    return in_unit(name, unit, _NAMED[name][AXIS_UNITS.index(unit)])


@dataclass(frozen=True)
class AxisMetrics:
    """Raw and compensated figures of one axis over one run, in the axis's unit: ``unit`` for the offsets and the
    residual (deg/s for a gyro axis, g for an accelerometer axis, whose moving average follows gravity when the
    unit is turned: a static run), ``bias_instability_unit`` for the bias instability (deg/h or ug). The names
    that carry a unit (``bias_offset_raw_dps`` ... for a gyro axis, ``bias_offset_raw_g`` ... for an
    accelerometer's) refuse the other, and :meth:`to_dict` writes the figures under them."""

    unit: AxisUnit
    offset_raw: float
    offset_comp: float
    offset_improvement: float
    bias_instability_raw: float
    bias_instability_comp: float
    integration_time_raw_s: float
    integration_time_comp_s: float
    residual_rms: float

    def __post_init__(self) -> None:
        check_axis_unit(self.unit)

    @property
    def bias_instability_unit(self) -> str:
        return BIAS_INSTABILITY_UNITS[self.unit]

    def to_dict(self) -> dict[str, float]:
        """The figures under the names that say their units (``bias_offset_raw_dps`` ..., or ``..._g``)."""
        column = AXIS_UNITS.index(self.unit)
        return {
            (_NAMED[f.name][column] if f.name in _NAMED else f.name): getattr(self, f.name)
            for f in fields(self)
            if f.name != "unit"
        }

    bias_offset_raw_dps = _in_unit("offset_raw", "deg/s")
    bias_offset_comp_dps = _in_unit("offset_comp", "deg/s")
    bias_instability_raw_dph = _in_unit("bias_instability_raw", "deg/s")
    bias_instability_comp_dph = _in_unit("bias_instability_comp", "deg/s")
    residual_rms_dps = _in_unit("residual_rms", "deg/s")
    bias_offset_raw_g = _in_unit("offset_raw", "g")
    bias_offset_comp_g = _in_unit("offset_comp", "g")
    bias_instability_raw_ug = _in_unit("bias_instability_raw", "g")
    bias_instability_comp_ug = _in_unit("bias_instability_comp", "g")
    residual_rms_g = _in_unit("residual_rms", "g")


@dataclass(frozen=True)
class RunEvaluation:
    """Figures of one run, per gyro axis (and accelerometer axis, when compensated), with one moving-average
    window."""

    file: str
    window_s: float
    axes: dict[str, AxisMetrics]
    accel_axes: dict[str, AxisMetrics] = field(default_factory=dict)

    def to_dict(self) -> dict:
        out = {
            "file": self.file,
            "window_s": self.window_s,
            "axes": {name: m.to_dict() for name, m in self.axes.items()},
        }
        if self.accel_axes:
            out["accel_axes"] = {name: m.to_dict() for name, m in self.accel_axes.items()}
        return out


#: what a scale-factor figure measures: the norm of each still pose's specific force less 1 g [g], the error of
#: the gravity direction the gyro predicts after each turn between poses [deg], the rate error on each constant
#: stretch of a rate table (the raw output less its bias at rest) [deg/s]
TriadFigure = Literal["pose_norm_g", "turn_direction_deg", "rate_error_dps"]


@dataclass(frozen=True)
class TriadResiduals:
    """One run's residuals that the scale factor and misalignment decide, raw and compensated, one per still
    pose, turn or rate-table stretch (unit in ``figure``)."""

    file: str
    figure: TriadFigure
    raw: np.ndarray
    compensated: np.ndarray

    @property
    def rms_raw(self) -> float:
        return float(np.sqrt(np.mean(self.raw**2)))

    @property
    def rms_compensated(self) -> float:
        return float(np.sqrt(np.mean(self.compensated**2)))

    def to_dict(self) -> dict:
        return {
            "file": self.file,
            "figure": self.figure,
            "count": int(self.raw.size),
            "rms_raw": self.rms_raw,
            "rms_compensated": self.rms_compensated,
        }


@dataclass(frozen=True)
class Evaluation:
    """Figures of several runs; ``to_dict`` gives the JSON shape ``gyrocomp evaluate --json`` prints."""

    runs: list[RunEvaluation]
    triads: list[TriadResiduals] = field(default_factory=list)

    def to_dict(self) -> dict:
        out = {"runs": [run.to_dict() for run in self.runs]}
        if self.triads:
            out["scale_factor"] = [t.to_dict() for t in self.triads]
        return out


def window_samples(window_s: float, rate_hz: float, n_samples: int) -> int:
    """Number of samples in a window of ``window_s`` seconds, checked against the data length."""
    if not window_s > 0:
        raise InputError(f"window_s: must be positive, got {window_s}")
    w = max(1, int(round(window_s * rate_hz)))
    if w > n_samples:
        raise InputError(
            f"window_s: {window_s:g} s is longer than the run ({n_samples / rate_hz:.6g} s); choose a shorter window"
        )
    return w


def smoothed_about_mean(x: np.ndarray, window_samples: int) -> np.ndarray:
    """The moving-averaged series about its mean, MA_w[x] - mean(MA_w[x]) [unit of x]."""
    smooth = moving_average(np.asarray(x, dtype=float), window_samples)
    return smooth - smooth.mean()


def smoothed_residual_rms(x: np.ndarray, window_samples: int) -> float:
    """RMS about its mean of the moving-averaged series [unit of x] (of :func:`smoothed_about_mean`)."""
    return float(np.sqrt(np.mean(smoothed_about_mean(x, window_samples) ** 2)))


@dataclass(frozen=True)
class _Figures:
    """One axis's figures in its own unit (deviations at the Allan minimum, not yet divided by 0.664)."""

    offset_raw: float
    offset_comp: float
    improvement: float
    allan_min_raw: float
    allan_min_comp: float
    integration_time_raw_s: float
    integration_time_comp_s: float
    residual_rms: float

    @classmethod
    def of(cls, off_raw: float, off_comp: float, low_raw, low_comp, residual_rms: float) -> "_Figures":
        """From the bias offsets before and after, the Allan minima before and after (``deviation``, ``tau_s``)
        and the residual's RMS."""
        improvement = off_raw / off_comp if off_comp > 0 else math.inf
        return cls(
            off_raw,
            off_comp,
            improvement,
            low_raw.deviation,
            low_comp.deviation,
            low_raw.tau_s,
            low_comp.tau_s,
            residual_rms,
        )


def _figures(
    raw: np.ndarray, comp: np.ndarray, rate_hz: float, w: int, stretches: list[slice], lows: tuple | None = None
) -> _Figures:
    """``lows``: the raw and compensated Allan minima when already computed."""
    off_raw, off_comp = bias_offset(raw, w), bias_offset(comp, w)
    low_raw, low_comp = lows or (_allan_minimum(raw, rate_hz, stretches), _allan_minimum(comp, rate_hz, stretches))
    return _Figures.of(off_raw, off_comp, low_raw, low_comp, smoothed_residual_rms(comp, w))


def check_compensated(source: str, axis: str, values: np.ndarray, rows: np.ndarray | None = None) -> None:
    """Refuse to judge a compensation whose output is not finite or beyond any MEMS sensor's range (gyro
    :data:`gyrocomp.measures.plausibility.MAX_RATE_DPS` [deg/s], accelerometer :data:`gyrocomp.measures.plausibility.MAX_ACCEL_G`
    [g]): the model was applied far outside its temperature range (a corrupt temperature value), and every figure
    would be noise of the overflow. ``rows``: the file's row of each value, to name it (None: not known)."""
    limit, unit = (MAX_ACCEL_G, "g") if axis.startswith("accel") else (MAX_RATE_DPS, "deg/s")
    magnitude = np.abs(np.asarray(values, dtype=float))
    bad = ~(magnitude <= limit)  # NaN too
    if not bad.any():
        return
    k = int(np.flatnonzero(bad)[0])
    where = "" if rows is None else f" at row {int(rows[k])}"
    raise InputError(
        f"{source}: {axis} compensated is {values[k]:.3g} {unit}{where}, beyond any MEMS sensor's "
        f"range ({limit:g} {unit}): the model was applied far outside its temperature range (a "
        "corrupt temperature value?); nothing to judge"
    )


def _checked_stretches(raw: Recording, compensated: Recording, accel: bool) -> list[slice]:
    """The raw run's stretches between time gaps, after checking the compensated values (warns of the gaps)."""
    for j, axis in enumerate(compensated.gyro_axes):
        check_compensated(raw.source, axis, compensated.gyro_dps[:, j], raw.row_numbers)
    if accel and compensated.accel_g is not None:
        for j, axis in enumerate(compensated.accel_axes):
            check_compensated(raw.source, axis, compensated.accel_g[:, j], raw.row_numbers)
    stretches = raw.contiguous_stretches()
    if raw.gaps:
        warnings.warn(
            f"{raw.source}: {len(raw.gaps)} time gap(s); the Allan deviation pools the {len(stretches)} stretches "
            "between them, the moving average runs across them",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
    return stretches


def evaluate_run(
    raw: Recording,
    compensated: Recording,
    *,
    window_s: float | None = None,
    accel: bool = False,
    allan: tuple[Mapping[str, AllanResult], Mapping[str, AllanResult]] | None = None,
) -> RunEvaluation:
    """Compare one run before and after compensation, axis by axis.

    Parameters
    ----------
    raw, compensated : Recording
        The same run before and after compensation (same rows and axes).
    window_s : float, optional
        Moving-average window [s]; default :func:`default_window_s` of the raw run.
    accel : bool
        Also compare the accelerometer axes [g] (when the compensation covers them).
    allan : (mapping, mapping), optional
        The octave overlapping Allan deviation of each gyro axis of ``raw`` and of ``compensated`` (pooled over
        the stretches between time gaps), by axis, when the caller has them already (the report draws them):
        their minima are the bias instabilities, instead of computing the curves again.
    """
    stretches = _checked_stretches(raw, compensated, accel)
    # the Allan minima do not depend on the window; the default window is the raw minima's longest tau
    if allan is not None:
        lows = [(allan[0][axis].minimum(), allan[1][axis].minimum()) for axis in raw.gyro_axes]
    else:
        lows = [
            (
                _allan_minimum(raw.gyro_dps[:, j], raw.rate_hz, stretches),
                _allan_minimum(compensated.gyro_dps[:, j], raw.rate_hz, stretches),
            )
            for j in range(len(raw.gyro_axes))
        ]
    if window_s is None:
        window_s = max(MIN_WINDOW_S, max(low.tau_s for low, _ in lows))  # as default_window_s(raw)
    w = window_samples(window_s, raw.rate_hz, raw.n_samples)
    gyro = {
        axis: _figures(raw.gyro_dps[:, j], compensated.gyro_dps[:, j], raw.rate_hz, w, stretches, lows[j])
        for j, axis in enumerate(raw.gyro_axes)
    }
    accel_figures = {}
    if accel and raw.accel_g is not None and compensated.accel_g is not None:
        accel_figures = {
            axis: _figures(raw.accel_g[:, j], compensated.accel_g[:, j], raw.rate_hz, w, stretches)
            for j, axis in enumerate(raw.accel_axes)
        }
    return _run_evaluation(raw.source, window_s, gyro, accel_figures)


def _axis_metrics(f: _Figures, unit: str, to_bias_instability: float) -> AxisMetrics:
    """One axis's figures in its unit; ``to_bias_instability`` turns the Allan minimum into the bias instability
    in its unit (deg/h or ug)."""
    return AxisMetrics(
        unit,
        f.offset_raw,
        f.offset_comp,
        f.improvement,
        f.allan_min_raw * to_bias_instability,
        f.allan_min_comp * to_bias_instability,
        f.integration_time_raw_s,
        f.integration_time_comp_s,
        f.residual_rms,
    )


def _run_evaluation(
    source: str, window_s: float, gyro: dict[str, _Figures], accel: dict[str, _Figures]
) -> RunEvaluation:
    """The figures of each axis in their quoted units: gyro [deg/s, deg/h], accelerometer [g, ug]."""
    to_dph = DEG_PER_S_TO_DEG_PER_H / BIAS_INSTABILITY_FACTOR
    to_ug = 1e6 / BIAS_INSTABILITY_FACTOR
    axes = {axis: _axis_metrics(f, "deg/s", to_dph) for axis, f in gyro.items()}
    accel_axes = {axis: _axis_metrics(f, "g", to_ug) for axis, f in accel.items()}
    return RunEvaluation(file=source, window_s=float(window_s), axes=axes, accel_axes=accel_axes)


def evaluate_phases(
    source: str,
    raw: list[np.ndarray],
    compensated: list[np.ndarray],
    rate_hz: float,
    *,
    gyro_axes: tuple[str, ...],
    accel_axes: tuple[str, ...] = (),
    window_s: float | None = None,
) -> RunEvaluation:
    """:func:`evaluate_run` of one contiguous run given as phases, e.g. integrated chunk by chunk from a file
    (:class:`gyrocomp.allan.PhaseAccumulator`, possibly memory-mapped): the moving average of a series is a
    difference of its phase, (x[k + w] - x[k]) rate_hz / w, and the Allan deviation reads the phase itself.

    Parameters
    ----------
    source : str
        The run's file, for the result.
    raw, compensated : list of arrays (N+1,)
        The phase [unit*s] of each axis before and after compensation: ``gyro_axes`` [deg] then ``accel_axes``
        [g*s], in that order.
    rate_hz : float
        Sample rate [Hz].
    window_s : float, optional
        Moving-average window [s]; default the longest tau at the raw gyro axes' Allan minima, at least 1 s.
    """
    names = (*gyro_axes, *accel_axes)
    if not (len(raw) == len(compensated) == len(names)):
        raise InputError(
            f"raw, compensated: one phase per axis ({', '.join(names)}); got {len(raw)} and {len(compensated)}"
        )
    n_samples = len(raw[0]) - 1
    lows = [(_phase_allan_minimum(r, rate_hz), _phase_allan_minimum(c, rate_hz)) for r, c in zip(raw, compensated)]
    if window_s is None:
        window_s = max(MIN_WINDOW_S, max(low.tau_s for low, _ in lows[: len(gyro_axes)]))
    w = window_samples(window_s, rate_hz, n_samples)
    figures = {}
    for name, r, c, (low_raw, low_comp) in zip(names, raw, compensated, lows):
        off_raw, _ = _smoothed_spread(r, rate_hz, w)
        off_comp, rms = _smoothed_spread(c, rate_hz, w)
        figures[name] = _Figures.of(off_raw, off_comp, low_raw, low_comp, rms)
    return _run_evaluation(source, window_s, {a: figures[a] for a in gyro_axes}, {a: figures[a] for a in accel_axes})


def _phase_allan_minimum(phase: np.ndarray, rate_hz: float):
    return allan_deviation(phase, rate_hz, taus="octave", confidence=None, data_type="phase").minimum()


#: phase points read at once by _smoothed_spread
_PHASE_BLOCK = 1 << 20


def _smoothed_spread(phase: np.ndarray, rate_hz: float, w: int) -> tuple[float, float]:
    """Peak-to-peak and RMS about its mean of the ``w``-sample moving average of the series whose phase [unit*s]
    is given, block by block (:func:`bias_offset` and :func:`smoothed_residual_rms` of the series)."""
    count = len(phase) - w
    scale = rate_hz / w

    def averages():
        for start in range(0, count, _PHASE_BLOCK):
            stop = min(start + _PHASE_BLOCK, count)
            yield (np.asarray(phase[start + w : stop + w]) - np.asarray(phase[start:stop])) * scale

    low, high, total = math.inf, -math.inf, 0.0
    for smooth in averages():
        low, high, total = min(low, float(smooth.min())), max(high, float(smooth.max())), total + float(smooth.sum())
    mean = total / count
    squares = sum(float(np.dot(smooth - mean, smooth - mean)) for smooth in averages())
    return high - low, math.sqrt(squares / count)
