"""The thermal calibration an autopilot already holds, read back from its parameters as a gyrocomp model.

PX4 (``TC_G{i}_*``): offset = X0 + X1 d + X2 d^2 + X3 d^3, d = clip(T, TMIN, TMAX) - TREF [rad/s]; ArduPilot
(``INS_TCAL{n}_*``): P(d) = (c1 + (c2 + c3 d) d) d * 1e-6, d = clip(T, TMIN, TMAX) - 35 degC [rad/s] (see
:mod:`gyrocomp.export.autopilot`, which writes them). Reading them back lets gyrocomp judge the calibration a
vehicle flies with against its own, on the same data.
"""

from __future__ import annotations

import math
import warnings

from .calibration import AxisCalibration, Calibration
from .errors import DataQualityWarning, InputError
from .models.temperature import PolynomialBias

DEG_TO_RAD = math.pi / 180.0
ARDUPILOT_TEMP_REFERENCE_DEGC = 35.0
ARDUPILOT_SCALE = 1.0e6
AXIS_INDEX = {"gyro_x": 0, "gyro_y": 1, "gyro_z": 2}


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

    The cubic becomes a polynomial in T - reference, held at TMIN and TMAX as the autopilots clip; PX4's X0 is the
    model's constant (ArduPilot's curve has none: its bias at the ordinary calibration's temperature belongs to
    the gyro offsets, so the constant is 0 and only drift is judged). PX4's SCL other than 1 is not modelled: a
    warning says so.
    """
    if autopilot == "px4":
        if int(parameters.get("TC_G_ENABLE", 0)) != 1:
            return None
        p = f"TC_G{instance}_"
        reference = parameters.get(f"{p}TREF", 25.0)
        coefficients = [[parameters.get(f"{p}X{k}_{j}", 0.0) for k in range(4)] for j in range(3)]
        scales = [parameters.get(f"{p}SCL_{j}", 1.0) for j in range(3)]
        if any(abs(sc - 1.0) > 1e-6 for sc in scales):
            warnings.warn(f"{p}SCL_*: scale factors {scales} are not modelled; the offsets are", DataQualityWarning,
                          stacklevel=2)
    elif autopilot == "ardupilot":
        p = f"INS_TCAL{instance + 1}_"
        if int(parameters.get(f"{p}ENABLE", 0)) != 1:
            return None
        reference = ARDUPILOT_TEMP_REFERENCE_DEGC
        coefficients = [[0.0, *(parameters.get(f"{p}GYR{k}_{a}", 0.0) / ARDUPILOT_SCALE for k in (1, 2, 3))]
                        for a in "XYZ"]
    else:
        raise InputError(f"autopilot: {autopilot!r}; use px4 or ardupilot")
    t_min, t_max = parameters.get(f"{p}TMIN", -40.0), parameters.get(f"{p}TMAX", 85.0)
    if not t_min < t_max:
        raise InputError(f"{p}TMIN {t_min:g} is not below {p}TMAX {t_max:g}: not a usable thermal calibration")
    axes = {}
    for name, j in AXIS_INDEX.items():
        c = [v / DEG_TO_RAD for v in coefficients[j]]  # rad/s -> deg/s
        curve = PolynomialBias((c[1], c[2], c[3]), reference, 1.0, t_min, t_max)
        axes[name] = AxisCalibration(curve, (c[0],))
    return Calibration(axes=axes, model=f"installed {autopilot} cubic ({p}*)",
                       provenance={"source": f"{autopilot} parameters {p}*"}, fit_report={"temperature": "installed"})


__all__ = ["ARDUPILOT_SCALE", "ARDUPILOT_TEMP_REFERENCE_DEGC", "AXIS_INDEX", "DEG_TO_RAD", "installed_calibration"]
