"""The polynomial temperature curve of an axis's bias (thesis section 2.5.2), as a calibration holds it:

    b_r(T) = c_r + sum_{k=1}^{p} a_k u^k,    u = (clip(T, T_min, T_max) - T_ref) / T_scale

with one turn-on constant c_r per run (each power-on has its own) and the shape a_1..a_p shared by all runs
(:class:`PolynomialCurve` holds the shape). Fitting it is :mod:`gyrocomp.fitting.polynomial_model`'s.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ..c_literals import c_array, c_number
from ..errors import InputError
from .protocol import CCode, RANGE_TOLERANCE_DEGC, RANGE_TOLERANCE_FRACTION, register_basis, register_curve

MAX_ORDER = 5
#: the polynomial family's name among the curve families (``poly:3``): the one that takes thermal memory
POLY_FAMILY = "poly"
#: data beyond the fitted temperature range by less than max(these) is not reported as outside it
#: what a polynomial does past its fitted range: held at the edge, or continued along its tangent
EXTRAPOLATIONS = ("hold", "linear")


@register_curve
@dataclass(frozen=True)
class PolynomialCurve:
    """Fitted temperature shape of one axis's bias, without its turn-on constant, in the axis's unit (deg/s for a
    gyro axis, g for an accelerometer axis: :attr:`gyrocomp.calibration.AxisCalibration.unit`; the model file
    names the coefficients ``coefficients_dps`` or ``coefficients_g``).

    bias(T) = sum_k coefficients[k-1] * u^k,  u = (clip(T, t_min_degc, t_max_degc) - t_ref_degc) / t_scale_degc

    Past the fitted range the curve is held at its edge (``extrapolation="hold"``, what PX4 and ArduPilot do),
    or continued along its tangent there (``"linear"``): bias(T) = bias(T_e) + bias'(T_e) (T - T_e), T_e the
    nearer edge. A temperature coefficient rarely vanishes just past the calibrated range, while a polynomial
    of higher order extrapolated as such diverges; the tangent is the first-order Taylor extension.
    """

    kind: ClassVar[str] = "polynomial"
    inputs: ClassVar[tuple[str, ...]] = ("temperature",)
    needs_accel: ClassVar[bool] = False

    coefficients: tuple[float, ...]
    t_ref_degc: float
    t_scale_degc: float
    t_min_degc: float
    t_max_degc: float
    extrapolation: str = "hold"

    def __post_init__(self) -> None:
        if self.extrapolation not in EXTRAPOLATIONS:
            raise InputError(f"extrapolation: {self.extrapolation!r}; use one of {', '.join(EXTRAPOLATIONS)}")

    @property
    def order(self) -> int:
        return len(self.coefficients)

    @property
    def beyond_range(self) -> str:
        return "continued along its tangent" if self.extrapolation == "linear" else "held at its edge"

    def describe(self) -> str:
        return f"polynomial order {self.order}"

    @property
    def label(self) -> str:
        return f"poly:{self.order}"

    def clamped(self) -> "PolynomialCurve":
        return dataclasses.replace(self, extrapolation="hold")

    def plus_slope(self, slope_per_degc: float) -> "PolynomialCurve":
        coefficients = list(self.coefficients) or [0.0]
        coefficients[0] += slope_per_degc * self.t_scale_degc
        return dataclasses.replace(self, coefficients=tuple(coefficients))

    def c_code(self, name: str) -> CCode:
        """Horner's rule on u = (clip(tm) - T_ref) / T_scale, continued along the tangent past the range when the
        curve is."""
        c = self.coefficients
        lines = [
            f"{{ const double c[] = {c_array(c)};" if c else "{",
            f"  double u = (clip(tm, {c_number(self.t_min_degc)}, {c_number(self.t_max_degc)}) - "
            f"{c_number(self.t_ref_degc)}) / {c_number(self.t_scale_degc)};",
            "  shape = 0.0;",
        ]
        if c:
            lines.append(f"  for (int k = {len(c) - 1}; k >= 0; --k) shape = (shape + c[k]) * u;")
            if self.extrapolation == "linear":  # continued along the tangent past the range
                lines += [
                    "  double slope = 0.0;",
                    f"  for (int k = {len(c) - 1}; k >= 0; --k) slope = slope * u + (k + 1) * c[k];",
                    f"  shape += slope * ((tm - {c_number(self.t_ref_degc)}) / {c_number(self.t_scale_degc)} - u);",
                ]
        lines.append("}")
        return CCode(tuple(lines))

    @property
    def range_tolerance_degc(self) -> float:
        """How far past its range data may go before it counts as outside [degC]: sensor noise and
        rounding make a new run at the same set points overshoot the fit's extremes slightly."""
        return max(RANGE_TOLERANCE_DEGC, RANGE_TOLERANCE_FRACTION * (self.t_max_degc - self.t_min_degc))

    def outside_range(self, temperature_degc: np.ndarray) -> bool:
        """Whether any temperature lies beyond the fitted range by more than ``range_tolerance_degc``."""
        t = np.asarray(temperature_degc)
        tol = self.range_tolerance_degc
        return bool(np.any(t < self.t_min_degc - tol) or np.any(t > self.t_max_degc + tol))

    def shape(self, temperature_degc: np.ndarray, accel_g: np.ndarray | None = None) -> np.ndarray:
        """Bias shape [the axis's unit] at ``temperature_degc`` [degC]; past the range held or extended
        (``extrapolation``). ``accel_g`` is not read."""
        t = np.asarray(temperature_degc, dtype=float)
        u = (np.clip(t, self.t_min_degc, self.t_max_degc) - self.t_ref_degc) / self.t_scale_degc
        # Horner's rule (as polynomial_columns @ coefficients, without building the columns)
        coefficients = [0.0, *map(float, self.coefficients)]
        value = horner(u, coefficients)
        beyond = self.extrapolation_u(t, u)
        if beyond is not None and self.order:
            value = value + horner(u, [k * c for k, c in enumerate(coefficients)][1:]) * beyond
        return value

    def extrapolation_u(self, temperature_degc: np.ndarray, clipped_u: np.ndarray) -> np.ndarray | None:
        """How far past the range each temperature lies, in u units (None when the curve is held)."""
        if self.extrapolation == "hold":
            return None
        return (np.asarray(temperature_degc, dtype=float) - self.t_ref_degc) / self.t_scale_degc - clipped_u

    def to_dict(self) -> dict[str, Any]:
        d = {
            "type": "polynomial",
            "coefficients_dps": list(self.coefficients),
            "t_ref_degc": self.t_ref_degc,
            "t_scale_degc": self.t_scale_degc,
            "t_min_degc": self.t_min_degc,
            "t_max_degc": self.t_max_degc,
        }
        if self.extrapolation != "hold":  # files without the key hold the edge, as every earlier file did
            d["extrapolation"] = self.extrapolation
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "PolynomialCurve":
        return cls(
            tuple(float(c) for c in d["coefficients_dps"]),
            float(d["t_ref_degc"]),
            float(d["t_scale_degc"]),
            float(d["t_min_degc"]),
            float(d["t_max_degc"]),
            str(d.get("extrapolation", "hold")),
        )


