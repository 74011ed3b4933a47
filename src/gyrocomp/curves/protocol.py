"""The extension point of temperature models: what a calibration's temperature curve provides
(:class:`TemperatureCurve`), what a curve family the fit can choose provides (:class:`CurveBasis`), and the
registries the calibration, the compensation, the export, the report and the model choice read
(:data:`CURVES`, :data:`BASES`) instead of asking which class a curve is.

How to add a temperature model (see docs/architecture.md): write its curve (a frozen dataclass with the methods
of :class:`TemperatureCurve`, decorated with :func:`register_curve`) and, when it is linear in its parameters, its
basis (:class:`CurveBasis`, decorated with :func:`register_basis`) in one module of ``gyrocomp.curves``, and name
that module in :mod:`gyrocomp.curves.kinds`. The model choice then scores it beside the polynomials, model
files store and load it, ``apply`` and the C export compute it, and the report describes it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np

from ..effects import find_turns
from ..errors import InputError

#: how far outside its calibration range a temperature model is still used without a warning: the larger of
#: this many degC and this fraction of the range
RANGE_TOLERANCE_DEGC = 0.5
RANGE_TOLERANCE_FRACTION = 0.01


@dataclass(frozen=True)
class CCode:
    """A curve in generated C (:mod:`gyrocomp.export.c_code`): functions at file scope, statements run once by
    ``gyrocomp_init``, and the statements that set ``double shape`` from ``double tm`` (the model temperature
    [degC]) and ``double acc[3]`` (accelerations [g]) in ``gyrocomp_step``."""

    statements: tuple[str, ...]
    functions: tuple[str, ...] = ()
    init: tuple[str, ...] = ()


@runtime_checkable
class TemperatureCurve(Protocol):
    """An axis's fitted bias shape, without its turn-on constant, in the axis's unit (deg/s, or g for an
    accelerometer axis), frozen and serializable.

    Attributes: ``kind`` (the ``type`` of its entry in a model file), ``t_min_degc`` and ``t_max_degc`` (the
    calibrated range [degC]), ``order`` (its size: an int for a polynomial, words otherwise), ``inputs`` (what it
    reads: ``temperature``, and the accelerations for a joint network), ``needs_accel``."""

    kind: ClassVar[str]
    t_min_degc: float
    t_max_degc: float

    @property
    def order(self) -> int | str: ...

    @property
    def label(self) -> str:
        """Short name in model names and candidate labels: ``poly:3``, ``table:8``, ``mlp:1-3-1``."""

    @property
    def inputs(self) -> tuple[str, ...]: ...

    @property
    def needs_accel(self) -> bool: ...

    @property
    def beyond_range(self) -> str:
        """What the curve does past its range, in words for a warning (``held at its edge``)."""

    def shape(self, temperature_degc: np.ndarray, accel_g: np.ndarray | None = None) -> np.ndarray:
        """The bias shape [the axis's unit] at ``temperature_degc`` [degC] (and ``accel_g`` [g] when it reads
        them)."""

    def outside_range(self, temperature_degc: np.ndarray) -> bool:
        """Whether a temperature lies past the calibrated range by more than its tolerance."""

    def describe(self) -> str:
        """The curve in words for tables: ``polynomial order 3``."""

    def to_dict(self) -> dict[str, Any]:
        """Its entry in a model file, ``type`` = ``kind``."""

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "TemperatureCurve":
        """The curve of a model file's entry, checked."""

    def clamped(self) -> "TemperatureCurve":
        """The curve as a firmware computes it: held at the edges of its range."""

    def plus_slope(self, slope_per_degc: float) -> "TemperatureCurve | None":
        """The curve plus ``slope_per_degc`` (T - T_0) [the axis's unit per degC] with the same zero, or None when
        it cannot take one (a network)."""

    def c_code(self, name: str) -> CCode:
        """The curve in C; ``name`` is unique in the file, for the functions it needs."""


#: every temperature curve a model file may hold, by its ``kind``
CURVES: dict[str, type] = {}


def _register(registry: dict[str, type], key: str, cls: type, what: str) -> type:
    """Put ``cls`` in ``registry`` under ``key``; a second class under a key taken is refused."""
    if key in registry and registry[key] is not cls:
        raise ValueError(f"{what} {key!r} is already registered")
    registry[key] = cls
    return cls


def register_curve(cls: type) -> type:
    """Class decorator: make a curve readable from model files (``kind`` unique)."""
    return _register(CURVES, cls.kind, cls, "a temperature curve of kind")


def curve_from_dict(d: dict[str, Any]) -> TemperatureCurve:
    """The curve of a model file's ``temperature`` entry (its ``type`` one of :data:`CURVES`)."""
    kind = d.get("type") if isinstance(d, dict) else None
    if kind not in CURVES:
        raise InputError(f"unknown temperature model type {kind!r}; known: {', '.join(sorted(CURVES))}")
    return CURVES[kind].from_dict(d)


