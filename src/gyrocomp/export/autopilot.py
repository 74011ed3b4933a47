"""PX4 and ArduPilot thermal-calibration parameters from a gyrocomp model.

Both autopilots correct the gyro bias with a cubic in temperature, in rad/s, and nothing else:

- PX4 (``src/lib/temperature_compensation``, parameters ``TC_G{i}_*``): offset = X0 + X1 d + X2 d^2 + X3 d^3
  with d = clip(T, TMIN, TMAX) - TREF, and corrected = (raw - offset) * SCL.
- ArduPilot (``AP_InertialSensor_tempcal.cpp``, parameters ``INS_TCAL{n}_*``): P(d) = (c1 + (c2 + c3 d) d) d
  * 1e-6 with d = clip(T, TMIN, TMAX) - 35 degC, and corrected = raw - P(T) + P(T_cal), T_cal being the
  temperature at which the ordinary gyro offsets were taken (the bias at T_cal is theirs to remove).

When the model compensates the accelerometer too (``fit --channels gyro,accel``), its axes are written the
same way in m/s^2: PX4 ``TC_A{i}_*`` (relative to TREF: the accelerometer's constant stays with its ordinary
calibration), ArduPilot ``INS_TCAL{n}_ACC{1,2,3}_{X,Y,Z}``. An accelerometer triad (multi-position
calibration) is that ordinary calibration: both autopilots correct (raw - offset) * scale per axis, PX4 with
``CAL_ACC{i}_{X,Y,Z}OFF`` [m/s^2] and ``CAL_ACC{i}_{X,Y,Z}SCALE`` (``sensors/.../Calibration::Correct``),
ArduPilot with ``INS_ACC{,2,3}OFFS_{X,Y,Z}`` [m/s^2] and ``INS_ACC{,2,3}SCAL_{X,Y,Z}``; the offsets are the
triad's bias and the scales 1 / K_ii, and the misalignment (off-diagonal K) is left out with a warning, as is
the gyro's scale factor and misalignment, which neither autopilot holds.

gyrocomp's temperature curve (a polynomial of any order, or a network) is converted to that cubic by
least squares on a dense grid over the model's range; the largest difference is reported, and is zero
(to rounding) for polynomials of order 3 or less. Thermal lag, hysteresis and g-sensitivity have no
place in either autopilot: they are left out with a warning that says how much correction is lost.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..calibration import AxisCalibration, Calibration
from ..calibration.installed import (
    ARDUPILOT_SCALE,
    ARDUPILOT_TEMP_REFERENCE_DEGC,
    AXIS_INDEX,
    DEG_TO_RAD,
    installed_calibration,
)
from ..errors import DataQualityWarning, InputError, user_stacklevel
from ..units import STANDARD_GRAVITY_M_PER_S2
from .encode import line_comment

ACCEL_INDEX = {"accel_x": 0, "accel_y": 1, "accel_z": 2}
G_TO_M_PER_S2 = STANDARD_GRAVITY_M_PER_S2
GRID_POINTS = 401
#: a cubic's term that changes the correction by less than this over the calibrated range is written as 0
#: [rad/s, or m/s^2]: 1e-10 rad/s is 6e-9 deg/s, far below any gyro's noise and float32's resolution
NEGLIGIBLE_SI = 1e-10


@dataclass(frozen=True)
class CubicFit:
    """One axis's temperature curve as a cubic in d = T - reference [rad/s per degC^k, or m/s^2 per degC^k
    for an accelerometer], and how far it is from gyrocomp's curve over [t_min, t_max] [deg/s, or g]."""

    coefficients_rad_per_s: tuple[float, float, float, float]  # X0..X3 (m/s^2 for an accelerometer axis)
    reference_degc: float
    t_min_degc: float
    t_max_degc: float
    max_error_dps: float  # [g] for an accelerometer axis


