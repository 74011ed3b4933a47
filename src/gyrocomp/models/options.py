"""Typed options of a fit: what temperature model, thermal memory, g-sensitivity and held-out folds
:func:`gyrocomp.models.fit.fit` and its other forms use.

>>> from gyrocomp.models.options import Curve, FitOptions, Network, Polynomial
>>> FitOptions(temperature=Polynomial(order=3), hysteresis="none")
>>> FitOptions(temperature=Curve("table", 16))
>>> FitOptions(temperature=Network(hidden=(5,)), acceleration="matrix")

Each field is checked when the object is made; an error names the field and the value.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, get_args

from ..errors import InputError
from ..curves.kinds import BASES
from ..curves.network import DEFAULT_HIDDEN
from ..curves.polynomial import POLY_FAMILY, MAX_ORDER
from ..fitting.thermal import MAX_HYSTERESIS_ORDER

#: the thermal memory on top of the temperature curve
Memory = Literal[
    "auto",
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
]
#: what the model is fitted for: gyrocomp itself, or the best model a firmware carries (a cubic at most, clamped)
Target = Literal["model", "px4", "ardupilot"]
#: the highest polynomial order a firmware target carries
FIRMWARE_MAX_ORDER = 3
#: the g-sensitivity fit (``auto``: the 3x3 matrix when the runs turn between positions)
Acceleration = Literal["auto", "none", "matrix", "matrix2"]
#: what the model choice holds out
FoldChoice = Literal["auto", "runs", "legs", "blocks"]
#: the most hidden neurons of a layer, and layers, a network may have
MAX_HIDDEN, MAX_LAYERS = 50, 3


@dataclass(frozen=True)
class Polynomial:
    """A polynomial in temperature: ``order`` 0..5, or ``"auto"`` (chosen by held-out drift)."""

    order: int | Literal["auto"] = "auto"

    def __post_init__(self):
        if self.order != "auto" and not (
            isinstance(self.order, int) and not isinstance(self.order, bool) and 0 <= self.order <= MAX_ORDER
        ):
            raise InputError(f"Polynomial.order: a whole number from 0 to {MAX_ORDER}, or 'auto'; got {self.order!r}")


@dataclass(frozen=True)
class Network:
    """The thesis's network of the temperature: ``hidden`` tanh neurons per layer (default one layer of 3), its
    restarts' initializations drawn from ``seed`` (the same seed gives the same model)."""

    hidden: tuple[int, ...] = DEFAULT_HIDDEN
    seed: int = 0

    def __post_init__(self):
        hidden = tuple(self.hidden) if isinstance(self.hidden, (tuple, list)) else None
        if (
            not hidden
            or len(hidden) > MAX_LAYERS
            or not all(isinstance(h, int) and not isinstance(h, bool) and 1 <= h <= MAX_HIDDEN for h in hidden)
        ):
            raise InputError(
                f"Network.hidden: 1 to {MAX_LAYERS} layers of 1..{MAX_HIDDEN} neurons, e.g. (3,); got {self.hidden!r}"
            )
        object.__setattr__(self, "hidden", hidden)
        if not isinstance(self.seed, int) or isinstance(self.seed, bool):
            raise InputError(f"Network.seed: a whole number, got {self.seed!r}")


#: the most parameters a curve of another family than the polynomial may have (a table's intervals)
MAX_CURVE_SIZE = 64


def curve_size_range(family: str) -> tuple[int, int]:
    """The sizes a curve family may be asked at, (lowest, highest): a polynomial's orders 0..5, any other family's
    1..``MAX_CURVE_SIZE``."""
    return (0, MAX_ORDER) if family == POLY_FAMILY else (1, MAX_CURVE_SIZE)


@dataclass(frozen=True)
class Curve:
    """A registered curve family by name (:data:`gyrocomp.curves.protocol.BASES`: ``poly``, ``table``, ...) at
    ``size`` (a polynomial's order, a table's intervals) or ``"auto"`` (its size chosen by held-out drift among
    the family's own). The family is fitted as asked, without lag or hysteresis unless it is the polynomial;
    ``Curve("poly", 3)`` is ``Polynomial(3)``.

    Parameters
    ----------
    family : str
        A name of :data:`gyrocomp.curves.protocol.BASES` (``gyrocomp fit --help`` lists them).
    size : int or "auto"
        The polynomial's order (0..5), a table's intervals (1..64), ...; ``auto``: chosen by held-out drift among
        the family's own sizes.
    """

    family: str
    size: int | Literal["auto"] = "auto"

    def __post_init__(self):
        if self.family not in BASES:
            raise InputError(f"Curve.family: {self.family!r}; the registered curves are {', '.join(BASES)}")
        low, top = curve_size_range(self.family)
        if self.size != "auto" and not (
            isinstance(self.size, int) and not isinstance(self.size, bool) and low <= self.size <= top
        ):
            raise InputError(
                f"Curve.size: {self.family} takes a whole number from {low} to {top}, or 'auto'; got {self.size!r}"
            )


