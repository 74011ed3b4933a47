"""The reference thesis's comparison of methods on one data set: raw, polynomial, network, each with
and without hysteresis compensation (M. Ali, METU, 2014, Tables 3.x and 4.4), and what the autopilots'
own tools fit (PX4's ``Tools/process_sensor_caldata.py``, ArduPilot's ``Tools/scripts/tempcal_IMU.py``).

With two runs or more every run is compensated by models fitted on the other runs (leave one run
out), so no method is scored on the data it was fitted on; with one run the models are fitted and
scored on that run, as the thesis did, and the result says so.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace

import numpy as np

from ..calibration import AxisCalibration, Calibration
from ..calibration.compensate import apply
from ..errors import DataQualityWarning, InputError, TemperatureRangeWarning
from ..measures.merit import default_window_s, evaluate_run, moving_average
from ..fitting.provenance import provenance
from ..models.options import FitOptions, Network, Polynomial
from ..models.pipelines import fit_pipeline
from ..curves.polynomial import PolynomialCurve
from ..measures.plausibility import require_temperature_span
from ..runs.prepared import prepare
from ..threads import single_threaded_blas
from ..recording import Recording

#: the polynomial order both autopilots use for the gyro bias against temperature
AUTOPILOT_ORDER = 3
#: PX4 process_sensor_caldata.py: median filter length [samples] and number of equal-width temperature bins
PX4_MEDIAN_SAMPLES = 31
PX4_BINS = 2000
#: ArduPilot tempcal_IMU.py: moving-average width [s] and the fixed reference temperature [degC]
ARDUPILOT_AVERAGE_S = 2
ARDUPILOT_TEMP_REF_DEGC = 35.0


def _cubic_calibration(recordings: list[Recording], name: str, fit_axis) -> Calibration:
    """A calibration holding, per gyro axis, the cubic ``fit_axis(recording list, axis)`` returns as
    (coefficients of np.polyfit in T - t_ref, highest first, t_ref, t_min, t_max)."""
    axes = {}
    for axis in recordings[0].gyro_axes:
        coef, t_ref, t_min, t_max = fit_axis(recordings, axis)
        shape = tuple(float(c) for c in coef[::-1][1:])  # np.polyfit: highest power first; X0 is the constant
        axes[axis] = AxisCalibration(
            PolynomialCurve(shape, float(t_ref), 1.0, float(t_min), float(t_max)),
            tuple(float(coef[-1]) for _ in recordings),
        )
    return Calibration(axes=axes, model=name, provenance=provenance(recordings), fit_report={"temperature": name})


def fit_px4_style(recordings: list[Recording]) -> Calibration:
    """The cubic PX4's ``Tools/process_sensor_caldata.py`` fits (its default, resampling on): the gyro
    through a 31-sample median filter (``scipy.signal.medfilt``), the samples in 2000 equal-width bins of
    temperature between its extremes, and ``np.polyfit`` of order 3 on the bin means, unweighted, in
    T - TREF with TREF the middle of the range; applied clamped to [TMIN, TMAX]. Several runs are pooled
    as one log.
    """
    from scipy.signal import medfilt  # scipy.signal is slow to import; only this baseline filters

    def fit_axis(recs, axis):
        temperature = np.concatenate([r.temperature_for(axis) for r in recs])
        gyro = np.concatenate([medfilt(r.gyro(axis), PX4_MEDIAN_SAMPLES) for r in recs])
        t_min, t_max = float(temperature.min()), float(temperature.max())
        t_ref = 0.5 * (t_min + t_max)
        span = t_max - t_min
        index = np.clip(
            ((temperature - t_min) / (span / PX4_BINS)).astype(np.int64)
            if span > 0
            else np.zeros(temperature.size, dtype=np.int64),
            0,
            PX4_BINS - 1,
        )
        count = np.bincount(index, minlength=PX4_BINS)
        full = count > 0
        t_mean = np.bincount(index, weights=temperature - t_ref, minlength=PX4_BINS)[full] / count[full]
        g_mean = np.bincount(index, weights=gyro, minlength=PX4_BINS)[full] / count[full]
        return np.polyfit(t_mean, g_mean, AUTOPILOT_ORDER), t_ref, t_min, t_max

    return _cubic_calibration(recordings, "PX4 cubic (process_sensor_caldata.py)", fit_axis)


def fit_ardupilot_style(recordings: list[Recording]) -> Calibration:
    """The cubic ArduPilot's ``Tools/scripts/tempcal_IMU.py`` fits from IMU records: gyro and temperature
    through a 2 s moving average (``int(samples / seconds) * 2`` samples), then ``np.polyfit`` of order 3
    over every sample, unweighted, in T - 35 degC; applied clamped to [TMIN, TMAX] of the log. Several runs
    are pooled as one log.
    """

    def fit_axis(recs, axis):
        temps, gyros = [], []
        for r in recs:
            w = int(r.n_samples / (r.time_s[-1] - r.time_s[0])) * ARDUPILOT_AVERAGE_S
            t, g = r.temperature_for(axis), r.gyro(axis)
            temps.append(moving_average(t, w) if w > 1 else t)  # its valid part, as tempcal_IMU.py keeps
            gyros.append(moving_average(g, w) if w > 1 else g)
        temperature, gyro = np.concatenate(temps), np.concatenate(gyros)
        coef = np.polyfit(temperature - ARDUPILOT_TEMP_REF_DEGC, gyro, AUTOPILOT_ORDER)
        return coef, ARDUPILOT_TEMP_REF_DEGC, float(temperature.min()), float(temperature.max())

    return _cubic_calibration(recordings, "ArduPilot cubic (tempcal_IMU.py)", fit_axis)


#: a method compared: the options of gyrocomp's fit, or a function of the training runs returning a Calibration
Method = FitOptions | Callable[[list[Recording]], Calibration]

#: the thesis's methods: name -> gyrocomp's fit with these options
THESIS_METHODS: dict[str, FitOptions] = {
    "polynomial": FitOptions(temperature=Polynomial(), hysteresis="none"),
    "polynomial + hysteresis": FitOptions(temperature=Polynomial(), hysteresis="turning-point"),
    "network": FitOptions(temperature=Network(), hysteresis="none"),
    "network + hysteresis": FitOptions(temperature=Network(), hysteresis="turning-point"),
}
#: what the autopilots' own calibration tools fit
AUTOPILOT_METHODS: dict[str, Callable[[list[Recording]], Calibration]] = {
    "PX4 cubic (process_sensor_caldata.py)": fit_px4_style,
    "ArduPilot cubic (tempcal_IMU.py)": fit_ardupilot_style,
}
#: the autopilots' fits, the thesis's methods and gyrocomp's default (lag and/or hysteresis chosen by the data)
DEFAULT_METHODS: dict[str, Method] = {**AUTOPILOT_METHODS, **THESIS_METHODS, "gyrocomp default (auto)": FitOptions()}


def fit_method(
    method: Method,
    train: list[Recording],
    *,
    hysteresis_band_degc: tuple[float, float] | None = None,
    seed: int | None = None,
) -> Calibration:
    """Fit one compared method on the training runs.

    Parameters
    ----------
    method : FitOptions or callable
        gyrocomp's fit with these options (:func:`gyrocomp.models.pipelines.fit_pipeline`), or a function of the
        training runs returning a Calibration (``AUTOPILOT_METHODS``).
    hysteresis_band_degc : (lo, hi), optional
        The band [degC] given to a method with a thermal memory (``hysteresis`` other than ``none``) that names
        none itself.
    seed : int, optional
        The seed of a network's initializations, replacing the method's own.
    """
    if callable(method):
        return method(train)
    if not isinstance(method, FitOptions):
        raise InputError(f"methods: FitOptions or a function of the training runs, got {type(method).__name__}")
    if hysteresis_band_degc is not None and method.hysteresis != "none" and method.hysteresis_band_degc is None:
        method = replace(method, hysteresis_band_degc=hysteresis_band_degc)
    if seed is not None and isinstance(method.temperature, Network):
        method = replace(method, temperature=replace(method.temperature, seed=seed))
    return fit_pipeline(train, "joint", method)


@dataclass(frozen=True)
class MethodRow:
    """One method on one axis, averaged over the scored runs.

    Attributes
    ----------
    bias_offset_dps : float
        Peak-to-peak of the moving-averaged output [deg/s].
    improvement : float
        Raw bias offset / this method's.
    bias_instability_deg_per_h : float
    integration_time_s : float
    """

    method: str
    axis: str
    bias_offset_dps: float
    improvement: float
    bias_instability_deg_per_h: float
    integration_time_s: float


@dataclass(frozen=True)
class MethodComparison:
    rows: list[MethodRow]
    how: str
    window_s: dict[str, float]

    def to_dict(self) -> dict:
        return {"how": self.how, "window_s": self.window_s, "rows": [asdict(r) for r in self.rows]}


@single_threaded_blas
def _method_row(name: str, axis: str, metrics: list) -> MethodRow:
    """One method's figures on one axis, averaged over the held-out runs (``raw``: the runs' raw figures)."""
    mean = lambda field: float(np.mean([getattr(m, field) for m in metrics]))  # noqa: E731
    if name == "raw":
        return MethodRow(
            name,
            axis,
            mean("bias_offset_raw_dps"),
            1.0,
            mean("bias_instability_raw_dph"),
            mean("integration_time_raw_s"),
        )
    offset, raw = mean("bias_offset_comp_dps"), mean("bias_offset_raw_dps")
    return MethodRow(
        name,
        axis,
        offset,
        raw / offset if offset > 0 else float("inf"),
        mean("bias_instability_comp_dph"),
        mean("integration_time_comp_s"),
    )


def compare_methods(
    recordings: list[Recording],
    *,
    methods: dict[str, Method] | None = None,
    window_s: float | None = None,
    hysteresis_band_degc: tuple[float, float] | None = None,
    seed: int | None = None,
) -> MethodComparison:
    """Score each method on the runs (see the module doc); the raw output is the first row of each axis.

    Parameters
    ----------
    recordings : list of Recording
        Runs of one sensor at rest through temperature changes.
    methods : dict, optional
        Name -> :class:`~gyrocomp.models.options.FitOptions` of gyrocomp's fit, or a function of the training runs
        returning a Calibration (``AUTOPILOT_METHODS``); default ``DEFAULT_METHODS``.
    window_s : float, optional
        Moving-average window [s]; default each run's raw Allan-minimum tau (the thesis's choice).
    hysteresis_band_degc : (lo, hi), optional
        Given to the methods with hysteresis that name no band themselves [degC].
    seed : int, optional
        The seed of the networks' initializations, replacing each method's own (default: each method's own; the
        thesis's networks use 0).
    """
    methods = DEFAULT_METHODS if methods is None else methods
    recordings = prepare(recordings)  # once for every method and held-out run
    if not recordings:
        raise InputError("compare: give at least one run")
    require_temperature_span(recordings, "compare")
    n = len(recordings)
    scored: dict[str, list] = {name: [] for name in ("raw", *methods)}
    windows = {}
    for held in range(n):
        rec = recordings[held]
        train = [r for i, r in enumerate(recordings) if i != held] if n > 1 else [rec]
        w = window_s if window_s is not None else default_window_s(rec)
        windows[rec.source] = w
        for name, options in methods.items():
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", TemperatureRangeWarning)
                warnings.simplefilter("ignore", DataQualityWarning)
                cal = fit_method(options, train, hysteresis_band_degc=hysteresis_band_degc, seed=seed)
                result = evaluate_run(rec, apply(cal, rec), window_s=w)
            scored[name].append(result)
            if name == next(iter(methods)):
                scored["raw"].append(result)
    rows = [
        _method_row(name, axis, [r.axes[axis] for r in results])
        for axis in recordings[0].gyro_axes
        for name, results in scored.items()
    ]
    how = (
        "leave one run out: each run compensated by models fitted on the other runs"
        if n > 1
        else "one run: the models are fitted and scored on the same run, as in the thesis (optimistic)"
    )
    return MethodComparison(rows, how, windows)


__all__ = [
    "AUTOPILOT_METHODS",
    "DEFAULT_METHODS",
    "Method",
    "MethodComparison",
    "MethodRow",
    "THESIS_METHODS",
    "compare_methods",
    "fit_ardupilot_style",
    "fit_method",
    "fit_px4_style",
]