def cubic_of(axis: AxisCalibration, reference_degc: float, with_constant: bool, to_si: float = DEG_TO_RAD) -> CubicFit:
    """Least-squares cubic of an axis's bias (shape plus mean turn-on constant) in d = T - reference;
    ``to_si`` converts the model's unit to the autopilot's (deg/s -> rad/s, or g -> m/s^2)."""
    curve = axis.temperature
    if curve is None:
        raise InputError("export: the model has no temperature curve on this axis; fit one (temperature= a polynomial)")
    t = np.linspace(curve.t_min_degc, curve.t_max_degc, GRID_POINTS)
    bias_dps = np.asarray(curve.shape(t), dtype=float) + (axis.mean_turn_on_bias if with_constant else 0.0)
    d = t - reference_degc
    powers = np.column_stack([d**k for k in (range(4) if with_constant else range(1, 4))])
    target = bias_dps if with_constant else bias_dps - np.asarray(curve.shape(np.array([reference_degc]))[0])
    coef, *_ = np.linalg.lstsq(powers, target, rcond=None)
    # a term that moves the correction by less than NEGLIGIBLE_SI over the range is rounding (a 1e-20 cubic of a
    # curve that is a line): written as 0
    reach = np.max(np.abs(d))
    orders = np.arange(4) if with_constant else np.arange(1, 4)
    coef = np.where(np.abs(coef * to_si) * reach**orders < NEGLIGIBLE_SI, 0.0, coef)
    error = float(np.max(np.abs(powers @ coef - target)))
    full = tuple(float(c) for c in coef) if with_constant else (0.0, *map(float, coef))
    return CubicFit(tuple(c * to_si for c in full), reference_degc, curve.t_min_degc, curve.t_max_degc, error)


def _warn_left_out(calibration: Calibration, target: str) -> None:
    parts = []
    every = list(calibration.axes.values()) + list(calibration.accel_axes.values())
    if any(ax.lag_time_constant_s > 0 for ax in every):
        parts.append("thermal lag")
    parts += sorted({ax.hysteresis.title for ax in every if ax.hysteresis is not None})
    parts += sorted({ax.rate_term.title for ax in every if ax.rate_term is not None})
    if any(ax.needs_accel for ax in calibration.axes.values()):
        parts.append("g-sensitivity")
    if calibration.gyro_triad is not None:
        parts.append("gyro scale-factor and misalignment")
    triad = calibration.accel_triad
    if triad is not None:
        off = float(np.max(np.abs(triad.misalignment)))
        if off > 0:
            parts.append(f"accelerometer misalignment (up to {off * 1e3:.2g} mrad; its offsets and scales are written)")
        if triad.sensitivity_per_degc:
            parts.append("accelerometer scale-factor temperature dependence")
    if parts:
        warnings.warn(
            f"{target} has no {' or '.join(parts)} term: left out of the export, only the temperature cubic "
            "and the accelerometer's offsets and scales are written (compare the stages of the evaluation "
            "to see what that costs)",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )


def accel_offsets_and_scales(calibration: Calibration) -> tuple[np.ndarray, np.ndarray] | None:
    """The accelerometer triad as the autopilots hold it, corrected = (raw - offset) * scale per axis: offsets
    [m/s^2] (the triad's bias) and scales (1 / K_ii: misalignment has no place there), or None without a triad."""
    triad = calibration.accel_triad
    if triad is None:
        return None
    return np.asarray(triad.bias, dtype=float) * G_TO_M_PER_S2, 1.0 / np.diag(
        np.asarray(triad.sensitivity, dtype=float)
    )


def _gyro_axes(calibration: Calibration) -> dict[str, AxisCalibration]:
    """The gyro axes with a temperature curve (refused when neither they nor accelerometer axes exist)."""
    axes = {name: ax for name, ax in calibration.axes.items() if name in AXIS_INDEX and ax.temperature is not None}
    if not axes and not _accel_axes(calibration) and calibration.accel_triad is None:
        raise InputError(
            "export: the model has no gyro or accelerometer axis with a temperature curve and no "
            "accelerometer calibration; nothing to export"
        )
    return axes


@dataclass(frozen=True)
class AutopilotParameters:
    """Parameter names and values, and the cubic fit of each axis."""

    values: dict[str, float]
    fits: dict[str, CubicFit]


