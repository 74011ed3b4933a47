"""The thermal calibration an autopilot holds: read back from its parameters as a gyrocomp model, and its
correction computed as the firmware computes it.

PX4 (``src/modules/temperature_compensation/TemperatureCompensation.cpp``, ``calc_thermal_offsets_3D``): the slot
``TC_G{i}_*`` whose ``TC_G{i}_ID`` equals the sensor's device id applies (``set_sensor_id_gyro``); the temperature
is clamped to [TMIN, TMAX], d = T - TREF, and the offset X0 + X1 d + X2 d^2 + X3 d^3 [rad/s] is subtracted from the
raw rate, in float32. ``TemperatureCompensationModule`` polls at 1 Hz and publishes new offsets only when the
temperature moved by more than 1 degC since the last publication (its ``last_temperature`` starts at -100 degC),
so as it runs the correction steps (:func:`px4_as_run`).

ArduPilot (``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``, ``TCal::correct_sensor`` and
``polynomial_eval``): T and the gyro calibration temperature T_cal (``INS_GYR{n}_CALTEMP``) are clamped to
[TMIN, TMAX]; v -= P(T - 35) - P(T_cal - 35) with P(d) = (c1 + (c2 + c3 d) d) d 1e-6 [rad/s], in float32: the
correction is relative to T_cal, where the boot-time gyro offset was taken.

A parameter the file leaves out has the firmware's default (:data:`FIRMWARE_DEFAULTS`: PX4 TMIN 0, TMAX 100,
TREF 25 degC; ArduPilot TMIN 0, TMAX 70 degC; coefficients 0), as on the vehicle. :mod:`gyrocomp.export.autopilot`
writes these parameters; reading them back lets gyrocomp judge the calibration a vehicle flies with against its
own, on the same data.

Units at the interface: temperature [degC], time [s], corrections [deg/s] (what is subtracted from the gyro's
output).
"""

from __future__ import annotations

import math
import warnings
from typing import Literal

import numpy as np

from .calibration import AxisCalibration, Calibration
from ..errors import DataQualityWarning, InputError, user_stacklevel
from ..curves.polynomial import PolynomialCurve

DEG_TO_RAD = math.pi / 180.0
ARDUPILOT_TEMP_REFERENCE_DEGC = 35.0
ARDUPILOT_SCALE = 1.0e6
AXIS_INDEX = {"gyro_x": 0, "gyro_y": 1, "gyro_z": 2}
RAD_TO_DEG = 180.0 / math.pi
Autopilot = Literal["px4", "ardupilot"]
#: what each firmware uses for a thermal-calibration parameter it was not given (PX4 ``temp_comp_params_gyro``,
#: ArduPilot ``AP_InertialSensor_TCal::var_info``) [degC]
FIRMWARE_DEFAULTS: dict[str, dict[str, float]] = {
    "px4": {"TMIN": 0.0, "TMAX": 100.0, "TREF": 25.0},
    "ardupilot": {"TMIN": 0.0, "TMAX": 70.0},
}
#: the gyro slots PX4's temperature compensation holds (``TC_G0`` to ``TC_G3``)
PX4_GYRO_SLOTS = 4
#: PX4's TemperatureCompensationModule: poll period [s] and the temperature change that republishes [degC]
PX4_POLL_S, PX4_REPUBLISH_DEGC = 1.0, 1.0


def _prefix(autopilot: str, instance: int) -> str:
    return f"TC_G{instance}_" if autopilot == "px4" else f"INS_TCAL{instance}_"


def _reader(params: dict, autopilot: str, prefix: str):
    """A lookup of ``prefix + name`` that falls back on the firmware's default (0 for a coefficient); refuses a
    parameter set that holds nothing of that slot."""
    if not any(str(k).startswith(prefix) for k in params):
        raise InputError(f"parameters: no {prefix}*; the file does not hold that sensor's thermal calibration")
    defaults = FIRMWARE_DEFAULTS[autopilot]
    return lambda name: float(params.get(prefix + name, defaults.get(name, 0.0)))


def px4_gyro_correction_dps(params: dict, temperature_degc: np.ndarray, instance: int = 0) -> np.ndarray:
    """(n, 3) offsets PX4 subtracts from gyro x, y, z [deg/s] at ``temperature_degc`` [degC], from the
    ``TC_G{instance}_*`` parameters, as ``calc_thermal_offsets_3D`` computes them (float32, clamped).

    Parameters
    ----------
    params : dict
        The vehicle's parameters (name to value).
    temperature_degc : array (n,)
        The gyro's temperature [degC].
    instance : int
        The ``TC_G`` slot, 0..3.
    """
    value = _reader(params, "px4", _prefix("px4", instance))
    f32 = np.float32
    t = np.asarray(temperature_degc, dtype=f32)
    d = np.clip(t, f32(value("TMIN")), f32(value("TMAX"))) - f32(value("TREF"))
    d2 = d * d
    d3 = d2 * d
    out = np.empty((t.size, 3))
    for j in range(3):
        x = [f32(value(f"X{k}_{j}")) for k in range(4)]
        out[:, j] = (x[0] + x[1] * d + x[2] * d2 + x[3] * d3).astype(float)
    return out * RAD_TO_DEG


