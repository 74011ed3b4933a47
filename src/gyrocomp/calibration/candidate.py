"""The candidate models of one axis the model choice scores and the report names (:class:`Candidate`), and the
names of the thermal memories a model may carry (:data:`MEMORIES`, :func:`memory_name`, :func:`memory_label`).

The fit report (:mod:`gyrocomp.calibration.fit_report`) records them; the model choice
(:mod:`gyrocomp.fitting.selection`) builds and scores them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from ..curves.polynomial import POLY_FAMILY

#: the thermal memories a gyro axis's model may carry, simplest first (the order the model choice takes as
#: simplest when two score alike: gyrocomp.fitting.thermal.CANDIDATES)
MEMORIES = (
    "none",
    "turning-point",
    "lag",
    "turning-point+lag",
    "turning-table",
    "turning-table+lag",
    "branch",
    "branch+lag",
    "play-bank",
    "play-bank+lag",
    "rate",
    "rate+lag",
)


def memory_name(
    lag: bool, hysteresis_order: int, branch: int = 0, rate: bool = False, table: int = 0, plays: int = 0
) -> str:
    """The thermal memory a model carries: ``none``, ``lag``, ``turning-point``, ``turning-point+lag``,
    ``turning-table`` (a table in the distance from the turn: ``table`` knots), ``turning-table+lag``, ``branch``
    (heating and cooling curves), ``branch+lag``, ``play-bank`` (``plays`` play operators), ``play-bank+lag``,
    ``rate`` (a temperature-rate term) or ``rate+lag``."""
    if plays:
        return "play-bank+lag" if lag else "play-bank"
    if table:
        return "turning-table+lag" if lag else "turning-table"
    if rate:
        return "rate+lag" if lag else "rate"
    if branch:
        return "branch+lag" if lag else "branch"
    if lag and hysteresis_order:
        return "turning-point+lag"
    return "lag" if lag else ("turning-point" if hysteresis_order else "none")


def memory_label(memory: str, hysteresis_order: int) -> str:
    """A thermal memory in the words the model file stores: ``turning-point (order 2)``, ``turning-table (8 knots)``,
    ``play-bank (8 plays)``, ``lag``, ``none`` (``hysteresis_order``: a turning-point table's knots, a bank's
    plays)."""
    if not hysteresis_order:
        return memory
    if memory.startswith("turning-table"):
        return f"{memory} ({hysteresis_order} knots)"
    if memory.startswith("play-bank"):
        return f"{memory} ({hysteresis_order} plays)"
    return f"{memory} (order {hysteresis_order})"


#: how a candidate's fit weights the samples: as they come in time, or each temperature bin alike
Weighting = Literal["time", "temperature-balanced"]


@dataclass(frozen=True)
class Candidate:
    """One model of an axis's bias: the size of its temperature curve (``order``: a polynomial's order, a
    table's intervals), thermal lag, turning-point order, fit weighting, whether the turning-point terms act only
    in the band found in the data, the number of terms of the difference between a heating and a cooling curve
    (``branch``; 0 for none), the curve's family (``curve``, a name of
    :data:`gyrocomp.curves.protocol.BASES`: ``poly``, ``table``), and a temperature-rate term (``rate``,
    :mod:`gyrocomp.curves.rate`). The model choice scores these (:mod:`gyrocomp.fitting.selection`) and the report
    names them."""

    order: int
    lag: bool = False
    hysteresis_order: int = 0
    weighting: Weighting = "time"
    band: bool = False
    branch: int = 0
    curve: str = POLY_FAMILY
    rate: bool = False
    turning_table: int = 0
    plays: int = 0

    @property
    def memory(self) -> str:
        """``none``, ``lag``, ``turning-point``, ``turning-point+lag``, ``turning-table``, ``turning-table+lag``,
        ``branch``, ``branch+lag``, ``play-bank``, ``play-bank+lag``, ``rate`` or ``rate+lag``."""
        return memory_name(self.lag, self.hysteresis_order, self.branch, self.rate, self.turning_table, self.plays)

    @property
    def complexity(self) -> int:
        """Number of shape terms: the order, the lag's time constant, two per hysteresis order, one for a band, the
        branch difference's terms and its crossover width, two for a rate term (its coefficient and smoothing), two per
        knot of a turning-point table, one per play of a bank."""
        return (
            self.order
            + int(self.lag)
            + 2 * self.hysteresis_order
            + int(self.band)
            + (self.branch + 1 if self.branch else 0)
            + 2 * int(self.rate)
            + 2 * self.turning_table
            + self.plays
        )

    @property
    def has_temperature_model(self) -> bool:
        return (
            self.order > 0
            or self.lag
            or self.hysteresis_order > 0
            or self.branch > 0
            or self.rate
            or self.turning_table > 0
            or self.plays > 0
        )

    @property
    def label(self) -> str:
        """Short name, e.g. ``poly:3 + lag + turning-point:2 (time)``, ``table:8 (time)``; ``constant`` for
        order 0."""
        parts = ["constant" if self.order == 0 else f"{self.curve}:{self.order}"]
        if self.lag:
            parts.append("lag")
        if self.hysteresis_order:
            parts.append(f"turning-point:{self.hysteresis_order}" + (" in band" if self.band else ""))
        if self.turning_table:
            parts.append(f"turning-table:{self.turning_table}")
        if self.branch:
            parts.append(f"branch:{self.branch}")
        if self.plays:
            parts.append(f"play-bank:{self.plays}")
        if self.rate:
            parts.append("rate")
        return " + ".join(parts) + f" ({self.weighting})"

    def to_dict(self) -> dict:
        d = {
            "order": self.order,
            "lag": self.lag,
            "hysteresis_order": self.hysteresis_order,
            "weighting": self.weighting,
            "band": self.band,
            "label": self.label,
        }
        if self.branch:  # written only when set: files without it read as before
            d["branch"] = self.branch
        if self.curve != POLY_FAMILY:
            d["curve"] = self.curve
        if self.rate:  # written only when set
            d["rate"] = True
        if self.turning_table:  # written only when set
            d["turning_table"] = self.turning_table
        if self.plays:  # written only when set
            d["plays"] = self.plays
        return d

    @classmethod
    def from_dict(cls, d: dict) -> "Candidate":
        """A stored candidate (its ``label`` is derived from the fields)."""
        return cls(
            int(d["order"]),
            bool(d.get("lag", False)),
            int(d.get("hysteresis_order", 0)),
            d.get("weighting", "time"),
            bool(d.get("band", False)),
            int(d.get("branch", 0)),
            str(d.get("curve", POLY_FAMILY)),
            bool(d.get("rate", False)),
            int(d.get("turning_table", 0)),
            int(d.get("plays", 0)),
        )


__all__ = ["MEMORIES", "Candidate", "Weighting", "memory_label", "memory_name"]
