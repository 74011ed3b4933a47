"""How a calibration was fitted, as typed records: ``Calibration.report`` (a :class:`FitReport`).

The model file keeps the account as the JSON object ``fit_report`` (the shape every schema version has written);
:meth:`FitReport.from_dict` reads it into these dataclasses, so the command line, the HTML report and the fleet
figures read attributes instead of parsing strings. Older files that wrote the chosen thermal memory only as text
(``"turning-point (order 2)"``) are read into the same fields. Sections the fit did not produce are None (or empty);
what has no typed record here (the online learner's, the population prior's, a triad's account) stays in
``FitReport.sections``.

Units are in the names: [deg/s] (``_dps``), [g] (``_g``), [s], [degC], [deg/s/g]. A record of an axis's drifts or
residuals has neutral names and the axis's ``unit`` (deg/s for the gyro, g for the accelerometer); the file names
each value with its unit (``raw_drift_dps`` or ``raw_drift_g``), and files written before that kept the
accelerometer's under ``_dps`` (read as the section's unit).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Any

from .candidate import MEMORIES, Candidate, memory_label
from ..measures.ramp_rate import ramp_rates_separate, separation_sentence
from ..units import AxisUnit, in_unit, unit_suffix

_TYPED = (
    "temperature",
    "axes",
    "order_selection",
    "selection",
    "hysteresis",
    "network",
    "acceleration",
    "stages",
    "accel",
    "pipeline",
)


def _number(value) -> float | None:
    """A score as stored: None where it could not be computed."""
    if value is None:
        return None
    value = float(value)
    return value if math.isfinite(value) else None


def _entry_in_unit(d: dict, name: str, unit: str, default=None):
    """``d``'s entry ``name`` + the ending that says ``unit`` (``mean_drift_g``); files written before the
    accelerometer's entries said their unit kept them under ``_dps`` whatever the unit (in g for the
    accelerometer), so that name is read when the other is absent."""
    return d.get(name + unit_suffix(unit), d.get(name + "_dps", default))


@dataclass(frozen=True)
class CandidateResult:
    """A candidate's held-out drift: mean and standard error over the folds, and each fold's [the axis's unit:
    deg/s, or g for an accelerometer axis], and the lag each fold's fit chose [s]; None where a fold held too
    little data."""

    candidate: Candidate
    mean_drift: float | None
    standard_error: float | None
    fold_drift: tuple[float | None, ...]
    fold_lag_s: tuple[float, ...]

    @classmethod
    def from_dict(cls, d: dict, unit: AxisUnit = "deg/s") -> "CandidateResult":
        return cls(
            Candidate.from_dict(d),
            _number(_entry_in_unit(d, "mean_drift", unit)),
            _number(_entry_in_unit(d, "standard_error", unit)),
            tuple(_number(v) for v in _entry_in_unit(d, "fold_drift", unit, ())),
            tuple(float(v) for v in d.get("fold_lag_s", ())),
        )


@dataclass(frozen=True)
class BranchTest:
    """Whether the heating and cooling curves differ by more than the drift explains, where no held-out leg can
    tell (:func:`gyrocomp.fitting.branch_evidence.branch_test`).

    ``order``: branch terms kept (0 none, 1 a constant difference, 2 also a slope); ``statistic``: the Wald
    statistic of the branch terms tested last (the kept ones, or both when none is kept) and ``threshold`` the
    value it had to exceed; ``width_degc``: the crossover width the terms were computed with [degC];
    ``walk_per_sqrt_s``: the square root of the drift coefficient c the residual of the model without branch terms
    showed [the axis's unit / s^(exponent / 2)], a random walk's K where ``drift_exponent`` is 1;
    ``drift_exponent``: the drift's exponent alpha (its variogram ``2 a + c dt^alpha``) [dimensionless; 1 in files
    written before it was stored]."""

    order: int
    statistic: float
    threshold: float
    width_degc: float
    walk_per_sqrt_s: float
    drift_exponent: float = 1.0

    def to_dict(self) -> dict:
        return {
            "order": self.order,
            "statistic": self.statistic,
            "threshold": self.threshold,
            "width_degc": self.width_degc,
            "walk_per_sqrt_s": self.walk_per_sqrt_s,
            "drift_exponent": self.drift_exponent,
        }

    @classmethod
    def from_dict(cls, d: dict) -> "BranchTest":
        return cls(
            int(d["order"]),
            float(d["statistic"]),
            float(d["threshold"]),
            float(d["width_degc"]),
            float(d["walk_per_sqrt_s"]),
            float(d.get("drift_exponent", 1.0)),
        )

    def sentence(self, axis: str) -> str:
        """One line for the user: what the test found and did."""
        found = "differ" if self.order else "do not differ"
        done = "branch terms added" if self.order else "no branch terms"
        return (
            f"{axis}: one heating and one cooling leg cannot test a branch model on held-out legs; its heating "
            f"and cooling curves {found} beyond the drift the data shows (Wald {self.statistic:.3g} against "
            f"{self.threshold:.3g}): {done}"
        )


@dataclass(frozen=True)
class OrderTest:
    """The temperature polynomial's order all the calibration data support beyond the drift, where only two held-out
    legs judge the choice (:func:`gyrocomp.fitting.order_evidence.order_test`).

    ``order``: the highest order whose top term stands out (0: none does); ``statistics``: the Wald statistic of
    the top term of each order 1..N in the fit of that order [chi-square, 1 degree of freedom]; ``threshold``: the
    value a statistic had to exceed; ``drift_exponents``: the exponent alpha of the drift model each statistic was
    computed under [dimensionless]."""

    order: int
    statistics: tuple[float, ...]
    threshold: float
    drift_exponents: tuple[float, ...]

    def to_dict(self) -> dict:
        return {
            "order": self.order,
            "statistics": list(self.statistics),
            "threshold": self.threshold,
            "drift_exponents": list(self.drift_exponents),
        }

    @classmethod
    def from_dict(cls, d: dict) -> "OrderTest":
        return cls(
            int(d["order"]),
            tuple(float(v) for v in d["statistics"]),
            float(d["threshold"]),
            tuple(float(v) for v in d["drift_exponents"]),
        )


@dataclass(frozen=True)
class SelectionReport:
    """The choice for one axis by held-out drift (:class:`gyrocomp.fitting.axis_selection.AxisSelection` as stored):
    how the data was held out, the moving-average window of the score [s], every candidate's result, the best
    and the chosen one (the simplest within one standard error of the best); the drifts are in the axis's
    ``unit`` (deg/s, or g for an accelerometer axis). ``chosen_drift`` +- ``chosen_standard_error`` is the drift
    to expect on data like a held-out fold (None in files written before it was stored); ``fold_note`` says why
    the folds are not of the kind asked for; ``branch_test`` what decided the branch terms where no fold could;
    ``lag_from_unit`` whether the lag was kept because the other axes of the die chose one (the folds unable to
    tell this axis's model with it from the one without; False in files written before it was stored);
    ``decided_by`` the rule that made the final choice, in one line ("" in files written before it was stored);
    ``order_test`` what all the data said of the polynomial's order where two held-out legs were all there was;
    ``ramp_rates_degc_per_min`` each calibration recording's typical ramp rate [degC/min] (NaN: it did not ramp;
    empty in files written before it was stored).
    """

    axis: str
    fold_kind: str
    folds: tuple[str, ...]
    window_s: float
    temperature_step_degc: float
    band_degc: tuple[float, float] | None
    best: Candidate
    chosen: Candidate
    raw_drift: float | None
    chosen_drift: float | None
    validated: bool
    generalizes: bool
    candidates: tuple[CandidateResult, ...]
    unit: AxisUnit = "deg/s"
    chosen_standard_error: float | None = None
    fold_note: str = ""
    branch_test: BranchTest | None = None
    lag_from_unit: bool = False
    decided_by: str = ""
    order_test: OrderTest | None = None
    ramp_rates_degc_per_min: tuple[float, ...] = ()

    raw_drift_dps = in_unit("raw_drift", "deg/s", "raw_drift_dps")
    chosen_drift_dps = in_unit("chosen_drift", "deg/s", "chosen_drift_dps")

    def result(self, label: str) -> CandidateResult:
        """The result of the candidate named ``label``."""
        for result in self.candidates:
            if result.candidate.label == label:
                return result
        raise KeyError(f"label: no candidate {label!r} for {self.axis}")

    @classmethod
    def from_dict(cls, d: dict, unit: AxisUnit = "deg/s") -> "SelectionReport":
        band = d.get("band_degc")
        return cls(
            str(d["axis"]),
            str(d["fold_kind"]),
            tuple(d.get("folds", ())),
            float(d["window_s"]),
            float(d.get("temperature_step_degc", 0.0)),
            None if band is None else (float(band[0]), float(band[1])),
            Candidate.from_dict(d["best"]),
            Candidate.from_dict(d["chosen"]),
            _number(_entry_in_unit(d, "raw_drift", unit)),
            _number(_entry_in_unit(d, "chosen_drift", unit)),
            bool(d.get("validated", True)),
            bool(d.get("generalizes", True)),
            tuple(CandidateResult.from_dict(c, unit) for c in d.get("candidates", ())),
            unit,
            _number(_entry_in_unit(d, "chosen_standard_error", unit)),
            str(d.get("fold_note", "")),
            BranchTest.from_dict(d["branch_test"]) if d.get("branch_test") else None,
            bool(d.get("lag_from_unit", False)),
            str(d.get("decided_by", "")),
            OrderTest.from_dict(d["order_test"]) if d.get("order_test") else None,
            tuple(math.nan if r is None else float(r) for r in d.get("ramp_rates_degc_per_min", ())),
        )

    @property
    def ramp_note(self) -> str:
        """What the runs' ramp rates could tell of the memory, in words (:func:`separation_sentence`; empty in
        files written before the rates were stored)."""
        return separation_sentence(self.ramp_rates_degc_per_min)

    @property
    def rates_separate(self) -> bool:
        """Whether the runs' ramp rates could tell a lag or a rate term from a memory of the turn
        (:func:`gyrocomp.measures.ramp_rate.ramp_rates_separate`)."""
        return ramp_rates_separate(self.ramp_rates_degc_per_min)


_CHOSEN = re.compile(r"^(?P<memory>[a-z+-]+)(?: \(order (?P<order>\d+)\))?$")


@dataclass(frozen=True)
class MemoryChoice:
    """The thermal memory chosen for one axis (``memory`` one of :data:`MEMORIES`, with the turning-point order,
    0 without), its lag's time constant [s], the polynomial order and weighting it came with, and the score of
    each memory (held-out drift [the axis's unit], or BIC when ``HysteresisReport.by_bic``; None where not
    computed), and where the thermal fit chose the polynomial order itself, the score of each order."""

    memory: str
    hysteresis_order: int
    lag_time_constant_s: float
    order: int | None
    weighting: str | None
    scores: dict[str, float | None] = field(default_factory=dict)
    order_scores: dict[int, float] = field(default_factory=dict)

    @property
    def label(self) -> str:
        """``turning-point (order 2)``, ``lag``, ``none``."""
        return memory_label(self.memory, self.hysteresis_order)

    def to_dict(self, by_bic: bool = False, unit: AxisUnit = "deg/s") -> dict:
        """As the model file stores it (``scores_bic`` when the scores are BIC, else ``scores_dps`` or
        ``scores_g`` by the axis's ``unit``)."""
        out = {
            "chosen": self.label,
            "memory": self.memory,
            "hysteresis_order": self.hysteresis_order,
            "lag_time_constant_s": self.lag_time_constant_s,
            "order": self.order,
        }
        if self.weighting is not None:
            out["weighting"] = self.weighting
        if self.order_scores:
            out["order_scores"] = {str(o): float(v) for o, v in self.order_scores.items()}
        out["scores_bic" if by_bic else "scores" + unit_suffix(unit)] = dict(self.scores)
        return out

    @classmethod
    def from_dict(cls, d: dict, unit: AxisUnit = "deg/s") -> "MemoryChoice":
        if "memory" in d:
            memory, order = str(d["memory"]), int(d.get("hysteresis_order", 0))
        else:  # files before the fields: the chosen memory as text
            match = _CHOSEN.match(str(d.get("chosen", "none")))
            memory, order = (match["memory"], int(match["order"] or 0)) if match else (str(d.get("chosen")), 0)
        scores = _entry_in_unit(d, "scores", unit, d.get("scores_bic", {})) or {}
        return cls(
            memory,
            order,
            float(d.get("lag_time_constant_s", 0.0)),
            None if d.get("order") is None else int(d["order"]),
            d.get("weighting"),
            {str(k): _number(v) for k, v in scores.items()},
            {int(o): float(v) for o, v in (d.get("order_scores") or {}).items()},
        )


@dataclass(frozen=True)
class HysteresisReport:
    """Thermal lag and turning-point hysteresis: the mode asked for, how the memory was chosen
    (``leave-one-run-out``, ``bic``, or why none was), and the choice per axis (its scores in ``unit``)."""

    mode: str
    selection: str
    axes: dict[str, MemoryChoice]
    unit: AxisUnit = "deg/s"

    @property
    def by_bic(self) -> bool:
        return self.selection == "bic"

    @property
    def memories_scored(self) -> tuple[str, ...]:
        """The memories some axis has a score for, in :data:`MEMORIES` order."""
        seen = {m for choice in self.axes.values() for m in choice.scores}
        return tuple(m for m in MEMORIES if m in seen) + tuple(sorted(seen - set(MEMORIES)))

    def to_dict(self) -> dict:
        """As the model file stores it (no ``axes`` when no memory was chosen)."""
        out = {"mode": self.mode, "selection": self.selection}
        if self.axes:
            out["axes"] = {axis: choice.to_dict(self.by_bic, self.unit) for axis, choice in self.axes.items()}
        return out

    @classmethod
    def from_dict(cls, d: dict, unit: AxisUnit = "deg/s") -> "HysteresisReport":
        return cls(
            str(d.get("mode", "auto")),
            str(d.get("selection", "none")),
            {str(a): MemoryChoice.from_dict(v, unit) for a, v in (d.get("axes") or {}).items()},
            unit,
        )


@dataclass(frozen=True)
class OrderSelection:
    """The polynomial order by ``method`` (``leave-one-run-out`` residual [deg/s] or ``bic``): each axis's score of
    each order tried."""

    method: str
    scores: dict[str, dict[int, float]]

    @property
    def orders(self) -> tuple[int, ...]:
        return tuple(sorted({p for s in self.scores.values() for p in s}))


@dataclass(frozen=True)
class NetworkReport:
    """The temperature network: hidden layer sizes, restarts, seed, how it was trained, and per axis the
    validation RMS of each restart [``unit``: deg/s, or g for accelerometer axes] and the epochs of the one kept."""

    hidden: tuple[int, ...]
    restarts: int
    seed: int
    training: str
    validation_rmse: dict[str, tuple[float, ...]]
    epochs: dict[str, Any]
    unit: AxisUnit = "deg/s"

    def to_dict(self) -> dict:
        """As the model file stores it (``validation_rmse_dps`` or ``validation_rmse_g``)."""
        name = "validation_rmse" + unit_suffix(self.unit)
        return {
            "hidden": list(self.hidden),
            "restarts": self.restarts,
            "seed": self.seed,
            "training": self.training,
            "axes": {
                a: {name: list(self.validation_rmse[a]), "epochs": self.epochs.get(a)} for a in self.validation_rmse
            },
        }

    @classmethod
    def from_dict(cls, d: dict, unit: AxisUnit = "deg/s") -> "NetworkReport":
        axes = d.get("axes", {})
        return cls(
            tuple(int(h) for h in d["hidden"]),
            int(d.get("restarts", 1)),
            int(d.get("seed", 0)),
            str(d.get("training", "")),
            {a: tuple(float(v) for v in _entry_in_unit(i, "validation_rmse", unit, ())) for a, i in axes.items()},
            {a: i.get("epochs") for a, i in axes.items()},
            unit,
        )


@dataclass(frozen=True)
class GSensitivityRow:
    """One gyro axis's row of G [deg/s/g] and its standard errors (None: not fitted, the axis was not excited);
    with ``matrix2``, also its g x g sensitivities to xx, yy, zz, xy, xz, yz [deg/s/g^2] and their errors."""

    g_sensitivity_dps_per_g: tuple[float, ...]
    standard_error_dps_per_g: tuple[float | None, ...]
    g_squared_dps_per_g2: tuple[float | None, ...] | None = None
    g_squared_standard_error_dps_per_g2: tuple[float | None, ...] | None = None

    def to_dict(self) -> dict:
        out = {
            "g_sensitivity_dps_per_g": list(self.g_sensitivity_dps_per_g),
            "standard_error_dps_per_g": list(self.standard_error_dps_per_g),
        }
        if self.g_squared_dps_per_g2 is not None:
            out["g_squared_dps_per_g2"] = list(self.g_squared_dps_per_g2)
            out["g_squared_standard_error_dps_per_g2"] = list(self.g_squared_standard_error_dps_per_g2 or ())
        return out

    @classmethod
    def from_dict(cls, d: dict) -> "GSensitivityRow":
        squared = d.get("g_squared_dps_per_g2")
        errors = d.get("g_squared_standard_error_dps_per_g2")
        return cls(
            tuple(float(v) for v in d["g_sensitivity_dps_per_g"]),
            tuple(_number(v) for v in d.get("standard_error_dps_per_g", (None,) * 3)),
            None if squared is None else tuple(_number(v) for v in squared),
            None if errors is None else tuple(_number(v) for v in errors),
        )


@dataclass(frozen=True)
class GSensitivityReport:
    """The g-sensitivity fit: its mode (``matrix``, ``matrix2``, ``network`` or ``none``, with why), the static
    segments of each run, the accelerometer axes the positions excite, the rows of G, and the network's hidden
    layers (``network``)."""

    mode: str
    why: str | None
    static_segments: tuple[int, ...]
    excited_axes: tuple[str, ...]
    axes: dict[str, GSensitivityRow]
    hidden: tuple[int, ...] | None = None

    def to_dict(self) -> dict:
        """As the model file stores it (what the mode has: ``why`` for none, ``hidden`` for a network)."""
        out: dict[str, Any] = {"mode": self.mode}
        if self.why is not None:
            out["why"] = self.why
        if self.hidden is not None:
            out["hidden"] = list(self.hidden)
        if self.mode != "none":
            out["static_segments"] = list(self.static_segments)
        if self.mode in ("matrix", "matrix2"):
            out["excited_axes"] = list(self.excited_axes)
            out["axes"] = {axis: row.to_dict() for axis, row in self.axes.items()}
        return out

    @classmethod
    def from_dict(cls, d: dict) -> "GSensitivityReport":
        return cls(
            str(d.get("mode", "none")),
            d.get("why"),
            tuple(int(s) for s in d.get("static_segments", ())),
            tuple(d.get("excited_axes", ())),
            {
                a: GSensitivityRow.from_dict(i)
                for a, i in (d.get("axes") or {}).items()
                if "g_sensitivity_dps_per_g" in i
            },
            None if d.get("hidden") is None else tuple(int(h) for h in d["hidden"]),
        )


@dataclass(frozen=True)
class AxisFit:
    """One axis's fitted curve: its order (an int for a polynomial, the network's name for a network), the
    temperature range it was fitted on [degC], its fit RMS [``unit``: deg/s, or g for an accelerometer axis] where
    the fit reported one, and where the order was chosen by the polynomial's own fit, each order's score
    (held-out residual [``unit``] or BIC, as ``FitReport.order_selection`` says)."""

    order: int | str | None
    t_min_degc: float | None
    t_max_degc: float | None
    fit_rms: float | None
    unit: AxisUnit = "deg/s"
    scores: dict[int, float] = field(default_factory=dict)

    def to_dict(self) -> dict:
        """As the model file stores it (``fit_rms_dps`` or ``fit_rms_g``; no entry the fit did not report)."""
        out: dict[str, Any] = {"order": self.order, "t_min_degc": self.t_min_degc, "t_max_degc": self.t_max_degc}
        if self.scores:
            out["scores"] = {str(p): float(v) for p, v in self.scores.items()}
        if self.fit_rms is not None:
            out["fit_rms" + unit_suffix(self.unit)] = float(self.fit_rms)
        return out

    @classmethod
    def from_dict(cls, d: dict, unit: AxisUnit = "deg/s") -> "AxisFit":
        return cls(
            d.get("order"),
            _number(d.get("t_min_degc")),
            _number(d.get("t_max_degc")),
            _number(_entry_in_unit(d, "fit_rms", unit)),
            unit,
            {int(p): float(v) for p, v in (d.get("scores") or {}).items()},
        )


#: fewer held-out folds than this: the evidence for a model choice (and for the drift it expects) is thin
THIN_FOLDS = 4


@dataclass(frozen=True)
class ExpectedDrift:
    """The drift a model choice expects on data like a held-out fold (the next heating or cooling leg, or the next
    run): the chosen candidate's mean held-out drift and its standard error [``unit``], the moving-average window
    the drift is taken over [s], what was held out, and what the runs' ramp rates could tell of the memory
    (:func:`gyrocomp.measures.ramp_rate.separation_sentence`; empty in files written before the rates were stored).
    """

    axis: str
    model: str
    drift: float
    standard_error: float | None
    constant_drift: float | None
    unit: AxisUnit
    window_s: float
    fold_kind: str
    folds: int
    ramp_note: str = ""

    @property
    def thin(self) -> bool:
        """Fewer than :data:`THIN_FOLDS` folds: the figure rests on little evidence."""
        return self.folds < THIN_FOLDS

    def to_dict(self) -> dict:
        u = unit_suffix(self.unit)
        return {
            "axis": self.axis,
            "model": self.model,
            f"drift{u}": self.drift,
            f"standard_error{u}": self.standard_error,
            f"constant_drift{u}": self.constant_drift,
            "window_s": self.window_s,
            "fold_kind": self.fold_kind,
            "folds": self.folds,
            "thin": self.thin,
            "ramp_note": self.ramp_note,
        }


@dataclass(frozen=True)
class FitReport:
    """How a calibration was fitted (see the module). ``method`` is the temperature model's family
    (``polynomial``, ``mlp``, ``population prior``, ...; None without a temperature model). ``accel`` is the
    accelerometer's own account, its figures in g.

    Attributes
    ----------
    method : str or None
        The temperature model's family.
    axes : dict of str to AxisFit
        Each axis's fit: residuals [the axis's unit] and range [degC].
    order_selection, selection : OrderSelection, dict of str to SelectionReport
        The model choice: every candidate's held-out drift per fold.
    hysteresis, network, acceleration : HysteresisReport, NetworkReport, GSensitivityReport or None
        The thermal memory's, the network's and the g-sensitivity's accounts.
    pipeline : str or None
        The pipeline's name (``cascade``, ``joint``, ...).
    stages : tuple of FitReport
        A cascade's stages, each its own report.
    accel : FitReport or None
        The accelerometer's account, in g.
    sections : dict
        The file's sections this release does not read, kept as they were.
    """

    method: str | None
    axes: dict[str, AxisFit]
    order_selection: OrderSelection | None
    selection: dict[str, SelectionReport]
    hysteresis: HysteresisReport | None
    network: NetworkReport | None
    acceleration: GSensitivityReport | None
    pipeline: str | None
    stages: tuple["FitReport", ...]
    accel: "FitReport | None"
    sections: dict[str, Any]

    @classmethod
    def from_dict(cls, d: dict | None, unit: AxisUnit = "deg/s") -> "FitReport":
        """Read the ``fit_report`` object of a model file (any schema version); ``unit`` is the unit of the axes it
        accounts for (its ``accel`` section is read in g).

        Parameters
        ----------
        d : dict or None
            The model file's ``fit_report`` object.
        unit : {"deg/s", "g"}
            The unit of the axes it accounts for.
        """
        d = d or {}
        axes = {a: AxisFit.from_dict(i, unit) for a, i in (d.get("axes") or {}).items()}
        scores = {a: fit.scores for a, fit in axes.items() if fit.scores}
        order_selection = (
            OrderSelection(str(d.get("order_selection", "")), scores) if scores and "network" not in d else None
        )
        hysteresis = d.get("hysteresis")
        acceleration = d.get("acceleration")
        return cls(
            method=d.get("temperature"),
            axes=axes,
            order_selection=order_selection,
            selection={a: SelectionReport.from_dict(s, unit) for a, s in (d.get("selection") or {}).items()},
            hysteresis=HysteresisReport.from_dict(hysteresis, unit) if isinstance(hysteresis, dict) else None,
            network=NetworkReport.from_dict(d["network"], unit) if d.get("network") else None,
            acceleration=GSensitivityReport.from_dict(acceleration) if isinstance(acceleration, dict) else None,
            pipeline=d.get("pipeline"),
            stages=tuple(cls.from_dict(s, unit) for s in d.get("stages") or ()),
            accel=cls.from_dict(d["accel"], "g") if isinstance(d.get("accel"), dict) else None,
            sections={k: v for k, v in d.items() if k not in _TYPED},
        )

    def expected_drift(self) -> dict[str, ExpectedDrift]:
        """Per axis chosen by held-out drift, the drift to expect on unseen data of the same kind (empty when the
        model was not chosen that way, or in files written before the standard error was stored it is None)."""
        out = {}
        for axis, sel in self.selection.items():
            if sel.chosen_drift is None:
                continue
            out[axis] = ExpectedDrift(
                axis,
                sel.chosen.label,
                sel.chosen_drift,
                sel.chosen_standard_error,
                sel.raw_drift,
                sel.unit,
                sel.window_s,
                sel.fold_kind,
                len(sel.folds),
                sel.ramp_note,
            )
        return out


__all__ = [
    "AxisFit",
    "BranchTest",
    "CandidateResult",
    "ExpectedDrift",
    "FitReport",
    "GSensitivityReport",
    "GSensitivityRow",
    "HysteresisReport",
    "MemoryChoice",
    "NetworkReport",
    "OrderSelection",
    "SelectionReport",
    "OrderTest",
    "THIN_FOLDS",
]
