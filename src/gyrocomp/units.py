"""Unit conversions at the edge of the library.

Inside gyrocomp, angular rate is in [deg/s], acceleration in [g], temperature in [degC] and time in [s].
Readers and CLI options convert to these with the factors below; writers convert back.
"""

from __future__ import annotations

import math
import re
from typing import Literal, get_args

from .errors import InputError

STANDARD_GRAVITY_M_PER_S2 = 9.80665  # [m/s^2], CGPM 1901

#: the unit of an axis's values: a gyro axis's [deg/s], an accelerometer axis's [g]
AxisUnit = Literal["deg/s", "g"]
AXIS_UNITS: tuple[str, ...] = get_args(AxisUnit)


def check_axis_unit(unit: str) -> None:
    """Refuse a unit no axis is in (``unit`` is one of :data:`AXIS_UNITS`)."""
    if unit not in AXIS_UNITS:
        raise InputError(f"unit: {unit!r}; an axis is in one of {', '.join(AXIS_UNITS)}")


#: how a name that carries an axis's unit ends: ``drift_dps`` [deg/s], ``drift_g`` [g]
UNIT_SUFFIXES = {"deg/s": "_dps", "g": "_g"}


def unit_suffix(unit: str) -> str:
    """The ending of a name that says ``unit`` (one of :data:`AXIS_UNITS`): ``_dps`` or ``_g``."""
    check_axis_unit(unit)
    return UNIT_SUFFIXES[unit]


def require_unit(actual: str, expected: str, name: str, neutral: str) -> None:
    """Refuse to read ``name`` (a name that says its unit, ``expected``) of an axis in ``actual``; ``neutral`` is
    the unit-free name that reads either."""
    if actual != expected:
        raise InputError(f"{name}: the axis's values are in {actual}, not {expected}; read {neutral}")


def in_unit(neutral: str, unit: str, name: str) -> property:
    """The attribute ``neutral`` of an object with a ``unit``, read under ``name``, the name that says ``unit``:
    refused (:func:`require_unit`) for an object in the other unit."""

    def get(self) -> object:
        require_unit(self.unit, unit, name, neutral)
        return getattr(self, neutral)

    return property(get, doc=f"``{neutral}`` of an axis in {unit}.")


#: multiply a value in the named unit by the factor to get [deg/s]
GYRO_UNITS_TO_DPS = {
    "deg/s": 1.0,
    "dps": 1.0,
    "rad/s": 180.0 / math.pi,
    "mrad/s": 0.18 / math.pi,
    "mdps": 1e-3,
    "deg/h": 1.0 / 3600.0,
}
#: multiply a value in the named unit by the factor to get [g]
ACCEL_UNITS_TO_G = {
    "g": 1.0,
    "mg": 1e-3,
    "m/s2": 1.0 / STANDARD_GRAVITY_M_PER_S2,
    "m/s^2": 1.0 / STANDARD_GRAVITY_M_PER_S2,
}
#: multiply a value in the named unit by the factor to get [s]
TIME_UNITS_TO_S = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}

# Conversions of noise parameters between the units people quote them in.
DEG_PER_S_PER_SQRT_HZ_TO_DEG_PER_SQRT_H = 60.0  # sqrt(3600)
DEG_PER_S_TO_DEG_PER_H = 3600.0
DEG_PER_S_PER_SQRT_S_TO_DEG_PER_H_PER_SQRT_H = 3600.0 * 60.0


#: an example of a scaled unit per kind, for messages
_EXAMPLE_SCALED = {"gyro": "1/131 deg/s", "accel": "1/16384 g", "time": "10 ms"}
#: a scaled unit: one file unit is a number (or a fraction) of a named unit, "1/131 deg/s", "0.061 mg", "10 ms"
_SCALED_UNIT = re.compile(
    r"^\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)(?:\s*/\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?))?\s+(\S+)\s*$"
)


def unit_factor(kind: str, unit: str, option: str | None = None) -> float:
    """Factor that converts a value in ``unit`` to gyrocomp's internal unit for ``kind``.

    A unit is a name (``"rad/s"``) or a scaled name: a number or a fraction, a space, a name, meaning that one unit
    of the file is that much of the named unit. Raw counts are read so: an MPU-6050 at +-250 deg/s gives 131 counts
    per deg/s, ``"1/131 deg/s"``; its accelerometer at +-2 g 16384 counts per g, ``"1/16384 g"``; a sample counter
    at 100 Hz is a time in ``"10 ms"``.

    Parameters
    ----------
    kind : {"gyro", "accel", "time"}
    unit : str
        Unit as a user writes it, e.g. ``"rad/s"`` or ``"1/131 deg/s"``.
    option : str, optional
        The parameter the unit came from (``gyro_unit`` ...), named in the error message.
    """
    tables = {"gyro": GYRO_UNITS_TO_DPS, "accel": ACCEL_UNITS_TO_G, "time": TIME_UNITS_TO_S}
    table = tables[kind]
    where = option or f"{kind}_unit"
    name, scale = unit.strip(), 1.0
    scaled = _SCALED_UNIT.match(unit)
    if scaled is not None:
        numerator, denominator, name = scaled.groups()
        bottom = float(denominator or 1.0)
        scale = float(numerator) / bottom if bottom > 0 else math.inf
        if not (math.isfinite(scale) and scale > 0):
            raise InputError(f"{where}: {unit!r} scales its unit by {scale:g}; a scale is a positive number")
    if name not in table:
        raise InputError(
            f"{where}: unknown unit {unit!r}; use one of {', '.join(sorted(table))}, or one scaled, "
            f"such as {_EXAMPLE_SCALED[kind]!r} (raw counts)"
        )
    return scale * table[name]
