"""The thesis's hysteresis (section 2.6): after the temperature turns, the bias follows another path,
an offset polynomial in |T - T_turn| on each branch.

This module holds the fitted curve and the turning-point threshold; the curve is fitted jointly with
the temperature polynomial, thermal lag and g-sensitivity by :class:`gyrocomp.fitting.thermal.ThermalHysteresisModel`,
and the turning points themselves are found by :func:`gyrocomp.effects.find_turns`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ..effects import branch_position, find_turns, hysteresis_offset
from ..errors import InputError
from ..c_literals import c_array, c_number
from ..recording import Recording
from ..spilled_series import parts, streamed_median
from .polynomial import power_columns
from .protocol import MEMORY_CURVES, CCode, memory_curve_from_dict, register_memory_curve


def turn_threshold_degc(temperature_degc: np.ndarray) -> float:
    """Turning-point threshold for a measured temperature series [degC].

    Ten times the sample noise (robust, from the median absolute second difference, which a ramp
    does not inflate: the running extreme of a long dwell wanders several sigma), 1.5 times the
    quantization step when the values sit on a grid, and at least 0.1 degC. The series (which may be a
    memory-mapped file) is read a part at a time (:func:`gyrocomp.spilled_series.parts`), the median taken exactly
    from a series that goes to a temporary file when long (:func:`gyrocomp.spilled_series.streamed_median`).
    """
    t = np.asarray(temperature_degc, dtype=float)
    n = t.size
    second = (np.abs(np.diff(t[a:b], 2)) for a, b in parts(n, overlap=2))
    noise = 1.4826 * streamed_median(second) / math.sqrt(6.0) if n > 2 else 0.0

    def steps():
        for a, b in parts(n, overlap=1):
            step = np.abs(np.diff(t[a:b]))
            yield step[step > 0]

    smallest = min((float(s.min()) for s in steps() if s.size), default=None)
    lsb = 0.0
    if smallest is not None and all(np.allclose(s / smallest, np.round(s / smallest), atol=1e-6) for s in steps()):
        lsb = smallest
    return max(10.0 * noise, 1.5 * lsb, 0.1)


def heats_and_cools(recordings: list[Recording], axis: str) -> bool:
    """Whether the runs together contain both a rising and a falling temperature branch."""
    up = down = False
    for rec in recordings:
        t = rec.temperature_for(axis)
        d = find_turns(t, turn_threshold_degc(t)).direction
        up |= bool(np.any(d == 1))
        down |= bool(np.any(d == -1))
    return up and down


@register_memory_curve
@dataclass(frozen=True)
class HysteresisCurve:
    """Fitted hysteresis of one axis: offset after a reversal of the model temperature.

    offset = sum_j h_j |T - T_turn|^j, h from ``descending`` on cooling branches and
    ``ascending`` on heating branches [the axis's unit per degC^j: deg/s/degC^j, or g/degC^j for an
    accelerometer], zero outside ``band_degc`` if given. With
    ``max_distance_degc`` (cooling, heating) the offset is held at its value at the largest distance d the
    fit saw on each branch (files without it follow the polynomial in d everywhere, as earlier ones did).
    Reversals are confirmed ``threshold_degc`` past the extreme (see :func:`gyrocomp.effects.find_turns`).
    """

    kind: ClassVar[str] = "turning-point"

    descending: tuple[float, ...]
    ascending: tuple[float, ...]
    threshold_degc: float
    band_degc: tuple[float, float] | None = None
    max_distance_degc: tuple[float, float] | None = None

    @property
    def order(self) -> int:
        return len(self.descending)

    #: what the curve models, in words (exports say which they cannot carry)
    title: ClassVar[str] = "turning-point hysteresis"  # in words, for messages

    def describe(self) -> str:
        """In words for tables: ``turning-point hysteresis order 2 in 55..80 degC``."""
        band = "" if self.band_degc is None else f" in {self.band_degc[0]:g}..{self.band_degc[1]:g} degC"
        return f"turning-point hysteresis order {self.order}{band}"

    def offset(self, temperature_degc: np.ndarray, turns) -> np.ndarray:
        reach = self.max_distance_degc or (None, None)
        down = hysteresis_offset(
            temperature_degc,
            turns,
            self.descending,
            direction="descending",
            band_degc=self.band_degc,
            max_distance_degc=reach[0],
        )
        up = hysteresis_offset(
            temperature_degc,
            turns,
            self.ascending,
            direction="ascending",
            band_degc=self.band_degc,
            max_distance_degc=reach[1],
        )
        return down + up

    def to_dict(self) -> dict[str, Any]:
        d = {
            "type": self.kind,
            "descending_dps": list(self.descending),
            "ascending_dps": list(self.ascending),
            "threshold_degc": self.threshold_degc,
            "band_degc": None if self.band_degc is None else list(self.band_degc),
        }
        if self.max_distance_degc is not None:  # written only when set: earlier readers see an earlier file
            d["max_distance_degc"] = list(self.max_distance_degc)
        return d

    def c_code(self, slot: int) -> CCode:
        """The offset on the branch after the last confirmed turn: sum_j h_j d^j, d = |tm - turn| (held at the
        largest distance the fit saw), inside the band."""
        lines = [
            f"turn_update(&s->turn[{slot}], tm, {c_number(self.threshold_degc)});",
            f"if (s->turn[{slot}].has_turn) {{",
        ]
        band = (
            ""
            if self.band_degc is None
            else f" && tm >= {c_number(self.band_degc[0])} && tm <= {c_number(self.band_degc[1])}"
        )
        reach = self.max_distance_degc or (None, None)
        for sign, coefs, d_max in ((-1, self.descending, reach[0]), (1, self.ascending, reach[1])):
            lines.append(f"    if (s->turn[{slot}].direction == {sign}{band}) {{")
            lines.append(f"        const double h[] = {c_array(coefs)};")
            lines.append(f"        double d = fabs(tm - s->turn[{slot}].turn), off = 0.0;")
            if d_max is not None:
                lines.append(f"        if (d > {c_number(d_max)}) d = {c_number(d_max)};")
            lines.append(f"        for (int k = {len(coefs) - 1}; k >= 0; --k) off = (off + h[k]) * d;")
            lines.append("        shape += off;")
            lines.append("    }")
        lines.append("}")
        return CCode(tuple(lines))

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "HysteresisCurve":
        if d.get("type") != "turning-point":
            raise InputError(f"unknown hysteresis model type {d.get('type')!r}")
        band = d.get("band_degc")
        reach = d.get("max_distance_degc")
        return cls(
            tuple(float(v) for v in d["descending_dps"]),
            tuple(float(v) for v in d["ascending_dps"]),
            float(d["threshold_degc"]),
            None if band is None else (float(band[0]), float(band[1])),
            None if reach is None else (float(reach[0]), float(reach[1])),
        )


def distance_from_turn(
    temperature_degc: np.ndarray, turns, band_degc: tuple[float, float] | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Where a memory of the last turn acts (after the first confirmed reversal, inside ``band_degc`` [degC] if
    given) and the distance d = |T - T_turn| there [degC] (0 elsewhere), ``turns`` from
    :func:`gyrocomp.effects.find_turns` on ``temperature_degc``."""
    t = np.asarray(temperature_degc, dtype=float)
    active = ~np.isnan(turns.turn_degc)
    if band_degc is not None:
        active &= (t >= band_degc[0]) & (t <= band_degc[1])
    return active, np.where(active, np.abs(t - np.where(active, turns.turn_degc, 0.0)), 0.0)


