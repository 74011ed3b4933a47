"""A lookup table: the bias shape as values on an evenly spaced temperature grid, linear in between and held at
the ends, the form many vendors flash into their parts' firmware (a table of offsets against temperature).

    bias(T) = v_k + (v_{k+1} - v_k) (T_c - T_k) / (T_{k+1} - T_k),   T_k <= T_c <= T_{k+1},
    T_c = clip(T, T_0, T_N),   T_k = T_0 + k (T_N - T_0) / N,   v_0 = 0

(the turn-on constant of each run takes the level, so the first value is 0). Piecewise linear in T: a shape
with a kink or a plateau that no low-order polynomial follows; linear in its values, so the model choice scores
tables of :data:`LookupTableBasis.sizes` intervals beside the polynomials by held-out drift
(:class:`LookupTableBasis`: hat functions as least-squares columns). Past its grid it is held at the end value,
as a firmware table is.

The module shows what a new temperature model takes (docs/architecture.md): the curve and its basis here,
registered with :func:`gyrocomp.curves.protocol.register_curve` and
:func:`~gyrocomp.curves.protocol.register_basis`, and its name in :mod:`gyrocomp.curves.kinds`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ..c_literals import c_array, c_number
from ..errors import InputError
from .protocol import CCode, RANGE_TOLERANCE_DEGC, RANGE_TOLERANCE_FRACTION, register_basis, register_curve


@register_curve
@dataclass(frozen=True)
class LookupTableCurve:
    """Fitted bias shape of one axis as a table: ``values`` [the axis's unit] at the ``len(values)`` temperatures
    evenly spaced from ``t_min_degc`` to ``t_max_degc`` [degC], linear in between, held past the ends."""

    kind: ClassVar[str] = "table"
    inputs: ClassVar[tuple[str, ...]] = ("temperature",)
    needs_accel: ClassVar[bool] = False
    beyond_range: ClassVar[str] = "held at its edge"

    values: tuple[float, ...]
    t_min_degc: float
    t_max_degc: float

    def __post_init__(self) -> None:
        if len(self.values) < 2 or not self.t_max_degc > self.t_min_degc:
            raise InputError(
                f"lookup table: at least 2 values on a range with t_max_degc > t_min_degc, got "
                f"{len(self.values)} on {self.t_min_degc}..{self.t_max_degc}"
            )

    @property
    def order(self) -> str:
        return f"table:{len(self.values) - 1}"

    @property
    def label(self) -> str:
        return self.order

    @property
    def grid_degc(self) -> np.ndarray:
        """The table's temperatures [degC]."""
        return np.linspace(self.t_min_degc, self.t_max_degc, len(self.values))

    def shape(self, temperature_degc: np.ndarray, accel_g: np.ndarray | None = None) -> np.ndarray:
        """Bias shape [the axis's unit] at ``temperature_degc`` [degC], linear between the grid points, held past
        the ends. ``accel_g`` is not read."""
        t = np.asarray(temperature_degc, dtype=float)
        return np.interp(t, self.grid_degc, np.asarray(self.values, dtype=float))

    def outside_range(self, temperature_degc: np.ndarray) -> bool:
        t = np.asarray(temperature_degc)
        tol = max(RANGE_TOLERANCE_DEGC, RANGE_TOLERANCE_FRACTION * (self.t_max_degc - self.t_min_degc))
        return bool(np.any(t < self.t_min_degc - tol) or np.any(t > self.t_max_degc + tol))

    def describe(self) -> str:
        step = (self.t_max_degc - self.t_min_degc) / (len(self.values) - 1)
        return f"lookup table, {len(self.values)} points {step:.3g} degC apart"

    def clamped(self) -> "LookupTableCurve":
        return self  # held past its ends already

    def plus_slope(self, slope_per_degc: float) -> "LookupTableCurve":
        added = slope_per_degc * (self.grid_degc - self.t_min_degc)
        return dataclasses.replace(self, values=tuple(float(v) for v in np.asarray(self.values) + added))

    def c_code(self, name: str) -> CCode:
        """The segment of the clipped temperature, then linear interpolation in it."""
        n = len(self.values) - 1
        step = (self.t_max_degc - self.t_min_degc) / n
        return CCode(
            (
                f"{{ static const double v[{n + 1}] = {c_array(self.values)};",
                f"  double x = (clip(tm, {c_number(self.t_min_degc)}, {c_number(self.t_max_degc)}) - "
                f"{c_number(self.t_min_degc)}) / {c_number(step)};",
                f"  int k = (int)x; if (k > {n - 1}) k = {n - 1}; if (k < 0) k = 0;",
                "  shape = v[k] + (v[k + 1] - v[k]) * (x - k);",
                "}",
            )
        )

    def to_dict(self) -> dict[str, Any]:
        return {
            "type": self.kind,
            "values_dps": list(self.values),
            "t_min_degc": self.t_min_degc,
            "t_max_degc": self.t_max_degc,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "LookupTableCurve":
        values = d.get("values_dps")
        if not isinstance(values, list) or not all(isinstance(v, (int, float)) and np.isfinite(v) for v in values):
            raise InputError("lookup table: values_dps must be a list of finite numbers")
        return cls(tuple(float(v) for v in values), float(d["t_min_degc"]), float(d["t_max_degc"]))


@register_basis
@dataclass(frozen=True)
class LookupTableBasis:
    """Tables of ``size`` intervals on the data's range [lo, hi]: the hat functions of grid points 1..size
    (point 0 is the level the run constants take) at the temperature clipped to the curve's range (held past it,
    as applied). Candidates ``table:8`` and ``table:16`` of the model choice, without lag or hysteresis, kept
    only where they beat the best polynomial on the held-out folds by more than the standard error of the
    paired difference (:mod:`gyrocomp.fitting.scores`)."""

    name: ClassVar[str] = "table"
    description: ClassVar[str] = (
        "a lookup table of N intervals over the calibrated range, linear between its points, "
        "held past its ends (what sensor vendors flash)"
    )
    sizes: ClassVar[tuple[int, ...]] = (8, 16)

    lo_degc: float
    hi_degc: float

    @classmethod
    def over(cls, lo_degc: float, hi_degc: float, extended: bool = True) -> "LookupTableBasis":
        return cls(lo_degc, hi_degc if hi_degc > lo_degc else lo_degc + 1.0)

    def columns(
        self, temperature_degc: np.ndarray, size: int, lo_degc: float | None = None, hi_degc: float | None = None
    ) -> np.ndarray:
        t = np.asarray(temperature_degc, dtype=float)
        if lo_degc is not None:
            t = np.clip(t, lo_degc, hi_degc)
        x = (t - self.lo_degc) / (self.hi_degc - self.lo_degc) * size
        k = np.arange(1, size + 1)
        return np.clip(1.0 - np.abs(x[:, None] - k[None, :]), 0.0, None)

    def curve(self, coefficients: np.ndarray, lo_degc: float, hi_degc: float) -> LookupTableCurve:
        """The table of the fitted values on the basis's grid (the hats are on it, whatever range [lo, hi] the fit
        saw: over all the data that is the grid itself)."""
        return LookupTableCurve((0.0, *map(float, coefficients)), self.lo_degc, self.hi_degc)


__all__ = ["LookupTableBasis", "LookupTableCurve"]
