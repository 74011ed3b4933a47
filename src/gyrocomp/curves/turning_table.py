"""A memory of the last turn of any shape: after each confirmed reversal of the temperature, the bias follows a
table in the distance travelled from the turn, one table after a maximum and another after a minimum.

    offset = f_down(d) on a cooling branch (after a maximum),   f_up(d) on a heating branch (after a minimum)
    d = |T - T_turn|,   f(d) = interp(d; 0, d_1, ..., d_m; 0, v_1, ..., v_m), held at v_m past d_m

with T the model temperature (reported, or through the thermal lag), T_turn the last confirmed turn
(:func:`gyrocomp.effects.find_turns`) and the knots d_j evenly spaced to the largest distance the fit saw. The
thesis's turning-point polynomial (:class:`gyrocomp.curves.hysteresis.HysteresisCurve`) is the case of a smooth
f that is a polynomial in d; the table carries shapes a polynomial of order 3 does not, such as a bump that rises
after the turn and falls back (relaxation of the die attach, the ADXRS450's bump below its hottest point), at
the cost of two values per knot. This module holds the fitted curve and its fit columns; it uses the turn state
the turning-point and branch memories use, so ``apply``, the streaming compensator and the C export carry it
with the same state.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ..c_literals import c_array, c_number
from ..effects import find_turns
from ..errors import InputError
from .hysteresis import distance_from_turn
from .protocol import CCode, register_memory_curve

#: knots per branch the default's model choice tries (each costs two values: one after a maximum, one after a
#: minimum)
TURNING_TABLE_SIZES = (4, 8, 16)


def turning_table_knots_degc(reach_degc: float, size: int) -> tuple[float, ...]:
    """``size`` knots [degC] evenly spaced from ``reach_degc / size`` to ``reach_degc`` (the largest distance from
    a turn the fit saw; 1 degC where it saw none)."""
    reach = reach_degc if reach_degc > 0 else 1.0
    return tuple(float(reach * (j + 1) / size) for j in range(size))


def largest_turn_distance_degc(temperatures_degc, threshold_degc: float) -> float:
    """The largest |T - T_turn| over every series of ``temperatures_degc`` [degC] after its first confirmed turn
    (turns confirmed ``threshold_degc`` past the extreme), 0 where none turns."""
    out = 0.0
    for t in temperatures_degc:
        t = np.asarray(t, dtype=float)
        turns = find_turns(t, threshold_degc)
        active = ~np.isnan(turns.turn_degc)
        if np.any(active):
            out = max(out, float(np.max(np.abs(t[active] - turns.turn_degc[active]))))
    return out


def _hats(distance_degc: np.ndarray, knots_degc: tuple[float, ...]) -> np.ndarray:
    """(n, m) hat functions of the distance at the knots (0 at d = 0, the last held at 1 past its knot)."""
    d = np.minimum(np.asarray(distance_degc, dtype=float), knots_degc[-1])
    grid = np.r_[0.0, knots_degc]
    out = np.empty((d.size, len(knots_degc)))
    for j in range(len(knots_degc)):
        unit = np.zeros(grid.size)
        unit[j + 1] = 1.0
        out[:, j] = np.interp(d, grid, unit)
    return out


def turning_table_columns(temperature_degc: np.ndarray, turns, knots_degc: tuple[float, ...]) -> np.ndarray:
    """The fit columns of :class:`TurningTableCurve`: its offset is these columns times (descending, ascending).

        x_j = hat_j(d) on cooling branches, then the same on heating branches,   d = |T - T_turn|,   j = 1..m

    with hat_j the piecewise-linear function that is 1 at knot d_j and 0 at the other knots and at 0 (the last
    held at 1 past d_m), after the first confirmed reversal, zero before it.

    Parameters
    ----------
    temperature_degc : array (n,)
        Model temperature [degC].
    turns : Turns
        From :func:`gyrocomp.effects.find_turns` on the same series.
    knots_degc : tuple of float
        The knots d_1 < ... < d_m [degC].

    Returns
    -------
    array (n, 2 m)
    """
    active, d = distance_from_turn(temperature_degc, turns)
    hats = _hats(d, knots_degc)
    return np.hstack([np.where((active & (turns.direction == sign))[:, None], hats, 0.0) for sign in (-1, 1)])


@register_memory_curve
@dataclass(frozen=True)
class TurningTableCurve:
    """Fitted memory of the last turn of one axis, as a table in the distance from it.

    Attributes
    ----------
    knots_degc : tuple of float
        Distances d_1 < ... < d_m from the turn [degC], positive.
    descending, ascending : tuple of float
        The offset at each knot on cooling branches (after a maximum) and on heating branches (after a minimum)
        [the axis's unit: deg/s, or g]; 0 at the turn, linear between knots, held past the last.
    threshold_degc : float
        A reversal is confirmed this far past the extreme [degC].
    """

    kind: ClassVar[str] = "turning-table"
    #: what the curve models, in words (exports say which they cannot carry)
    title: ClassVar[str] = "turning-point table"

    knots_degc: tuple[float, ...]
    descending: tuple[float, ...]
    ascending: tuple[float, ...]
    threshold_degc: float

    band_degc = None  # the table acts over the whole range

    def __post_init__(self) -> None:
        k = np.asarray(self.knots_degc, dtype=float)
        if k.size == 0 or not (len(self.descending) == len(self.ascending) == k.size):
            raise InputError("hysteresis: a turning-point table needs one descending and one ascending value per knot")
        values = np.r_[k, self.descending, self.ascending, self.threshold_degc]
        if not np.all(np.isfinite(values)):
            raise InputError("hysteresis: a turning-point table's knots, values and threshold must be finite numbers")
        if not (k[0] > 0 and np.all(np.diff(k) > 0)):
            raise InputError("hysteresis: a turning-point table's knots_degc must be positive and increasing")
        if self.threshold_degc < 0:
            raise InputError("hysteresis: threshold_degc must not be negative")

    @property
    def order(self) -> int:
        """Knots per branch."""
        return len(self.knots_degc)

    def describe(self) -> str:
        """In words for tables: ``turning-point table of 8 knots to 72 degC``."""
        return f"turning-point table of {self.order} knots to {self.knots_degc[-1]:.3g} degC"

    def offset(self, temperature_degc: np.ndarray, turns) -> np.ndarray:
        """The offset [the axis's unit] at ``temperature_degc`` [degC] given the confirmed ``turns``."""
        columns = turning_table_columns(temperature_degc, turns, self.knots_degc)
        return columns @ np.r_[self.descending, self.ascending]

    def to_dict(self) -> dict[str, Any]:
        return {
            "type": self.kind,
            "knots_degc": list(self.knots_degc),
            "descending_dps": list(self.descending),
            "ascending_dps": list(self.ascending),
            "threshold_degc": self.threshold_degc,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "TurningTableCurve":
        if not isinstance(d, dict) or d.get("type") != cls.kind:
            raise InputError(f"hysteresis: expected an entry of type {cls.kind!r}")
        try:
            fields = (
                tuple(float(v) for v in d["knots_degc"]),
                tuple(float(v) for v in d["descending_dps"]),
                tuple(float(v) for v in d["ascending_dps"]),
                float(d["threshold_degc"]),
            )
        except (KeyError, TypeError, ValueError):
            raise InputError(
                "hysteresis: a turning-point table needs knots_degc, descending_dps, ascending_dps and threshold_degc"
            ) from None
        return cls(*fields)

    def c_code(self, slot: int) -> CCode:
        """The offset on the branch after the last confirmed turn: the table interpolated at d = |tm - turn|,
        0 at the turn, held past the last knot."""
        lines = [
            f"turn_update(&s->turn[{slot}], tm, {c_number(self.threshold_degc)});",
            f"if (s->turn[{slot}].has_turn) {{",
            f"    const double knot[] = {c_array((0.0,) + self.knots_degc)};",
            f"    double d = fabs(tm - s->turn[{slot}].turn);",
            f"    if (d > knot[{self.order}]) d = knot[{self.order}];",
            "    int k = 1;",
            f"    while (k < {self.order} && d > knot[k]) ++k;",
            "    const double f = (d - knot[k - 1]) / (knot[k] - knot[k - 1]);",
        ]
        for sign, values in ((-1, self.descending), (1, self.ascending)):
            lines += [
                f"    if (s->turn[{slot}].direction == {sign}) {{",
                f"        const double v[] = {c_array((0.0,) + tuple(values))};",
                "        shape += v[k - 1] + f * (v[k] - v[k - 1]);",
                "    }",
            ]
        lines.append("}")
        return CCode(tuple(lines))


__all__ = [
    "TURNING_TABLE_SIZES",
    "TurningTableCurve",
    "largest_turn_distance_degc",
    "turning_table_columns",
    "turning_table_knots_degc",
]