def turning_point_columns(
    temperature_degc: np.ndarray,
    turns,
    order: int,
    band_degc: tuple[float, float] | None = None,
    scale_degc: float = 1.0,
) -> np.ndarray:
    """The fit columns of :class:`HysteresisCurve`: its offset is these columns times (descending, ascending).

        x_j = (d / s)^j on cooling branches, then the same on heating branches,   d = |T - T_turn|,   j = 1..order

    after the first confirmed reversal, inside ``band_degc`` if given, zero elsewhere.

    Parameters
    ----------
    temperature_degc : array (n,)
        Model temperature [degC].
    turns : Turns
        From :func:`gyrocomp.effects.find_turns` on the same series.
    order : int
        Terms per branch.
    band_degc : (lo, hi), optional
        Temperature band [degC] outside which the columns are zero.
    scale_degc : float
        Divisor s of the distance [degC] (conditions the normal equations; 1 gives the curve's own coefficients
        [the axis's unit per degC^j]).

    Returns
    -------
    array (n, 2 order)
    """
    active, d = distance_from_turn(temperature_degc, turns, band_degc)
    powers = power_columns(d / scale_degc, 1, order)
    return np.hstack([np.where((active & (turns.direction == sign))[:, None], powers, 0.0) for sign in (-1, 1)])