def px4_as_run(params: dict, time_s: np.ndarray, temperature_degc: np.ndarray, instance: int = 0) -> np.ndarray:
    """(n, 3) the offsets [deg/s] PX4 applies at each sample as it runs: recomputed at each 1 s poll, published
    only when the temperature moved by more than 1 degC since the last publication (the first poll publishes).

    Parameters
    ----------
    params : dict
        The vehicle's parameters (name to value).
    time_s : array (n,)
        Sample times [s].
    temperature_degc : array (n,)
        The gyro's temperature [degC].
    instance : int
        The ``TC_G`` slot, 0..3.
    """
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
    # each publication holds from its sample to the next one's; before the first, nothing is applied
    held = np.repeat(offsets, np.diff(np.append(index, t.size)), axis=0)
    return np.concatenate([np.zeros((index[0], 3)), held]) if index[0] else held


def ardupilot_gyro_correction_dps(
    params: dict, temperature_degc: np.ndarray, cal_temp_degc: float, instance: int = 1
) -> np.ndarray:
    """(n, 3) what ArduPilot subtracts from gyro x, y, z [deg/s] at ``temperature_degc`` [degC], its gyro offsets
    taken at ``cal_temp_degc`` [degC], from the ``INS_TCAL{instance}_*`` parameters (``TCal::correct_sensor``).

    Parameters
    ----------
    params : dict
        The vehicle's parameters (name to value).
    temperature_degc : array (n,)
        The IMU's temperature [degC].
    cal_temp_degc : float
        The temperature the gyro offsets were taken at [degC] (:func:`ardupilot_cal_temp_degc`).
    instance : int
        The IMU, 1..3.
    """
    value = _reader(params, "ardupilot", _prefix("ardupilot", instance))
    f32 = np.float32
    lo, hi = f32(value("TMIN")), f32(value("TMAX"))
    t = np.clip(np.asarray(temperature_degc, dtype=f32), lo, hi) - f32(ARDUPILOT_TEMP_REFERENCE_DEGC)
    t_cal = np.clip(f32(cal_temp_degc), lo, hi) - f32(ARDUPILOT_TEMP_REFERENCE_DEGC)
    out = np.empty((t.size, 3))
    poly = np.empty_like(t)
    for j, axis in enumerate("XYZ"):
        c = [f32(value(f"GYR{k}_{axis}")) for k in (1, 2, 3)]
        scale = f32(1.0 / ARDUPILOT_SCALE)
        # (c0 + (c1 + c2 t) t) t scale in float32, in place: the same operations in the same order
        np.multiply(c[2], t, out=poly)
        poly += c[1]
        poly *= t
        poly += c[0]
        poly *= t
        poly *= scale
        poly -= (c[0] + (c[1] + c[2] * t_cal) * t_cal) * t_cal * scale
        out[:, j] = poly
    out *= RAD_TO_DEG
    return out


def px4_slot(params: dict, device_id: int | None) -> int | None:
    """The ``TC_G{i}`` slot PX4 applies to the gyro with ``device_id`` (the one whose ``TC_G{i}_ID`` equals it,
    as ``set_sensor_id_gyro`` chooses), or None: then the vehicle applies no thermal correction to that gyro.

    Parameters
    ----------
    params : dict
        The vehicle's parameters (name to value).
    device_id : int or None
        The gyro's device id (None: no slot).
    """
    if device_id is None:
        return None
    for i in range(PX4_GYRO_SLOTS):
        if f"TC_G{i}_ID" in params and int(params[f"TC_G{i}_ID"]) == int(device_id):
            return i
    return None


def ardupilot_cal_temp_degc(params: dict, instance: int = 1) -> float:
    """The temperature ArduPilot took its gyro offsets at (``INS_GYR_CALTEMP``, ``INS_GYR2_CALTEMP``, ... for
    ``instance`` 1, 2, ...) [degC]; -300 (ArduPilot's "never calibrated") when the parameters do not say: the
    correction then clamps it to TMIN, as the firmware does.

    Parameters
    ----------
    params : dict
        The vehicle's parameters (name to value).
    instance : int
        The IMU, 1..3.
    """
    return float(params.get("INS_GYR_CALTEMP" if instance == 1 else f"INS_GYR{instance}_CALTEMP", -300.0))