@dataclass(frozen=True)
class CurveCandidates:
    """What the model choice scores for a temperature option: the polynomial's ``orders``, the ``others``
    ((family, size) pairs of other families), and whether a curve must beat the run constant on held-out data to
    be kept (``do_no_harm``: when nothing was asked for)."""

    orders: tuple[int, ...]
    others: tuple[tuple[str, int], ...]
    do_no_harm: bool


def curve_candidates(spec: "Polynomial | Curve | Network", target: "Target" = "model") -> CurveCandidates:
    """The one place that knows what the automatic choice tries.

    ``Polynomial()`` (the default) and a network's polynomial stage: every polynomial order, and each other
    registered family at its basis's ``sizes`` (a firmware target: the orders it carries, nothing else);
    ``Polynomial(n)``: that order; ``Curve(family)``: that family's sizes (the polynomial: its orders);
    ``Curve(family, n)``: that curve.

    Parameters
    ----------
    spec : Polynomial, Curve or Network
        The temperature option (a network's polynomial stage is the automatic choice's).
    target : {"model", "px4", "ardupilot"}
        What the model is fitted for (a firmware carries a cubic at most).

    Returns
    -------
    CurveCandidates
        The polynomial's orders, the other families' (name, size) pairs, and whether a curve must beat the run
        constant on held-out data to be kept.
    """
    top = MAX_ORDER if target == "model" else FIRMWARE_MAX_ORDER
    every_order = tuple(range(top + 1))
    if isinstance(spec, Curve) and spec.family != POLY_FAMILY:
        sizes = BASES[spec.family].sizes if spec.size == "auto" else (spec.size,)
        return CurveCandidates((), tuple((spec.family, size) for size in sizes), False)
    if isinstance(spec, Curve):
        return CurveCandidates(every_order, (), True)
    if isinstance(spec, Polynomial) and spec.order != "auto":
        return CurveCandidates((spec.order,), (), False)
    others = tuple((name, size) for name, basis in BASES.items() if name != POLY_FAMILY for size in basis.sizes)
    return CurveCandidates(every_order, others if target == "model" else (), True)


def family_help() -> str:
    """The registered curve families as ``--temperature`` lists them: each name, its sizes, what it is."""
    out = []
    for name, basis in BASES.items():
        low, top = curve_size_range(name)
        out.append(f"{name} or {name}:N (N = {low}..{top}): {basis.description}")
    return "; ".join(out)


#: what an error about a plain temperature form (an order, "auto", "mlp") adds
PLAIN_FORMS = " (an order N is Polynomial(N), 'auto' is Polynomial(), 'mlp' is Network())"


def _choice(name: str, value, choices) -> None:
    if value not in choices:
        raise InputError(f"{name}: {value!r}; use one of {', '.join(map(str, choices))}")