def _accel_axes(calibration: Calibration) -> dict[str, AxisCalibration]:
    return {
        name: ax for name, ax in calibration.accel_axes.items() if name in ACCEL_INDEX and ax.temperature is not None
    }


def _range(axes: dict[str, AxisCalibration]) -> tuple[float, float]:
    return (
        min(ax.temperature.t_min_degc for ax in axes.values()),
        max(ax.temperature.t_max_degc for ax in axes.values()),
    )


#: where a user finds a PX4 sensor's device id, per sensor, for the refusal's message
_WHERE_ID = {"G": ("device_id", "sensor_gyro", "CAL_GYRO0_ID"), "A": ("accel_device_id", "sensor_accel", "CAL_ACC0_ID")}


def model_device_id(calibration: Calibration, key: str = "device_id") -> int | None:
    """The device id the model's runs name (``device_id`` of the gyro, ``accel_device_id`` of the accelerometer,
    recorded from a ULog's ``sensor_gyro``/``sensor_accel``), or None when no run names one; runs of different
    sensors are refused, naming their ids."""
    ids = sorted(
        {
            int(i[key])
            for i in (calibration.provenance or {}).get("inputs", ())
            if isinstance(i, dict) and isinstance(i.get(key), int) and i[key] != 0
        }
    )
    if len(ids) > 1:
        raise InputError(
            f"export: the model's runs come from sensors with {key} {', '.join(map(str, ids))}; "
            "a PX4 slot applies to one (give it with device_id= / accel_device_id=)"
        )
    return ids[0] if ids else None


def _device_id(calibration: Calibration, sensor: str, given: int | None) -> int:
    if given is not None:
        if not 0 < given < 2**32:
            raise InputError(f"{_WHERE_ID[sensor][0]}: a PX4 device id is a positive 32-bit number, got {given}")
        return given
    found = model_device_id(calibration, "device_id" if sensor == "G" else "accel_device_id")
    if found is None:
        option, topic, param = _WHERE_ID[sensor]
        raise InputError(
            f"PX4 export: no {'gyro' if sensor == 'G' else 'accelerometer'} device id (PX4 applies "
            f"TC_{sensor}n_* only to the sensor whose device id matches, so 0 does nothing); give "
            f"{option}=ID: find it in the ULog's {topic} topic, with 'listener {topic}' on the vehicle, or "
            f"in the {param} parameter"
        )
    return found


def px4_parameters(
    calibration: Calibration, *, instance: int = 0, device_id: int | None = None, accel_device_id: int | None = None
) -> AutopilotParameters:
    """``TC_G{instance}_*`` (and ``TC_A{instance}_*``) for PX4: TREF is the middle of the model's range, axes not in
    the model 0. ``TC_Gn_ID``/``TC_An_ID``: ``device_id``/``accel_device_id``, else the ids the model's runs
    recorded (:func:`model_device_id`); without one the export is refused (PX4 would apply nothing). No
    ``TC_*_SCL_*``: PX4 removed them (QGroundControl reports each as a parameter that does not exist).

    Reference: PX4 ``src/modules/temperature_compensation/TemperatureCompensation.cpp`` (``calc_thermal_offsets_3D``,
    the slot chosen by ``TC_Gn_ID == device_id``)."""
    if not 0 <= instance <= 3:
        raise InputError(f"instance: PX4 has thermal compensation for gyros 0..3, got {instance}")
    _warn_left_out(calibration, "PX4")
    values: dict[str, float] = {}
    fits = {}
    for sensor, axes, index, to_si, with_constant, given in (
        ("G", _gyro_axes(calibration), AXIS_INDEX, DEG_TO_RAD, True, device_id),
        ("A", _accel_axes(calibration), ACCEL_INDEX, G_TO_M_PER_S2, False, accel_device_id),
    ):
        if not axes:
            continue
        t_min, t_max = _range(axes)
        t_ref = 0.5 * (t_min + t_max)
        p = f"TC_{sensor}{instance}_"
        values.update(
            {
                f"TC_{sensor}_ENABLE": 1,
                f"{p}ID": _device_id(calibration, sensor, given),
                f"{p}TMIN": t_min,
                f"{p}TMAX": t_max,
                f"{p}TREF": t_ref,
            }
        )
        for name, j in index.items():
            fit = cubic_of(axes[name], t_ref, with_constant=with_constant, to_si=to_si) if name in axes else None
            coef = fit.coefficients_rad_per_s if fit else (0.0, 0.0, 0.0, 0.0)
            for k in range(4):
                values[f"{p}X{k}_{j}"] = coef[k]
            if fit:
                fits[name] = fit
    triad = accel_offsets_and_scales(calibration)
    if triad is not None:
        p = f"CAL_ACC{instance}_"
        values[f"{p}ID"] = _device_id(calibration, "A", accel_device_id)
        values.update({f"{p}{a}OFF": float(triad[0][j]) for j, a in enumerate("XYZ")})
        values.update({f"{p}{a}SCALE": float(triad[1][j]) for j, a in enumerate("XYZ")})
    return AutopilotParameters(values, fits)