def installed_correction_dps(
    params: dict, autopilot: Autopilot, time_s: np.ndarray, temperature_degc: np.ndarray, instance: int
) -> np.ndarray:
    """(n, 3) what the firmware subtracts from gyro x, y, z [deg/s] at each sample as it runs: PX4's slot
    ``TC_G{instance}`` with its 1 Hz / 1 degC republish (:func:`px4_as_run`), ArduPilot's ``INS_TCAL{instance}``
    relative to its gyro calibration temperature (:func:`ardupilot_cal_temp_degc`).

    Parameters
    ----------
    params : dict
        The vehicle's parameters (names as the firmware spells them).
    autopilot : {"px4", "ardupilot"}
    time_s : array
        Sample times [s].
    temperature_degc : array
        The gyro's temperature at each sample [degC].
    instance : int
        PX4's slot from 0, ArduPilot's IMU from 1.
    """
    if autopilot == "px4":
        return px4_as_run(params, time_s, temperature_degc, instance)
    if autopilot == "ardupilot":
        return ardupilot_gyro_correction_dps(
            params, temperature_degc, ardupilot_cal_temp_degc(params, instance), instance
        )
    raise InputError(f"autopilot: {autopilot!r}; use px4 or ardupilot")


def installed_calibration(parameters: dict[str, float], autopilot: str, instance: int = 0) -> Calibration | None:
    """The gyro thermal calibration an autopilot holds, as a :class:`Calibration` (the inverse of
    :func:`px4_parameters` / :func:`ardupilot_parameters` for the gyro), or None when it is not enabled.

    Parameters
    ----------
    parameters : dict
        The log's parameters (``Recording.metadata["autopilot_parameters"]`` of a ULog or DataFlash log).
    autopilot : {"px4", "ardupilot"}
    instance : int
        The sensor instance from 0 (PX4 ``TC_G{instance}``, ArduPilot ``INS_TCAL{instance + 1}``).

    Notes
    -----
    The cubic becomes a polynomial in T - reference, held at TMIN and TMAX as the autopilots clip; PX4's X0 is the
    model's constant (ArduPilot's curve has none: its bias at the ordinary calibration's temperature belongs to
    the gyro offsets, so the constant is 0 and only drift is judged). PX4's SCL other than 1 is not modelled: a
    warning says so.
    """
    if autopilot == "px4":
        if int(parameters.get("TC_G_ENABLE", 0)) != 1:
            return None
        p = f"TC_G{instance}_"
        reference = parameters.get(f"{p}TREF", FIRMWARE_DEFAULTS["px4"]["TREF"])
        coefficients = [[parameters.get(f"{p}X{k}_{j}", 0.0) for k in range(4)] for j in range(3)]
        scales = [parameters.get(f"{p}SCL_{j}", 1.0) for j in range(3)]
        if any(abs(sc - 1.0) > 1e-6 for sc in scales):
            warnings.warn(
                f"{p}SCL_*: scale factors {scales} are not modelled; the offsets are",
                DataQualityWarning,
                stacklevel=user_stacklevel(),
            )
    elif autopilot == "ardupilot":
        p = f"INS_TCAL{instance + 1}_"
        if int(parameters.get(f"{p}ENABLE", 0)) != 1:
            return None
        reference = ARDUPILOT_TEMP_REFERENCE_DEGC
        coefficients = [
            [0.0, *(parameters.get(f"{p}GYR{k}_{a}", 0.0) / ARDUPILOT_SCALE for k in (1, 2, 3))] for a in "XYZ"
        ]
    else:
        raise InputError(f"autopilot: {autopilot!r}; use px4 or ardupilot")
    defaults = FIRMWARE_DEFAULTS[autopilot]
    t_min, t_max = parameters.get(f"{p}TMIN", defaults["TMIN"]), parameters.get(f"{p}TMAX", defaults["TMAX"])
    if not t_min < t_max:
        raise InputError(f"{p}TMIN {t_min:g} is not below {p}TMAX {t_max:g}: not a usable thermal calibration")
    axes = {}
    for name, j in AXIS_INDEX.items():
        c = [v / DEG_TO_RAD for v in coefficients[j]]  # rad/s -> deg/s
        curve = PolynomialCurve((c[1], c[2], c[3]), reference, 1.0, t_min, t_max)
        axes[name] = AxisCalibration(curve, (c[0],))
    return Calibration(
        axes=axes,
        model=f"installed {autopilot} cubic ({p}*)",
        provenance={"source": f"{autopilot} parameters {p}*"},
        fit_report={"temperature": "installed"},
    )


__all__ = [
    "ARDUPILOT_SCALE",
    "ARDUPILOT_TEMP_REFERENCE_DEGC",
    "AXIS_INDEX",
    "Autopilot",
    "DEG_TO_RAD",
    "FIRMWARE_DEFAULTS",
    "PX4_GYRO_SLOTS",
    "PX4_POLL_S",
    "PX4_REPUBLISH_DEGC",
    "RAD_TO_DEG",
    "ardupilot_cal_temp_degc",
    "ardupilot_gyro_correction_dps",
    "installed_calibration",
    "installed_correction_dps",
    "px4_as_run",
    "px4_gyro_correction_dps",
    "px4_slot",
]
