"""The thermal fit's design: the columns of every effect on one axis's runs, built in one place.

Per run r and block i, the bias is modelled as a run constant plus a sum of effects, each linear in its
coefficients at a given model temperature T_s (the reported temperature, or it through a thermal lag):

    b_ri = c_r + sum_blocks X_block(T_s, history, a)_i . beta_block

The blocks (:class:`Terms` names which a fit uses, in this order):

- ``shape``: a temperature curve of a family of :data:`gyrocomp.curves.protocol.BASES` (the polynomial's
  u^1..u^p, a lookup table's hat functions), one block per (family, size);
- ``turning-point``: the thesis's hysteresis (section 2.6), (d / s)^j on cooling then heating branches
  (:func:`gyrocomp.curves.hysteresis.turning_point_columns`), one block per band (None: the whole range);
- ``turning-table``: a table in the distance from the last turn, hat functions of d on cooling then heating
  branches (:func:`gyrocomp.curves.turning_table.turning_table_columns`), one block per set of knots;
- ``play-bank``: plays of several half-widths, play_r(T) - T (:func:`gyrocomp.curves.play_bank.play_bank_columns`),
  one block per set of half-widths;
- ``branch``: heating and cooling curves crossing over after each turn, s(T) u^k
  (:func:`gyrocomp.curves.hysteresis.branch_columns`), one block per crossover width;
- ``rate``: the smoothed rate of the model temperature [degC/s] (:func:`gyrocomp.curves.rate.rate_columns`), one
  column per smoothing time constant;
- ``acceleration``: the g-sensitivity's accelerometer columns [g] and g x g products [g^2].

Both the model choice (:class:`gyrocomp.fitting.selection.SelectionProblem`, which builds every candidate's
columns at once and picks each candidate's by :meth:`ThermalDesign.layout`) and the final fit
(:class:`gyrocomp.fitting.thermal.ThermalHysteresisModel`, which builds the chosen candidate's) take their
columns from here, and each curve module gives the columns of the curve it evaluates.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..curves.hysteresis import branch_columns, turning_point_columns
from ..curves.protocol import BASES
from ..curves.play_bank import play_bank_columns
from ..curves.rate import rate_columns
from ..curves.turning_table import turning_table_columns
from ..effects import find_turns, g_squared_products


@dataclass(frozen=True)
class Terms:
    """Which blocks of columns a design holds, in order.

    Attributes
    ----------
    shapes : tuple of (str, int)
        (family, size) of each temperature-curve block (family a name of :data:`gyrocomp.curves.protocol.BASES`).
    turning_point_order : int
        Terms per branch of each turning-point block (0: none).
    bands_degc : tuple of (lo, hi) or None
        One turning-point block per entry: limited to that band [degC], or over the whole range (None).
    turning_table_knots_degc : tuple of tuple of float
        One turning-point table block per set of knots [degC] (empty: none).
    play_half_widths_degc : tuple of tuple of float
        One bank-of-plays block per set of half-widths [degC] (empty: none).
    branch_order : int
        Terms of each branch block (0: none).
    branch_widths_degc : tuple of float
        One branch block per crossover width [degC].
    rate_smoothings_s : tuple of float
        One temperature-rate column per smoothing time constant [s] (empty: none).
    acceleration : bool
        Whether the design ends with the g-sensitivity columns.
    """

    shapes: tuple[tuple[str, int], ...] = ()
    turning_point_order: int = 0
    bands_degc: tuple[tuple[float, float] | None, ...] = (None,)
    turning_table_knots_degc: tuple[tuple[float, ...], ...] = ()
    play_half_widths_degc: tuple[tuple[float, ...], ...] = ()
    branch_order: int = 0
    branch_widths_degc: tuple[float, ...] = ()
    rate_smoothings_s: tuple[float, ...] = ()
    acceleration: bool = True


@dataclass(frozen=True)
class ThermalDesign:
    """The columns of one axis's thermal fit.

    Parameters
    ----------
    t_ref_degc, t_scale_degc : float
        Centre and half-span of the calibration temperature [degC]: the curve families' range, the branch terms' u.
    threshold_degc : float
        Turning-point threshold [degC] (:func:`gyrocomp.effects.find_turns`).
    accel_cols : tuple of int
        Accelerometer axes fitted (0, 1, 2 for x, y, z).
    square_cols : tuple of int
        g x g products fitted (indices of :data:`gyrocomp.effects.G_SQUARED_TERMS`).
    extended : bool
        A polynomial continues along its tangent past a curve's range (else is held there).
    distance_scale_degc : float
        Divisor of the turning-point distance [degC]: the half-span for normal equations, 1 for the curve's own
        coefficients.
    period_s : float
        Nominal period of the samples the columns are built on [s] (the rate's smoothing filter).
    """

    t_ref_degc: float
    t_scale_degc: float
    threshold_degc: float
    accel_cols: tuple[int, ...] = ()
    square_cols: tuple[int, ...] = ()
    extended: bool = True
    distance_scale_degc: float = 1.0
    period_s: float = 1.0

    def basis(self, family: str):
        """The curve family ``family`` over the calibration temperature range."""
        return BASES[family].over(
            self.t_ref_degc - self.t_scale_degc, self.t_ref_degc + self.t_scale_degc, self.extended
        )

    def acceleration_columns(self, accel_g: np.ndarray | None, n: int) -> np.ndarray:
        """The g [g] and g x g [g^2] sensitivity columns (n, m), m = 0 without them."""
        cols = [np.zeros((n, 0))]
        if self.accel_cols:
            cols.append(accel_g[:, list(self.accel_cols)])
        if self.square_cols:
            cols.append(g_squared_products(accel_g)[:, list(self.square_cols)])
        return np.hstack(cols)

    def acceleration_size(self) -> int:
        return len(self.accel_cols) + len(self.square_cols)

    def columns(
        self,
        temperature_degc: np.ndarray,
        accel_g: np.ndarray | None,
        terms: Terms,
        lo_degc: float | None = None,
        hi_degc: float | None = None,
        time_s: np.ndarray | None = None,
    ) -> np.ndarray:
        """The columns of ``terms`` (n, :meth:`width`) at model temperature ``temperature_degc`` [degC] and
        acceleration ``accel_g`` [g] (n, 3).

        ``lo_degc``, ``hi_degc``: the range [degC] the curves are applied as fitted on (held, or continued along
        the tangent, past it); unlimited when omitted. ``time_s`` [s]: the samples' times (the rate terms need
        them)."""
        t = np.asarray(temperature_degc, dtype=float)
        cols = [self.basis(family).columns(t, size, lo_degc, hi_degc) for family, size in terms.shapes if size]
        if terms.turning_point_order or terms.turning_table_knots_degc or terms.branch_order:
            turns = find_turns(t, self.threshold_degc)
            if terms.turning_point_order:
                cols += [
                    turning_point_columns(t, turns, terms.turning_point_order, band, self.distance_scale_degc)
                    for band in terms.bands_degc
                ]
            cols += [turning_table_columns(t, turns, knots) for knots in terms.turning_table_knots_degc]
            if terms.branch_order:
                cols += [
                    branch_columns(
                        t, turns, w, terms.branch_order, self.t_ref_degc, self.t_scale_degc, lo_degc, hi_degc
                    )
                    for w in terms.branch_widths_degc
                ]
        cols += [play_bank_columns(t, widths)[0] for widths in terms.play_half_widths_degc]
        if terms.rate_smoothings_s:
            if time_s is None:
                raise ValueError("ThermalDesign.columns: rate terms need the samples' times (time_s)")
            cols.append(rate_columns(time_s, t, terms.rate_smoothings_s, self.period_s))
        if terms.acceleration:
            cols.append(self.acceleration_columns(accel_g, t.size))
        return np.hstack(cols) if cols else np.zeros((t.size, 0))

    def layout(self, terms: Terms) -> dict[tuple, slice]:
        """Where each block of :meth:`columns` lies: ``("shape", family, size)``, ``("turning-point", band)``,
        ``("turning-table", knots)``, ``("branch", width)``, ``("rate", smoothing)`` and ``("acceleration",)`` to their columns."""
        out, start = {}, 0

        def take(key, size):
            nonlocal start
            out[key] = slice(start, start + size)
            start += size

        for family, size in terms.shapes:
            if size:
                take(("shape", family, size), size)
        for band in terms.bands_degc if terms.turning_point_order else ():
            take(("turning-point", band), 2 * terms.turning_point_order)
        for knots in terms.turning_table_knots_degc:
            take(("turning-table", knots), 2 * len(knots))
        for w in terms.branch_widths_degc if terms.branch_order else ():
            take(("branch", w), terms.branch_order)
        for widths in terms.play_half_widths_degc:
            take(("play-bank", widths), len(widths))
        for s in terms.rate_smoothings_s:
            take(("rate", s), 1)
        if terms.acceleration:
            take(("acceleration",), self.acceleration_size())
        return out

    def width(self, terms: Terms) -> int:
        """The number of columns of ``terms``."""
        return max((s.stop for s in self.layout(terms).values()), default=0)


__all__ = ["Terms", "ThermalDesign"]