@register_memory_curve
@dataclass(frozen=True)
class BranchCurve:
    """Fitted branches of one axis: one curve while heating, another while cooling, crossing over after each
    turning point (:func:`gyrocomp.effects.branch_position`).

    offset = s(t) sum_k c_k u^k,  u = (T - t_ref) / t_scale,  k = 0..len(coefficients) - 1

    so the heating curve lies ``+ sum c_k u^k`` and the cooling curve ``- sum c_k u^k`` from the polynomial the
    axis also carries; ``coefficients`` are in the axis's unit [deg/s, or g]. Past the fitted range
    [``t_min_degc``, ``t_max_degc``] the half difference is held at its edge value. Reversals are confirmed
    ``threshold_degc`` past the extreme; ``transition_degc`` is the crossover's width w [degC].
    """

    kind: ClassVar[str] = "branch"

    coefficients: tuple[float, ...]
    t_ref_degc: float
    t_scale_degc: float
    transition_degc: float
    threshold_degc: float
    t_min_degc: float
    t_max_degc: float

    @property
    def order(self) -> int:
        """Number of terms of the half difference between the branches."""
        return len(self.coefficients)

    band_degc = None  # the branches differ over the whole range
    #: what the curve models, in words (exports say which they cannot carry)
    title: ClassVar[str] = "heating/cooling branches"  # in words, for messages

    def describe(self) -> str:
        """In words for tables: ``heating/cooling branches (2 terms, crossover 6 degC)``."""
        return (
            f"heating/cooling branches ({self.order} term{'s' if self.order > 1 else ''}, crossover "
            f"{self.transition_degc:.3g} degC)"
        )

    def half_difference(self, temperature_degc: np.ndarray) -> np.ndarray:
        """(heating curve - cooling curve) / 2 at ``temperature_degc`` [the axis's unit], held past the range."""
        u = (
            np.clip(np.asarray(temperature_degc, dtype=float), self.t_min_degc, self.t_max_degc) - self.t_ref_degc
        ) / self.t_scale_degc
        out = np.zeros_like(u)
        for c in reversed(self.coefficients):
            out = out * u + c
        return out

    def offset(self, temperature_degc: np.ndarray, turns) -> np.ndarray:
        return branch_position(temperature_degc, turns, self.transition_degc) * self.half_difference(temperature_degc)

    def to_dict(self) -> dict[str, Any]:
        return {
            "type": self.kind,
            "coefficients_dps": list(self.coefficients),
            "t_ref_degc": self.t_ref_degc,
            "t_scale_degc": self.t_scale_degc,
            "transition_degc": self.transition_degc,
            "threshold_degc": self.threshold_degc,
            "t_min_degc": self.t_min_degc,
            "t_max_degc": self.t_max_degc,
        }

    def c_code(self, slot: int) -> CCode:
        """The heating and cooling branches: s * sum c_k u^k (:func:`gyrocomp.effects.branch_position` for s)."""
        w = c_number(self.transition_degc)
        return CCode(
            (
                f"turn_update(&s->turn[{slot}], tm, {c_number(self.threshold_degc)});",
                "{",
                f"    const double c[] = {c_array(self.coefficients)};",
                f"    double tc = tm < {c_number(self.t_min_degc)} ? {c_number(self.t_min_degc)} : "
                f"(tm > {c_number(self.t_max_degc)} ? {c_number(self.t_max_degc)} : tm);",
                f"    double u = (tc - {c_number(self.t_ref_degc)}) / {c_number(self.t_scale_degc)}, half = 0.0;",
                f"    for (int k = {self.order - 1}; k >= 0; --k) half = half * u + c[k];",
                f"    const gyrocomp_turn *tp = &s->turn[{slot}];",
                "    double position = (double)tp->direction;",
                f"    if (tp->has_turn) position *= 1.0 - 2.0 * exp(-fabs(tm - tp->turn) / {w});",
                f"    else position *= 1.0 - exp(-fabs(tm - (tp->direction > 0 ? tp->low : tp->high)) / {w});",
                "    shape += position * half;",
                "}",
            )
        )

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "BranchCurve":
        curve = cls(
            tuple(float(v) for v in d["coefficients_dps"]),
            float(d["t_ref_degc"]),
            float(d["t_scale_degc"]),
            float(d["transition_degc"]),
            float(d["threshold_degc"]),
            float(d["t_min_degc"]),
            float(d["t_max_degc"]),
        )
        if not (curve.t_scale_degc > 0 and curve.transition_degc > 0 and curve.threshold_degc >= 0):
            raise InputError(
                "hysteresis: a branch model needs t_scale_degc and transition_degc above 0 and "
                "threshold_degc of 0 or more"
            )
        return curve