def horner(u: np.ndarray, coefficients: list[float]) -> np.ndarray:
    """sum_k coefficients[k] u^k by Horner's rule, one pass over u per coefficient."""
    value = (
        np.full(np.shape(u), coefficients[-1]) if len(coefficients) == 1 else coefficients[-1] * u + coefficients[-2]
    )
    for c in reversed(coefficients[:-2]):
        value *= u
        value += c
    return value


@register_basis
@dataclass(frozen=True)
class PolynomialBasis:
    """The polynomials u^1..u^p, u = (T - T_ref) / T_scale over the data's range [lo, hi] (T_ref its middle,
    T_scale its half-width): candidates ``poly:0`` .. ``poly:5`` of the model choice. Past a curve's range the
    columns continue along their tangent when ``extended`` (how the model choice scores, and the chosen curve is
    applied), else they are held at the edge."""

    name: ClassVar[str] = POLY_FAMILY
    description: ClassVar[str] = "a polynomial of order N in temperature (poly alone: its order by held-out drift)"
    sizes: ClassVar[tuple[int, ...]] = tuple(range(1, MAX_ORDER + 1))

    t_ref_degc: float
    t_scale_degc: float
    extended: bool = True

    @classmethod
    def over(cls, lo_degc: float, hi_degc: float, extended: bool = True) -> "PolynomialBasis":
        return cls((lo_degc + hi_degc) / 2, (hi_degc - lo_degc) / 2 if hi_degc > lo_degc else 1.0, extended)

    def columns(
        self, temperature_degc: np.ndarray, size: int, lo_degc: float | None = None, hi_degc: float | None = None
    ) -> np.ndarray:
        t = np.asarray(temperature_degc, dtype=float)
        u = (t - self.t_ref_degc) / self.t_scale_degc
        if lo_degc is None:
            return power_columns(u, 1, size)
        clipped = (np.clip(t, lo_degc, hi_degc) - self.t_ref_degc) / self.t_scale_degc
        return polynomial_columns(clipped, size, u - clipped if self.extended else None)

    def curve(self, coefficients: np.ndarray, lo_degc: float, hi_degc: float) -> PolynomialCurve:
        return PolynomialCurve(
            tuple(float(a) for a in coefficients),
            self.t_ref_degc,
            self.t_scale_degc,
            lo_degc,
            hi_degc,
            "linear" if self.extended else "hold",
        )


def power_columns(u: np.ndarray, first: int, last: int) -> np.ndarray:
    """Columns u^first..u^last (n, last - first + 1) by repeated multiplication: ``u[:, None] ** np.arange(first,
    last + 1)`` to a rounding, at a small part of its cost (numpy's power with an array of exponents calls pow for
    every element; the model choice makes these columns for every run at every lag it tries)."""
    u = np.asarray(u, dtype=float)
    out = np.empty((max(0, last - first + 1), u.size))
    for j in range(out.shape[0]):
        if j:
            np.multiply(out[j - 1], u, out=out[j])
        else:
            out[0] = 1.0 if first == 0 else u if first == 1 else u**first
    return out.T


def polynomial_columns(clipped_u: np.ndarray, order: int, beyond_u: np.ndarray | None = None) -> np.ndarray:
    """Columns u^1..u^order at the clipped u, each continued along its tangent by ``beyond_u`` (u - clipped u)
    when given: u_c^k + k u_c^(k-1) (u - u_c). The curve is linear in its coefficients either way."""
    cols = power_columns(clipped_u, 1, order)
    if beyond_u is not None and order:
        cols = cols + np.arange(1, order + 1) * power_columns(clipped_u, 0, order - 1) * beyond_u[:, None]
    return cols
