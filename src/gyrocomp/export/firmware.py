"""What the autopilots do with a parameter file: their temperature corrections evaluated as their source computes
them, and how far that is from the gyrocomp model it was exported from.

PX4 (``src/modules/temperature_compensation/TemperatureCompensation.cpp``, ``calc_thermal_offsets_3D``): the
temperature is clamped to [TMIN, TMAX], d = T - TREF, and the offset X0 + X1 d + X2 d^2 + X3 d^3 [rad/s] is
subtracted from the raw rate, in float32. ``TemperatureCompensationModule`` polls at 1 Hz and publishes new
offsets only when the temperature moved by more than 1 degC since the last publication (its ``last_temperature``
starts at -100 degC), so as it runs the correction steps (:func:`px4_as_run`).

ArduPilot (``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``, ``TCal::correct_sensor`` and
``polynomial_eval``): T and the gyro calibration temperature T_cal (``INS_GYRn_CALTEMP``) are clamped to
[TMIN, TMAX]; v -= P(T - 35) - P(T_cal - 35) with P(d) = (c1 + (c2 + c3 d) d) d 1e-6 [rad/s], in float32: the
correction is relative to T_cal, where the boot-time gyro offset was taken.

Units at the interface: temperature [degC], corrections [deg/s] (what is subtracted from the gyro's output).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..calibration import Calibration
from ..compensate import predict_error
from ..errors import InputError
from ..installed import ARDUPILOT_SCALE, ARDUPILOT_TEMP_REFERENCE_DEGC
from ..recording import GYRO_AXES, Recording

RAD_TO_DEG = 180.0 / math.pi
#: PX4's TemperatureCompensationModule: poll period [s] and the temperature change that republishes [degC]
PX4_POLL_S, PX4_REPUBLISH_DEGC = 1.0, 1.0
#: how far beyond the calibrated range the exports judge the firmware against the model [degC]
BEYOND_DEGC = 20.0


def _param(params: dict, name: str) -> float:
    if name not in params:
        raise InputError(f"parameters: no {name}; the file does not hold that sensor's thermal calibration")
    return float(params[name])


def px4_gyro_correction_dps(params: dict, temperature_degc: np.ndarray, instance: int = 0) -> np.ndarray:
    """(n, 3) offsets PX4 subtracts from gyro x, y, z [deg/s] at ``temperature_degc`` [degC], from the
    ``TC_G{instance}_*`` parameters, as ``calc_thermal_offsets_3D`` computes them (float32, clamped)."""
    p = f"TC_G{instance}_"
    f32 = np.float32
    t = np.asarray(temperature_degc, dtype=f32)
    d = np.clip(t, f32(_param(params, p + "TMIN")), f32(_param(params, p + "TMAX"))) - f32(_param(params, p + "TREF"))
    d2 = d * d
    d3 = d2 * d
    out = np.empty((t.size, 3))
    for j in range(3):
        x = [f32(_param(params, f"{p}X{k}_{j}")) for k in range(4)]
        out[:, j] = (x[0] + x[1] * d + x[2] * d2 + x[3] * d3).astype(float)
    return out * RAD_TO_DEG


def px4_as_run(params: dict, time_s: np.ndarray, temperature_degc: np.ndarray, instance: int = 0) -> np.ndarray:
    """(n, 3) the offsets [deg/s] PX4 applies at each sample as it runs: recomputed at each 1 s poll, published
    only when the temperature moved by more than 1 degC since the last publication (the first poll publishes)."""
    t = np.asarray(time_s, dtype=float)
    temp = np.asarray(temperature_degc, dtype=float)
    polls = np.flatnonzero(np.diff(np.floor((t - t[0]) / PX4_POLL_S), prepend=-1.0) > 0) if t.size else []
    published_at, last = [], -100.0
    for k in polls:
        if abs(temp[k] - last) > PX4_REPUBLISH_DEGC:
            published_at.append(k)
            last = temp[k]
    if not published_at:
        return np.zeros((t.size, 3))
    index = np.asarray(published_at)
    offsets = px4_gyro_correction_dps(params, temp[index], instance)
    which = np.searchsorted(index, np.arange(t.size), side="right") - 1
    out = offsets[np.maximum(which, 0)]
    out[which < 0] = 0.0  # before the first publication nothing is applied
    return out


def ardupilot_gyro_correction_dps(params: dict, temperature_degc: np.ndarray, cal_temp_degc: float,
                                  instance: int = 1) -> np.ndarray:
    """(n, 3) what ArduPilot subtracts from gyro x, y, z [deg/s] at ``temperature_degc`` [degC], its gyro offsets
    taken at ``cal_temp_degc`` [degC], from the ``INS_TCAL{instance}_*`` parameters (``TCal::correct_sensor``)."""
    p = f"INS_TCAL{instance}_"
    f32 = np.float32
    lo, hi = f32(_param(params, p + "TMIN")), f32(_param(params, p + "TMAX"))
    t = np.clip(np.asarray(temperature_degc, dtype=f32), lo, hi) - f32(ARDUPILOT_TEMP_REFERENCE_DEGC)
    t_cal = np.clip(f32(cal_temp_degc), lo, hi) - f32(ARDUPILOT_TEMP_REFERENCE_DEGC)
    out = np.empty((t.size, 3))
    for j, axis in enumerate("XYZ"):
        c = [f32(_param(params, f"{p}GYR{k}_{axis}")) for k in (1, 2, 3)]
        scale = f32(1.0 / ARDUPILOT_SCALE)
        poly = (c[0] + (c[1] + c[2] * t) * t) * t * scale
        poly_cal = (c[0] + (c[1] + c[2] * t_cal) * t_cal) * t_cal * scale
        out[:, j] = (poly - poly_cal).astype(float)
    return out * RAD_TO_DEG


@dataclass(frozen=True)
class FirmwareDifference:
    """How far the firmware's correction is from the model's [deg/s], per gyro axis the model has: the largest
    and the RMS difference inside the calibrated range, beyond it (``BEYOND_DEGC`` each side: the firmware clamps,
    the model continues), and over a heat-cool cycle through the range as the firmware runs (PX4's steps, the
    model's lag and hysteresis: what the file cannot carry). Each is taken about its mean: a constant is the turn-on
    bias, which neither removes."""

    target: str
    axes: tuple[str, ...]
    in_range_max_dps: tuple[float, ...]
    in_range_rms_dps: tuple[float, ...]
    beyond_max_dps: tuple[float, ...]
    beyond_rms_dps: tuple[float, ...]
    as_run_max_dps: tuple[float, ...]
    as_run_rms_dps: tuple[float, ...]

    def lines(self) -> list[str]:
        """The figures in words, one line per axis."""
        return [f"{axis}: firmware vs model, largest (RMS) [deg/s]: {self.in_range_max_dps[j]:.2g} "
                f"({self.in_range_rms_dps[j]:.2g}) in range, {self.beyond_max_dps[j]:.2g} ({self.beyond_rms_dps[j]:.2g}) "
                f"up to {BEYOND_DEGC:g} degC beyond it, {self.as_run_max_dps[j]:.2g} ({self.as_run_rms_dps[j]:.2g}) "
                f"through a 1 degC/min heat-cool cycle as it runs" for j, axis in enumerate(self.axes)]


def _stats(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    a = a - a.mean(axis=0)
    return np.max(np.abs(a), axis=0), np.sqrt(np.mean(a ** 2, axis=0))


def firmware_difference(calibration: Calibration, params: dict, target: str, instance: int) -> FirmwareDifference:
    """The firmware's correction against the model's (:class:`FirmwareDifference`); ``target`` ``px4`` or
    ``ardupilot``, ``params`` the exported parameter values."""
    axes = tuple(a for a in GYRO_AXES if a in calibration.axes and calibration.axes[a].temperature is not None)
    curves = [calibration.axes[a].temperature for a in axes]
    lo, hi = min(c.t_min_degc for c in curves), max(c.t_max_degc for c in curves)
    cols = [GYRO_AXES.index(a) for a in axes]
    inside = np.linspace(lo, hi, 400)
    beyond = np.concatenate([np.linspace(lo - BEYOND_DEGC, lo, 100), np.linspace(hi, hi + BEYOND_DEGC, 100)])
    # a heat-cool cycle at 1 degC/min through the range, 1 Hz: the model's memory and PX4's steps both show
    ramp = np.concatenate([np.linspace(lo, hi, int(60 * (hi - lo)) + 2), np.linspace(hi, lo, int(60 * (hi - lo)) + 2)])
    time_s = np.arange(ramp.size, dtype=float)

    def model(temperature: np.ndarray, time: np.ndarray | None = None) -> np.ndarray:
        t = np.arange(temperature.size, dtype=float) if time is None else time
        rec = Recording(t, np.zeros((t.size, len(axes))), axes, temperature_degc=temperature, source="<firmware>")
        return predict_error(calibration, rec)

    def firmware(temperature: np.ndarray, time: np.ndarray | None = None) -> np.ndarray:
        if target == "px4":
            out = px4_as_run(params, time, temperature, instance) if time is not None else \
                px4_gyro_correction_dps(params, temperature, instance)
        else:
            out = ardupilot_gyro_correction_dps(params, temperature, 0.5 * (lo + hi), instance)
        return out[:, cols]

    # static points of the curve (no history): the model without its memory there; the cycle with it
    static = calibration.without("hysteresis", "lag") if any(
        calibration.axes[a].has_memory for a in axes) else calibration
    diffs = []
    for temps in (inside, beyond):
        rec = Recording(np.arange(temps.size, dtype=float), np.zeros((temps.size, len(axes))), axes,
                        temperature_degc=temps, source="<firmware>")
        diffs.append(firmware(temps) - predict_error(static, rec))
    diffs.append(firmware(ramp, time_s) - model(ramp, time_s))
    (a, b), (c, d), (e, f) = (_stats(x) for x in diffs)
    as_tuple = lambda x: tuple(float(v) for v in x)  # noqa: E731
    return FirmwareDifference(target, axes, as_tuple(a), as_tuple(b), as_tuple(c), as_tuple(d), as_tuple(e),
                              as_tuple(f))


__all__ = ["BEYOND_DEGC", "FirmwareDifference", "ardupilot_gyro_correction_dps", "firmware_difference",
           "px4_as_run", "px4_gyro_correction_dps"]