__all__ = [
    "BranchCurve",
    "HysteresisCurve",
    "MEMORY_CURVES",
    "branch_columns",
    "distance_from_turn",
    "heats_and_cools",
    "memory_curve_from_dict",
    "parting_band_degc",
    "turn_threshold_degc",
    "turning_point_columns",
]


def branch_columns(
    temperature_degc: np.ndarray,
    turns,
    transition_degc: float,
    order: int,
    t_ref_degc: float,
    t_scale_degc: float,
    lo_degc: float | None = None,
    hi_degc: float | None = None,
) -> np.ndarray:
    """The fit columns of :class:`BranchCurve`: its offset is these columns times its coefficients.

        x_k = s(T) u^k,   u = (clip(T, lo, hi) - t_ref) / t_scale,   k = 0..order - 1

    with s the branch position (:func:`gyrocomp.effects.branch_position`, crossover width ``transition_degc``).

    Parameters
    ----------
    temperature_degc : array (n,)
        Model temperature [degC].
    turns : Turns
        From :func:`gyrocomp.effects.find_turns` on the same series.
    transition_degc : float
        Crossover width w [degC].
    order : int
        Terms of the half difference between the branches.
    t_ref_degc, t_scale_degc : float
        Centre and half-span of u [degC].
    lo_degc, hi_degc : float, optional
        Range [degC] past which u is held (the curve's fitted range); not held when omitted.

    Returns
    -------
    array (n, order)
    """
    t = np.asarray(temperature_degc, dtype=float)
    held = t if lo_degc is None else np.clip(t, lo_degc, hi_degc)
    position = branch_position(t, turns, transition_degc)
    return position[:, None] * power_columns((held - t_ref_degc) / t_scale_degc, 0, order - 1)


def _grow(core: np.ndarray, tail: np.ndarray, start: int, step: int) -> int:
    """The last bin reached from ``start`` going ``step`` (-1 or +1) through bins in ``core`` or ``tail``."""
    k = start
    while 0 <= k + step < core.size and (core[k + step] or tail[k + step]):
        k += step
    return k


