"""Sensor triads beyond bias: scale factor and misalignment as a 3 x 3 matrix (the frozen results).

A triad of sensing axes measures a vector quantity v (specific force [g] or angular rate [deg/s]) as

    raw = K v + b,                         K = I + E (scale-factor errors on the diagonal of E,
                                                      misalignment / cross-coupling off it)

and is corrected by v = C (raw - b) with C = K^-1. For the accelerometer, a multi-position test
without known orientations (the norm of gravity is the only reference; Tedaldi et al., ICRA 2014;
imu_tk) fixes K only up to a rotation of the reference frame; gyrocomp then reports the upper
triangular K of the RQ decomposition: the corrected z axis is the sensor's z axis and the corrected
y axis lies in the plane of the sensor's y and z axes. With known orientations (six-position /
Ferraris test, poses along +-x, +-y, +-z of a reference frame) K is full and relative to that frame.

For the gyro, K(T) may depend on temperature: each element is a polynomial in (T - T_ref)
(coefficients in ``sensitivity_per_degc``), as rate-table calibrations at several temperatures give.
Without a rate table, rotations between still poses (``method="rotation"``) give the gyro's K relative
to the accelerometer's corrected frame: gravity, measured before and after each turn, is the reference.
These classes are data only; the fitters live in :mod:`gyrocomp.fitting.triad_fit`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal, get_args

import numpy as np

from ..errors import InputError
from ..units import unit_suffix

#: how a triad was calibrated
TriadMethod = Literal["norm", "six-position", "rate-table", "rotation"]
TRIAD_METHODS: tuple[str, ...] = get_args(TriadMethod)


def _matrix(value: Any, where: str) -> np.ndarray:
    m = np.asarray(value, dtype=float)
    if m.shape != (3, 3) or not np.all(np.isfinite(m)):
        raise InputError(f"{where}: expected 3 rows of 3 finite numbers")
    return m


def _vector(value: Any, where: str) -> np.ndarray:
    v = np.asarray(value, dtype=float)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise InputError(f"{where}: expected 3 finite numbers")
    return v


def rows_of(m: np.ndarray) -> tuple[tuple[float, ...], ...]:
    return tuple(tuple(float(x) for x in row) for row in np.asarray(m))


@dataclass(frozen=True)
class TriadCalibration:
    """Bias, scale factor and misalignment of a sensor triad, optionally changing with temperature.

    Attributes
    ----------
    sensitivity : 3 x 3
        K at ``reference_degc``: raw = K v + bias [dimensionless].
    bias : 3 floats
        Constant bias [g for the accelerometer, deg/s for the gyro].
    method : {"norm", "six-position", "rate-table", "rotation"}
        How it was found (see the module doc for the frame each method fixes).
    sensitivity_stderr, bias_stderr : 3 x 3, 3 floats
        Standard errors of the above (same units).
    reference_degc : float or None
        Temperature the constant terms refer to [degC]; None when K does not depend on temperature.
    sensitivity_per_degc : tuple of 3 x 3
        K(T) = sensitivity + sum_p sensitivity_per_degc[p-1] (T - reference_degc)^p [1/degC^p];
        empty when K is constant.
    sensitivity_per_degc_stderr : tuple of 3 x 3
        Standard errors of those coefficients.
    unit : str
        ``"g"`` (accelerometer) or ``"deg/s"`` (gyro): the unit of bias and of the corrected vector.
    """

    sensitivity: tuple[tuple[float, ...], ...]
    bias: tuple[float, float, float]
    method: TriadMethod
    sensitivity_stderr: tuple[tuple[float, ...], ...]
    bias_stderr: tuple[float, float, float]
    unit: str
    reference_degc: float | None = None
    sensitivity_per_degc: tuple[tuple[tuple[float, ...], ...], ...] = ()
    sensitivity_per_degc_stderr: tuple[tuple[tuple[float, ...], ...], ...] = ()

    def __post_init__(self) -> None:
        if self.method not in TRIAD_METHODS:
            raise InputError(f"method: {self.method!r}; use one of {', '.join(TRIAD_METHODS)}")
        if self.unit not in ("g", "deg/s"):
            raise InputError(f"unit: {self.unit!r}; use 'g' or 'deg/s'")
        k = _matrix(self.sensitivity, "sensitivity")
        if abs(np.linalg.det(k)) < 1e-6:
            raise InputError("sensitivity: the matrix is singular; it cannot be inverted to correct the triad")
        if self.sensitivity_per_degc and self.reference_degc is None:
            raise InputError("sensitivity_per_degc: temperature coefficients need reference_degc")
        if len(self.sensitivity_per_degc_stderr) not in (0, len(self.sensitivity_per_degc)):
            raise InputError("sensitivity_per_degc_stderr: one 3 x 3 per temperature coefficient")

    # -- the physics ------------------------------------------------------------------------------
    @property
    def temperature_order(self) -> int:
        """Order of K(T) in temperature (0: constant)."""
        return len(self.sensitivity_per_degc)

    def sensitivity_at(self, temperature_degc: np.ndarray | float | None = None) -> np.ndarray:
        """K at each temperature: (3, 3) when constant or T is a scalar/None, else (n, 3, 3) [dimensionless]."""
        k0 = np.asarray(self.sensitivity, dtype=float)
        if not self.sensitivity_per_degc or temperature_degc is None:
            return k0
        d = np.asarray(temperature_degc, dtype=float) - float(self.reference_degc)
        out = np.broadcast_to(k0, d.shape + (3, 3)).copy()
        for p, coef in enumerate(self.sensitivity_per_degc, start=1):
            out = out + np.multiply.outer(d**p, np.asarray(coef, dtype=float))
        return out

    def correct(self, raw: np.ndarray, temperature_degc: np.ndarray | None = None) -> np.ndarray:
        """v = K(T)^-1 (raw - bias) for raw (n, 3) [unit]; ``temperature_degc`` (n,) [degC] when K(T) varies."""
        raw = np.asarray(raw, dtype=float)
        if raw.ndim != 2 or raw.shape[1] != 3:
            raise InputError(f"raw: shape {raw.shape}; expected (n, 3)")
        centred = raw - np.asarray(self.bias, dtype=float)
        if self.sensitivity_per_degc and temperature_degc is None:
            raise InputError("temperature_degc: this triad's scale factor depends on temperature; give the temperature")
        k = self.sensitivity_at(temperature_degc)
        if k.ndim == 2:
            return np.linalg.solve(k, centred.T).T
        return np.linalg.solve(k, centred[..., None])[..., 0]

    @property
    def scale_factor_error(self) -> np.ndarray:
        """Diagonal of K - I at the reference temperature (3,) [dimensionless; x 1e6 for ppm]."""
        return np.diag(np.asarray(self.sensitivity, dtype=float)) - 1.0

    @property
    def misalignment(self) -> np.ndarray:
        """Off-diagonal of K, the cross-axis coupling (3, 3) with zeros on the diagonal [rad, small angles]."""
        k = np.asarray(self.sensitivity, dtype=float)
        return k - np.diag(np.diag(k))

    @classmethod
    def identity(cls, unit: Literal["g", "deg/s"] = "deg/s") -> "TriadCalibration":
        """K = I and no bias (zero standard errors): a triad that passes the data through as given, e.g. to measure
        raw data with the tools that take a calibration (``rotation_errors``)."""
        zeros = ((0.0, 0.0, 0.0),) * 3
        return cls(
            ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
            (0.0, 0.0, 0.0),
            "norm" if unit == "g" else "rotation",
            zeros,
            (0.0, 0.0, 0.0),
            unit,
        )

    # -- serialization ----------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        suffix = unit_suffix(self.unit)
        return {
            "method": self.method,
            "unit": self.unit,
            "sensitivity": [list(r) for r in self.sensitivity],
            "sensitivity_stderr": [list(r) for r in self.sensitivity_stderr],
            f"bias{suffix}": list(self.bias),
            f"bias_stderr{suffix}": list(self.bias_stderr),
            "reference_degc": self.reference_degc,
            "sensitivity_per_degc": [[list(r) for r in m] for m in self.sensitivity_per_degc],
            "sensitivity_per_degc_stderr": [[list(r) for r in m] for m in self.sensitivity_per_degc_stderr],
        }

    @classmethod
    def from_dict(cls, d: Any, where: str = "triad") -> "TriadCalibration":
        if not isinstance(d, dict):
            raise InputError(f"{where}: not an object")
        unit = d.get("unit")
        if unit not in ("g", "deg/s"):
            raise InputError(f"{where}.unit: {unit!r}; use 'g' or 'deg/s'")
        suffix = unit_suffix(unit)
        for key in ("method", "sensitivity", "sensitivity_stderr", f"bias{suffix}", f"bias_stderr{suffix}"):
            if key not in d:
                raise InputError(f"{where}: no {key!r} entry")
        per_degc = d.get("sensitivity_per_degc") or []
        per_degc_se = d.get("sensitivity_per_degc_stderr") or []
        if len(per_degc) > 4:
            raise InputError(f"{where}.sensitivity_per_degc: {len(per_degc)} coefficients; at most 4")
        reference = d.get("reference_degc")
        try:
            return cls(
                sensitivity=rows_of(_matrix(d["sensitivity"], f"{where}.sensitivity")),
                bias=tuple(_vector(d[f"bias{suffix}"], f"{where}.bias{suffix}")),
                method=d["method"],
                sensitivity_stderr=rows_of(_matrix(d["sensitivity_stderr"], f"{where}.sensitivity_stderr")),
                bias_stderr=tuple(_vector(d[f"bias_stderr{suffix}"], f"{where}.bias_stderr{suffix}")),
                unit=unit,
                reference_degc=None if reference is None else float(reference),
                sensitivity_per_degc=tuple(
                    rows_of(_matrix(m, f"{where}.sensitivity_per_degc[{p}]")) for p, m in enumerate(per_degc)
                ),
                sensitivity_per_degc_stderr=tuple(
                    rows_of(_matrix(m, f"{where}.sensitivity_per_degc_stderr[{p}]")) for p, m in enumerate(per_degc_se)
                ),
            )
        except InputError as exc:
            message = str(exc)
            raise InputError(message if message.startswith(where) else f"{where}: {message}") from None


__all__ = ["TRIAD_METHODS", "TriadCalibration", "TriadMethod", "rows_of"]
