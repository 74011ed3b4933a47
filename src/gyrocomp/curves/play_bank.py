"""A bank of play (backlash) operators on the temperature: a memory of the temperature's path that needs no model
of the turns (a discrete Prandtl-Ishlinskii, or Preisach, model).

    offset = sum_k w_k (y_k - T),   y_k = play_{r_k}(T):   y_k[n] = min(max(y_k[n-1], T[n] - r_k), T[n] + r_k)

with T the model temperature (reported, or through the thermal lag), r_k the plays' half-widths [degC] and w_k
their weights [the axis's unit per degC]. Each play's output follows the temperature only once it has moved more
than r_k from where the play stopped, so y_k - T lies in [-r_k, r_k]: a loop of width 2 r_k between heating and
cooling, with a straight crossover after each turn. The sum over a geometric grid of widths, its weights fitted
linearly, is a loop of any shape whose width grows with the excursion, and it treats minor loops (a turn inside
a leg, a small cycle) as the physics of friction-held package stress does; each play starts centred on the
recording's first temperature (what a power-on knows of the history). This module holds the operator (computed
as a prefix scan of clamps, so a series is processed at numpy speed and in chunks with the same result), the
fitted curve and its fit columns.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ..c_literals import c_array
from ..errors import InputError
from .protocol import CCode, register_memory_curve

#: plays per bank the default's model choice tries
PLAY_BANK_SIZES = (8, 16)
#: the most plays a bank may hold (the C export's state holds this many per axis)
MAX_PLAYS = 16
#: the widest play's half-width as a share of the calibration span (a play wider than half the span never moves:
#: its column is the temperature itself), and the narrowest's
WIDEST_SHARE, NARROWEST_SHARE = 1.0 / 3.0, 1.0 / 64.0


def play_half_widths_degc(span_degc: float, threshold_degc: float, size: int) -> tuple[float, ...]:
    """``size`` half-widths [degC] log-spaced from the larger of ``span_degc`` / 64 and twice the turning-point
    threshold (a play narrower than the temperature's noise follows the noise) to ``span_degc`` / 3."""
    hi = max(span_degc, 1.0) * WIDEST_SHARE
    lo = min(max(span_degc * NARROWEST_SHARE, 2.0 * threshold_degc), hi / 2.0)
    return tuple(float(r) for r in np.geomspace(lo, hi, size))


def play_operator(
    temperature_degc: np.ndarray, half_width_degc: float, start_degc: float | None = None
) -> tuple[np.ndarray, float]:
    """The play operator's output [degC] along ``temperature_degc``, and its last value (the state a next chunk
    starts from).

        y[n] = min(max(y[n-1], T[n] - r), T[n] + r),   y[-1] = ``start_degc`` (default T[0])

    Each step is a clamp to [T[n] - r, T[n] + r], and clamps compose into clamps (first [a1, b1], then [a2, b2]:
    [clip(a1, a2, b2), clip(b1, a2, b2)]), so the output is the start clamped by the composition of the steps up to
    n, a prefix scan in log2(n) vectorized passes.

    Parameters
    ----------
    temperature_degc : array (n,)
        Model temperature [degC].
    half_width_degc : float
        r [degC], not negative.
    start_degc : float, optional
        The play's output before the first sample [degC]; None: centred on the first sample.
    """
    x = np.asarray(temperature_degc, dtype=float)
    if x.size == 0:
        return x.copy(), float("nan") if start_degc is None else float(start_degc)
    lo, hi = x - half_width_degc, x + half_width_degc
    shift = 1
    while shift < x.size:
        prev_lo, prev_hi = lo[:-shift], hi[:-shift]
        cur_lo, cur_hi = lo[shift:], hi[shift:]
        new_lo = np.minimum(np.maximum(prev_lo, cur_lo), cur_hi)
        new_hi = np.minimum(np.maximum(prev_hi, cur_lo), cur_hi)
        lo = np.concatenate([lo[:shift], new_lo])
        hi = np.concatenate([hi[:shift], new_hi])
        shift *= 2
    y0 = x[0] if start_degc is None else float(start_degc)
    out = np.minimum(np.maximum(y0, lo), hi)
    return out, float(out[-1])


def play_bank_columns(
    temperature_degc: np.ndarray, half_widths_degc: tuple[float, ...], starts_degc=None
) -> tuple[np.ndarray, tuple[float, ...]]:
    """The fit columns of :class:`PlayBankCurve`: its offset is these columns times its weights; and each play's
    last output (the state).

        x_k = play_{r_k}(T) - T   [degC],   k = 1..m

    Parameters
    ----------
    temperature_degc : array (n,)
        Model temperature [degC].
    half_widths_degc : tuple of float
        r_1..r_m [degC].
    starts_degc : sequence of float, optional
        Each play's output before the first sample [degC] (a state); default centred on the first sample.

    Returns
    -------
    (array (n, m), tuple of float)
    """
    t = np.asarray(temperature_degc, dtype=float)
    cols, last = [], []
    for k, r in enumerate(half_widths_degc):
        y, end = play_operator(t, r, None if starts_degc is None else starts_degc[k])
        cols.append(y - t)
        last.append(end)
    return (np.column_stack(cols) if cols else np.zeros((t.size, 0))), tuple(last)


@register_memory_curve
@dataclass(frozen=True)
class PlayBankCurve:
    """A fitted bank of plays of one axis.

    Attributes
    ----------
    half_widths_degc : tuple of float
        r_k [degC], positive, increasing; at most :data:`MAX_PLAYS`.
    weights : tuple of float
        w_k [the axis's unit per degC: deg/s/degC, or g/degC].
    """

    kind: ClassVar[str] = "play-bank"
    #: what the curve models, in words (exports say which they cannot carry)
    title: ClassVar[str] = "bank of plays"

    half_widths_degc: tuple[float, ...]
    weights: tuple[float, ...]

    band_degc = None  # the plays act over the whole range
    threshold_degc = 0.0  # no turn is looked for

    def __post_init__(self) -> None:
        r = np.asarray(self.half_widths_degc, dtype=float)
        if not (0 < r.size <= MAX_PLAYS and len(self.weights) == r.size):
            raise InputError(f"hysteresis: a bank of plays needs 1 to {MAX_PLAYS} half-widths and one weight each")
        if not (np.all(np.isfinite(r)) and np.all(np.isfinite(self.weights))):
            raise InputError("hysteresis: a bank of plays' half-widths and weights must be finite numbers")
        if not (r[0] > 0 and np.all(np.diff(r) > 0)):
            raise InputError("hysteresis: a bank of plays' half_widths_degc must be positive and increasing")

    @property
    def order(self) -> int:
        """Plays in the bank."""
        return len(self.half_widths_degc)

    def describe(self) -> str:
        """In words for tables: ``bank of 8 plays of half-width 1.4..30 degC``."""
        r = self.half_widths_degc
        return f"bank of {self.order} plays of half-width {r[0]:.3g}..{r[-1]:.3g} degC"

    def streamed_offset(self, temperature_degc: np.ndarray, state=None) -> tuple[np.ndarray, tuple[float, ...]]:
        """The offset [the axis's unit] along ``temperature_degc`` [degC], the plays starting from ``state`` (each
        play's last output; None: centred on the first sample), and the state after the last sample."""
        t = np.asarray(temperature_degc, dtype=float)
        if t.size == 0:
            return np.zeros(0), state
        cols, last = play_bank_columns(t, self.half_widths_degc, state)
        return cols @ np.asarray(self.weights, dtype=float), last

    def offset(self, temperature_degc: np.ndarray, turns=None) -> np.ndarray:
        """The offset [the axis's unit] along a whole recording's ``temperature_degc`` [degC] (``turns`` unused)."""
        return self.streamed_offset(temperature_degc)[0]

    def to_dict(self) -> dict[str, Any]:
        return {"type": self.kind, "half_widths_degc": list(self.half_widths_degc), "weights_dps": list(self.weights)}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "PlayBankCurve":
        if not isinstance(d, dict) or d.get("type") != cls.kind:
            raise InputError(f"hysteresis: expected an entry of type {cls.kind!r}")
        try:
            fields = (tuple(float(v) for v in d["half_widths_degc"]), tuple(float(v) for v in d["weights_dps"]))
        except (KeyError, TypeError, ValueError):
            raise InputError("hysteresis: a bank of plays needs half_widths_degc and weights_dps") from None
        return cls(*fields)

    def c_code(self, slot: int) -> CCode:
        """Each play clamped to [tm - r, tm + r] from its last output ``s->play[slot][k]`` (centred on the first
        sample), the offset the weighted sum of the plays' outputs minus tm."""
        m = self.order
        return CCode(
            (
                "{",
                f"    const double r[] = {c_array(self.half_widths_degc)}, w[] = {c_array(self.weights)};",
                f"    if (!s->play_started[{slot}]) {{",
                f"        for (int k = 0; k < {m}; ++k) s->play[{slot}][k] = tm;",
                f"        s->play_started[{slot}] = 1;",
                "    }",
                f"    for (int k = 0; k < {m}; ++k) {{",
                f"        double y = s->play[{slot}][k];",
                "        if (y < tm - r[k]) y = tm - r[k];",
                "        if (y > tm + r[k]) y = tm + r[k];",
                f"        s->play[{slot}][k] = y;",
                "        shape += w[k] * (y - tm);",
                "    }",
                "}",
            )
        )


__all__ = [
    "MAX_PLAYS",
    "PLAY_BANK_SIZES",
    "PlayBankCurve",
    "play_bank_columns",
    "play_half_widths_degc",
    "play_operator",
]