def _bin_differences(
    t: np.ndarray, e: np.ndarray, hit: np.ndarray, ref: np.ndarray, edges: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Per temperature bin (``edges`` [degC]), the mean of ``e`` where ``hit`` minus its mean where ``ref``, and
    that difference's standard error (NaN and infinity where either side has fewer than three points)."""
    diff, se = np.full(edges.size - 1, np.nan), np.full(edges.size - 1, np.inf)
    for b in range(edges.size - 1):
        inside = (t >= edges[b]) & (t < edges[b + 1])
        h, r = e[inside & hit], e[inside & ref]
        if h.size >= 3 and r.size >= 3:
            diff[b] = h.mean() - r.mean()
            se[b] = math.sqrt(h.var() / h.size + r.var() / r.size)
    return diff, se


def parting_band_degc(
    temperature_degc: np.ndarray,
    residual_dps: np.ndarray,
    after_turn: np.ndarray,
    direction: np.ndarray,
    tail: bool = False,
) -> tuple[float, float] | None:
    """The temperature band where the branches after a reversal part from the opposite branches [degC], or None
    when no band stands out or it spans most of the range.

    Per temperature bin (span / 40, at least 1 degC), the mean residual on branches after a confirmed reversal
    minus the mean on the opposite-direction branches; bins where that difference exceeds three standard errors
    and 30 % of its largest value, contiguous around the largest, are the band's core; the bins beyond it on the side away from
    the turns (colder for branches after a cooling turn), where the difference keeps its sign and exceeds one standard
    error, its tail (with ``tail``).

    Parameters
    ----------
    temperature_degc : (N,) array
        Temperature of each sample or block [degC].
    residual_dps : (N,) array
        Residual of the temperature model without hysteresis [deg/s].
    after_turn : (N,) bool array
        Whether the sample lies on a branch after a confirmed reversal.
    direction : (N,) int array
        Direction of travel (-1 cooling, +1 heating, 0 unknown), as :func:`gyrocomp.effects.find_turns` gives.
    tail : bool
        Extend the core by its tail (above). Only for a residual in which a thermal lag was modelled: an
        unmodelled lag parts the branches by the same sign everywhere, and the tail would then cover the range.
    """
    t, e, after, d = temperature_degc, residual_dps, after_turn, direction
    if t.size == 0 or not t.max() > t.min():
        return None
    width = max(1.0, (t.max() - t.min()) / 40.0)
    edges = np.arange(t.min(), t.max() + width, width)
    best = None
    for sign in (-1, 1):
        diff, se = _bin_differences(t, e, after & (d == sign), d == -sign, edges)
        if np.all(np.isnan(diff)):
            continue
        peak = int(np.nanargmax(np.abs(diff)))
        if best is None or abs(diff[peak]) > best[0]:
            best = (abs(diff[peak]), diff, se, peak, sign)
    if best is None:
        return None
    top, diff, se, peak, branch = best
    strong = (np.abs(np.nan_to_num(diff)) > 3 * se) & (np.abs(np.nan_to_num(diff)) > 0.3 * top)
    if not strong[peak]:
        return None
    # the core, then its tail away from the turn: a bump that fades with the distance from the turning point is
    # cut where it is lost in the noise, not at 30 % of its peak, which would leave a step of that size
    fading = (np.sign(np.nan_to_num(diff)) == np.sign(diff[peak])) & (np.abs(np.nan_to_num(diff)) > se) & tail
    a, b = _grow(strong, fading & (branch < 0), peak, -1), _grow(strong, fading & (branch > 0), peak, 1)
    covered = np.count_nonzero(~np.isnan(diff))
    if b - a + 1 >= 0.8 * covered:
        return None
    return float(edges[a]), float(edges[b + 1])