def ardupilot_parameters(calibration: Calibration, *, instance: int = 1) -> AutopilotParameters:
    """``INS_TCAL{instance}_*`` for ArduPilot: cubic without constant about 35 degC, coefficients x 1e6
    (gyro in rad/s, accelerometer in m/s^2)."""
    if not 1 <= instance <= 3:
        raise InputError(f"instance: ArduPilot numbers its IMUs 1..3, got {instance}")
    _warn_left_out(calibration, "ArduPilot")
    gyro, accel = _gyro_axes(calibration), _accel_axes(calibration)
    values: dict[str, float] = {}
    fits = {}
    triad = accel_offsets_and_scales(calibration)
    if triad is not None:  # INS_ACCOFFS_X for the first IMU, INS_ACC2OFFS_X for the second, ...
        n = "" if instance == 1 else str(instance)
        values.update({f"INS_ACC{n}OFFS_{a}": float(triad[0][j]) for j, a in enumerate("XYZ")})
        values.update({f"INS_ACC{n}SCAL_{a}": float(triad[1][j]) for j, a in enumerate("XYZ")})
    if not gyro and not accel:
        return AutopilotParameters(values, fits)
    t_min, t_max = _range({**gyro, **accel})
    p = f"INS_TCAL{instance}_"
    values.update({f"{p}ENABLE": 1, f"{p}TMIN": t_min, f"{p}TMAX": t_max})
    for sensor, axes, index, to_si in (
        ("ACC", accel, ACCEL_INDEX, G_TO_M_PER_S2),
        ("GYR", gyro, AXIS_INDEX, DEG_TO_RAD),
    ):
        for name, j in index.items():
            fit = (
                cubic_of(axes[name], ARDUPILOT_TEMP_REFERENCE_DEGC, with_constant=False, to_si=to_si)
                if name in axes
                else None
            )
            coef = fit.coefficients_rad_per_s if fit else (0.0, 0.0, 0.0, 0.0)
            for k in (1, 2, 3):
                values[f"{p}{sensor}{k}_{'XYZ'[j]}"] = coef[k] * ARDUPILOT_SCALE
            if fit:
                fits[name] = fit
    return AutopilotParameters(values, fits)


#: what to do with the file on the vehicle, in order (PX4: TemperatureCompensationModule.cpp and
#: sensor_calibration/Gyroscope.hpp; ArduPilot: AP_InertialSensor_tempcal.cpp and AP_InertialSensor.cpp)
_STEPS = {
    "PX4": (
        "load it in QGroundControl (Vehicle Setup > Parameters > Tools > Load from file)",
        "reboot: TC_G_ENABLE / TC_A_ENABLE take effect at start-up",
        "PX4 subtracts CAL_GYRO*_XOFF/YOFF/ZOFF after these offsets: calibrate the gyro again (or zero them), "
        "and calibrate the accelerometer again after loading TC_A*",
        "outside TMIN..TMAX PX4 holds the correction at its edge; it updates it at 1 Hz when the temperature "
        "moved by more than 1 degC",
    ),
    "ArduPilot": (
        "set INS_TCAL<n>_ENABLE = 1 first (the INS_TCAL<n>_* group is hidden until then): load the file, "
        "refresh the parameters, load it again",
        "reboot",
        "INS_GYR<n>_CALTEMP must hold a valid temperature (calibrate the gyro once at start-up); the "
        "boot-time gyro offset is taken without this correction: keep the vehicle still at boot",
        "outside TMIN..TMAX ArduPilot holds the correction at its edge",
    ),
}