class CurveBasis(Protocol):
    """A family of curves linear in their parameters, which the model choice scores and the fit solves by least
    squares: ``name`` (as in candidate labels, ``poly:3``), the ``sizes`` the default tries, and, over the
    calibration data's range [lo, hi] degC (:meth:`over`), the columns of a size at model temperatures and the
    curve of the fitted coefficients.

    The columns have no constant (each run's turn-on constant takes it). ``columns(t, size, lo, hi)`` evaluates
    them as the curve is applied when its range is [lo, hi]: held past it, or, for a family that can
    (``over(..., extended=True)``), continued along its tangent as the model choice scores it."""

    name: ClassVar[str]
    #: what a curve of the family is, a phrase with ``N`` for its size (``--temperature``'s help lists it)
    description: ClassVar[str]
    #: the sizes the default model choice tries (the polynomial's orders come from the fit's own order range)
    sizes: ClassVar[tuple[int, ...]]

    @classmethod
    def over(cls, lo_degc: float, hi_degc: float, extended: bool = True) -> "CurveBasis": ...

    def columns(
        self, temperature_degc: np.ndarray, size: int, lo_degc: float | None = None, hi_degc: float | None = None
    ) -> np.ndarray:
        """(n, size) columns at ``temperature_degc`` [degC], applied as a curve of range [lo, hi] would be
        (default: this basis's range)."""

    def curve(self, coefficients: np.ndarray, lo_degc: float, hi_degc: float) -> TemperatureCurve:
        """The curve of ``coefficients`` (one per column of their size) fitted on [lo, hi] degC, applied past
        that range as :meth:`columns` evaluates it."""


#: the curve families the fit can choose, by name
BASES: dict[str, type] = {}


def register_basis(cls: type) -> type:
    """Class decorator: make a curve family a candidate of the model choice (``name`` unique)."""
    return _register(BASES, cls.name, cls, "a curve basis named")


class MemoryCurve(Protocol):
    """What the bias remembers of the temperature's path (turning-point hysteresis, heating and cooling branches),
    added to the temperature curve's shape, frozen and serializable.

    Attributes: ``kind`` (the ``type`` of its entry in a model file), ``title`` (what it is, in words for
    messages), ``threshold_degc`` (a reversal is
    confirmed this far past the extreme [degC]), ``band_degc`` (where it acts [degC], or None), ``order``."""

    kind: ClassVar[str]
    threshold_degc: float

    def offset(self, temperature_degc: np.ndarray, turns) -> np.ndarray:
        """The offset [the axis's unit] at ``temperature_degc`` [degC] given the confirmed ``turns``
        (:func:`gyrocomp.effects.find_turns`)."""

    def describe(self) -> str:
        """The memory in words for tables."""

    def to_dict(self) -> dict[str, Any]:
        """Its entry in a model file, ``type`` = ``kind``."""

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "MemoryCurve":
        """The memory curve of a model file's entry, checked."""

    def c_code(self, slot: int) -> CCode:
        """The statements that add its offset to ``shape`` in ``gyrocomp_step`` from ``tm`` and the turn state
        ``s->turn[slot]`` (updated by them)."""


def memory_offset(curve, temperature_degc: np.ndarray, state=None):
    """A memory curve's offset [the axis's unit] along ``temperature_degc`` [degC] from ``state`` (None: the
    recording's start), and the state after the last sample: the curve's own ``streamed_offset`` where it keeps a
    state of its own (a bank of plays), else its offset given the turns found from the turn state
    (:func:`gyrocomp.effects.find_turns`)."""
    own = getattr(curve, "streamed_offset", None)
    if own is not None:
        return own(temperature_degc, state)
    turns = find_turns(temperature_degc, curve.threshold_degc, state=state)
    return curve.offset(temperature_degc, turns), turns.state


#: every memory curve a model file may hold, by its ``kind``
MEMORY_CURVES: dict[str, type] = {}


def register_memory_curve(cls: type) -> type:
    """Class decorator: make a memory curve readable from model files and exportable (``kind`` unique)."""
    return _register(MEMORY_CURVES, cls.kind, cls, "a memory curve of kind")


def memory_curve_from_dict(d: dict[str, Any]) -> MemoryCurve:
    """The memory curve a model file's ``hysteresis`` entry describes (its ``type`` one of :data:`MEMORY_CURVES`)."""
    kind = MEMORY_CURVES.get(d.get("type")) if isinstance(d, dict) else None
    if kind is None:
        raise InputError(
            f"hysteresis: unknown model type {d.get('type') if isinstance(d, dict) else d!r}; "
            f"use one of {', '.join(MEMORY_CURVES)}"
        )
    return kind.from_dict(d)


__all__ = [
    "BASES",
    "CCode",
    "CURVES",
    "CurveBasis",
    "MEMORY_CURVES",
    "MemoryCurve",
    "TemperatureCurve",
    "curve_from_dict",
    "memory_curve_from_dict",
    "memory_offset",
    "register_basis",
    "register_curve",
    "register_memory_curve",
]