@dataclass(frozen=True)
class FitOptions:
    """How the gyro (and the accelerometer's temperature model) is fitted.

    Parameters
    ----------
    temperature : Polynomial, Curve, Network or None
        The temperature model: ``Polynomial()`` the automatic choice (:func:`curve_candidates`), a
        ``Polynomial(n)``, any registered family by name (``Curve("table", 16)``), a network; None fits no curve
        (each run's constant, and G when the runs turn).
    bin_width_degc : float, optional
        Temperature bin width of the fit [degC].
    hysteresis : Memory
        Thermal lag and/or turning-point hysteresis, heating and cooling branches, or a temperature-rate term
        (``rate``, ``rate+lag``: a bias in the smoothed dT/dt, :mod:`gyrocomp.curves.rate`, fitted where asked
        for), or a table in the distance from the last turn (``turning-table``, ``turning-table+lag``: a memory of
        any shape after a maximum and after a minimum, :mod:`gyrocomp.curves.turning_table`), or a bank of play
        (backlash) operators (``play-bank``, ``play-bank+lag``: a loop of any shape whose width grows with the
        excursion, :mod:`gyrocomp.curves.play_bank`), both fitted where asked for
        (``auto``: chosen by held-out drift when the runs heat and cool).
    hysteresis_order : int or "auto"
        Order of the turning-point polynomial, 1..3.
    hysteresis_band_degc : (lo, hi), optional
        Limit the hysteresis to this band [degC].
    acceleration : Acceleration
        The g-sensitivity fitted jointly on the static segments.
    static_min_duration_s : float
        Shortest still stretch used as a static segment [s].
    run_folds : tuple of int, optional
        The validation fold of each recording (pieces of one run left out together).
    folds : FoldChoice
        What the model choice holds out.
    target : Target
        ``model``: gyrocomp's best model. ``px4``/``ardupilot``: the best model that firmware carries: a polynomial
        of order 3 at most (chosen by the same held-out validation), held at its range's edges as the firmware clamps
        there, no lag, hysteresis or g-sensitivity; ``apply`` then computes what the exported file will.
    """

    temperature: Polynomial | Curve | Network | None = Polynomial()
    bin_width_degc: float | None = None
    hysteresis: Memory = "auto"
    hysteresis_order: int | Literal["auto"] = "auto"
    hysteresis_band_degc: tuple[float, float] | None = None
    acceleration: Acceleration = "auto"
    static_min_duration_s: float = 10.0
    run_folds: tuple[int, ...] | None = None
    folds: FoldChoice = "auto"
    target: Target = "model"

    def __post_init__(self):
        if (
            isinstance(self.temperature, Curve)
            and self.temperature.family == POLY_FAMILY
            and self.temperature.size != "auto"
        ):
            object.__setattr__(self, "temperature", Polynomial(self.temperature.size))
        if self.temperature is not None and not isinstance(self.temperature, (Polynomial, Curve, Network)):
            raise InputError(
                f"FitOptions.temperature: Polynomial(order=...), Curve(family, size), Network(hidden=...) "
                f"or None; got "
                f"{self.temperature!r}" + (PLAIN_FORMS if isinstance(self.temperature, (int, str, tuple)) else "")
            )
        _choice("FitOptions.hysteresis", self.hysteresis, get_args(Memory))
        _choice("FitOptions.hysteresis_order", self.hysteresis_order, ("auto", *range(1, MAX_HYSTERESIS_ORDER + 1)))
        _choice("FitOptions.acceleration", self.acceleration, get_args(Acceleration))
        _choice("FitOptions.folds", self.folds, get_args(FoldChoice))
        _choice("FitOptions.target", self.target, get_args(Target))
        if self.target != "model":
            self._check_firmware_target()
        if isinstance(self.temperature, Curve) and self.temperature.family != POLY_FAMILY:
            self._check_other_family()
        if isinstance(self.temperature, Network) and "rate" in self.hysteresis:
            raise InputError(
                "FitOptions.hysteresis: a network is trained without a temperature-rate term; use a polynomial "
                "with hysteresis='rate' or 'rate+lag'"
            )
        for memory, what in (("turning-table", "a turning-point table"), ("play-bank", "a bank of plays")):
            if isinstance(self.temperature, Network) and memory in self.hysteresis:
                raise InputError(
                    f"FitOptions.hysteresis: a network is trained without {what}; use a polynomial with "
                    f"hysteresis='{memory}' or '{memory}+lag'"
                )
        if self.bin_width_degc is not None and not (
            isinstance(self.bin_width_degc, (int, float)) and self.bin_width_degc > 0
        ):
            raise InputError(f"FitOptions.bin_width_degc: a positive number of degC, got {self.bin_width_degc!r}")
        if not (isinstance(self.static_min_duration_s, (int, float)) and self.static_min_duration_s > 0):
            raise InputError(
                f"FitOptions.static_min_duration_s: a positive number of seconds, got {self.static_min_duration_s!r}"
            )
        band = self.hysteresis_band_degc
        if band is not None:
            if not (
                isinstance(band, (tuple, list))
                and len(band) == 2
                and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in band)
                and band[0] < band[1]
            ):
                raise InputError(f"FitOptions.hysteresis_band_degc: (lo, hi) in degC with lo < hi, got {band!r}")
            object.__setattr__(self, "hysteresis_band_degc", (float(band[0]), float(band[1])))

    def _check_firmware_target(self) -> None:
        """A firmware target carries a cubic at most and nothing else: other asks are refused naming the field."""
        t = self.target
        poly_only = isinstance(self.temperature, Curve) and self.temperature.family == POLY_FAMILY
        if not (isinstance(self.temperature, Polynomial) or poly_only) or (
            not poly_only and self.temperature.order != "auto" and self.temperature.order > FIRMWARE_MAX_ORDER
        ):
            raise InputError(
                f"FitOptions.target: {t} carries a polynomial of order {FIRMWARE_MAX_ORDER} at most; "
                f"use temperature=Polynomial() or Polynomial(0..{FIRMWARE_MAX_ORDER}), got "
                f"{self.temperature!r}"
            )
        if self.hysteresis not in ("auto", "none") or self.hysteresis_band_degc is not None:
            raise InputError(f"FitOptions.target: {t} has no lag or hysteresis term; leave hysteresis='auto' or 'none'")
        if self.acceleration not in ("auto", "none"):
            raise InputError(f"FitOptions.target: {t} has no g-sensitivity term; leave acceleration='auto' or 'none'")
        object.__setattr__(self, "hysteresis", "none")
        object.__setattr__(self, "acceleration", "none")

    def _check_other_family(self) -> None:
        """A family other than the polynomial is fitted without thermal memory: asking for one is refused."""
        if self.hysteresis not in ("auto", "none") or self.hysteresis_band_degc is not None:
            raise InputError(
                f"FitOptions.hysteresis: {self.temperature.family} is fitted without lag or hysteresis; "
                "leave hysteresis='auto' or 'none', or use a polynomial"
            )
        object.__setattr__(self, "hysteresis", "none")


__all__ = [
    "Acceleration",
    "Curve",
    "CurveCandidates",
    "FIRMWARE_MAX_ORDER",
    "FitOptions",
    "FoldChoice",
    "MAX_CURVE_SIZE",
    "curve_size_range",
    "Memory",
    "Network",
    "Polynomial",
    "Target",
    "curve_candidates",
    "family_help",
]