def _header(calibration: Calibration, params: AutopilotParameters, target: str, comment: str) -> list[str]:
    lines = [
        f"{comment} {target} thermal calibration written by gyrocomp from model '{line_comment(calibration.model)}'",
        f"{comment} bias as a cubic in temperature [rad/s, accelerometer m/s^2]; largest difference from the "
        "gyrocomp model over its range:",
    ]
    for name, fit in params.fits.items():
        unit = "g" if name in ACCEL_INDEX else "deg/s"
        lines.append(
            f"{comment}   {name}: {fit.max_error_dps:.3g} {unit} over {fit.t_min_degc:.2f}..{fit.t_max_degc:.2f} degC"
        )
    lines.append(f"{comment} on the vehicle, in this order:")
    lines += [f"{comment}   {k}. {step}" for k, step in enumerate(_STEPS[target], 1)]
    return lines


def px4_params_file(
    calibration: Calibration, *, instance: int = 0, device_id: int | None = None, accel_device_id: int | None = None
) -> str:
    """A QGroundControl parameter file (vehicle 1, component 1; type 6 = int32, 9 = float32) of
    :func:`px4_parameters` (``instance`` 0..3 of the sensor, its device ids)."""
    return px4_params_text(
        calibration,
        px4_parameters(calibration, instance=instance, device_id=device_id, accel_device_id=accel_device_id),
    )


def px4_params_text(calibration: Calibration, params: AutopilotParameters) -> str:
    """The QGroundControl file of parameters already computed (:func:`px4_parameters` of ``calibration``)."""
    lines = _header(calibration, params, "PX4", "#")
    lines.append("# Vehicle-Id Component-Id Name Value Type")
    for name, value in params.values.items():
        integer = name in ("TC_G_ENABLE", "TC_A_ENABLE") or name.endswith("_ID")
        lines.append(
            f"1\t1\t{name}\t{int(value) if integer else format(np.float32(value), '.9g')}\t{6 if integer else 9}"
        )
    return "\n".join(lines) + "\n"


def ardupilot_params_file(calibration: Calibration, *, instance: int = 1) -> str:
    """An ArduPilot parameter file (``NAME VALUE`` per line, as MAVProxy and Mission Planner load) of
    :func:`ardupilot_parameters` (``instance`` 1..3 of the IMU)."""
    return ardupilot_params_text(calibration, ardupilot_parameters(calibration, instance=instance))


def ardupilot_params_text(calibration: Calibration, params: AutopilotParameters) -> str:
    """The ArduPilot file of parameters already computed (:func:`ardupilot_parameters` of ``calibration``)."""
    lines = _header(calibration, params, "ArduPilot", "#")
    lines.append(
        "# the correction is relative to INS_GYRn_CALTEMP (INS_ACCn_CALTEMP for the accelerometer): the offsets "
        "taken there remove the bias at that temperature"
    )
    for name, value in params.values.items():
        lines.append(f"{name} {int(value)}" if name.endswith("ENABLE") else f"{name} {float(value):.9g}")
    return "\n".join(lines) + "\n"


__all__ = [
    "AutopilotParameters",
    "CubicFit",
    "accel_offsets_and_scales",
    "ardupilot_parameters",
    "ardupilot_params_file",
    "ardupilot_params_text",
    "px4_params_text",
    "cubic_of",
    "installed_calibration",
    "model_device_id",
    "px4_parameters",
    "px4_params_file",
]
