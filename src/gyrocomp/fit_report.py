"""How a calibration was fitted, as typed records: ``Calibration.report`` (a :class:`FitReport`).

The model file keeps the account as the JSON object ``fit_report`` (the shape every schema version has written);
:meth:`FitReport.from_dict` reads it into these dataclasses, so the command line, the HTML report and the fleet
figures read attributes instead of parsing strings. Older files that wrote the chosen thermal memory only as text
(``"turning-point (order 2)"``) are read into the same fields. Sections the fit did not produce are None (or empty);
what has no typed record here (the online learner's, the population prior's, a triad's account) stays in
``FitReport.sections``.

Units are in the names: [deg/s] (``_dps``), [s], [degC], [deg/s/g].
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Any, Literal

#: the thermal memories a gyro axis's model may carry
MEMORIES = ("none", "lag", "turning-point", "turning-point+lag")
_TYPED = ("temperature", "axes", "order_selection", "selection", "hysteresis", "network", "acceleration", "stages",
          "accel", "pipeline")


def memory_name(lag: bool, hysteresis_order: int) -> str:
    """The thermal memory a model carries: ``none``, ``lag``, ``turning-point`` or ``turning-point+lag``."""
    if lag and hysteresis_order:
        return "turning-point+lag"
    return "lag" if lag else ("turning-point" if hysteresis_order else "none")


def memory_label(memory: str, hysteresis_order: int) -> str:
    """A thermal memory in the words the model file stores: ``turning-point (order 2)``, ``lag``, ``none``."""
    return memory + (f" (order {hysteresis_order})" if hysteresis_order else "")


def _number(value) -> float | None:
    """A score as stored: None where it could not be computed."""
    if value is None:
        return None
    value = float(value)
    return value if math.isfinite(value) else None


#: how a candidate's fit weights the samples: as they come in time, or each temperature bin alike
Weighting = Literal["time", "temperature-balanced"]


@dataclass(frozen=True)
class Candidate:
    """One model of an axis's bias: polynomial order, thermal lag, turning-point order, fit weighting, and whether
    the turning-point terms act only in the band found in the data. The model choice scores these
    (:mod:`gyrocomp.models.selection`) and the report names them."""

    order: int
    lag: bool = False
    hysteresis_order: int = 0
    weighting: Weighting = "time"
    band: bool = False

    @property
    def memory(self) -> str:
        """``none``, ``lag``, ``turning-point`` or ``turning-point+lag``."""
        return memory_name(self.lag, self.hysteresis_order)

    @property
    def complexity(self) -> int:
        """Number of shape terms: the order, the lag's time constant, two per hysteresis order, one for a band."""
        return self.order + int(self.lag) + 2 * self.hysteresis_order + int(self.band)

    @property
    def has_temperature_model(self) -> bool:
        return self.order > 0 or self.lag or self.hysteresis_order > 0

    @property
    def label(self) -> str:
        """Short name, e.g. ``poly:3 + lag + turning-point:2 (time)``; ``constant`` for order 0."""
        parts = ["constant" if self.order == 0 else f"poly:{self.order}"]
        if self.lag:
            parts.append("lag")
        if self.hysteresis_order:
            parts.append(f"turning-point:{self.hysteresis_order}" + (" in band" if self.band else ""))
        return " + ".join(parts) + f" ({self.weighting})"

    def to_dict(self) -> dict:
        return {"order": self.order, "lag": self.lag, "hysteresis_order": self.hysteresis_order,
                "weighting": self.weighting, "band": self.band, "label": self.label}

    @classmethod
    def from_dict(cls, d: dict) -> "Candidate":
        """A stored candidate (its ``label`` is derived from the fields)."""
        return cls(int(d["order"]), bool(d.get("lag", False)), int(d.get("hysteresis_order", 0)),
                   d.get("weighting", "time"), bool(d.get("band", False)))


@dataclass(frozen=True)
class CandidateResult:
    """A candidate's held-out drift: mean and standard error over the folds, each fold's, and the lag each fold's
    fit chose [deg/s, s]; None where a fold held too little data."""

    candidate: Candidate
    mean_drift_dps: float | None
    standard_error_dps: float | None
    fold_drift_dps: tuple[float | None, ...]
    fold_lag_s: tuple[float, ...]

    @classmethod
    def from_dict(cls, d: dict) -> "CandidateResult":
        return cls(Candidate.from_dict(d), _number(d.get("mean_drift_dps")), _number(d.get("standard_error_dps")),
                   tuple(_number(v) for v in d.get("fold_drift_dps", ())),
                   tuple(float(v) for v in d.get("fold_lag_s", ())))


@dataclass(frozen=True)
class SelectionReport:
    """The choice for one axis by held-out drift (:class:`gyrocomp.models.selection.AxisSelection` as stored):
    how the data was held out, the moving-average window of the score [s], every candidate's result, the best
    and the chosen one (the simplest within one standard error of the best)."""

    axis: str
    fold_kind: str
    folds: tuple[str, ...]
    window_s: float
    temperature_step_degc: float
    band_degc: tuple[float, float] | None
    best: Candidate
    chosen: Candidate
    raw_drift_dps: float | None
    chosen_drift_dps: float | None
    validated: bool
    generalizes: bool
    candidates: tuple[CandidateResult, ...]

    def result(self, label: str) -> CandidateResult:
        """The result of the candidate named ``label``."""
        for result in self.candidates:
            if result.candidate.label == label:
                return result
        raise KeyError(f"label: no candidate {label!r} for {self.axis}")

    @classmethod
    def from_dict(cls, d: dict) -> "SelectionReport":
        band = d.get("band_degc")
        return cls(str(d["axis"]), str(d["fold_kind"]), tuple(d.get("folds", ())), float(d["window_s"]),
                   float(d.get("temperature_step_degc", 0.0)), None if band is None else (float(band[0]), float(band[1])),
                   Candidate.from_dict(d["best"]), Candidate.from_dict(d["chosen"]),
                   _number(d.get("raw_drift_dps")), _number(d.get("chosen_drift_dps")), bool(d.get("validated", True)),
                   bool(d.get("generalizes", True)), tuple(CandidateResult.from_dict(c) for c in d.get("candidates", ())))


_CHOSEN = re.compile(r"^(?P<memory>[a-z+-]+)(?: \(order (?P<order>\d+)\))?$")


@dataclass(frozen=True)
class MemoryChoice:
    """The thermal memory chosen for one axis (``memory`` one of :data:`MEMORIES`, with the turning-point order,
    0 without), its lag's time constant [s], the polynomial order and weighting it came with, and the score of
    each memory (held-out drift [deg/s], or BIC when ``HysteresisReport.by_bic``; None where not computed), and
    where the thermal fit chose the polynomial order itself, the score of each order."""

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

    def to_dict(self, by_bic: bool = False) -> dict:
        """As the model file stores it (``scores_bic`` instead of ``scores_dps`` when the scores are BIC)."""
        out = {"chosen": self.label, "memory": self.memory, "hysteresis_order": self.hysteresis_order,
               "lag_time_constant_s": self.lag_time_constant_s, "order": self.order}
        if self.weighting is not None:
            out["weighting"] = self.weighting
        if self.order_scores:
            out["order_scores"] = {str(o): float(v) for o, v in self.order_scores.items()}
        out["scores_bic" if by_bic else "scores_dps"] = dict(self.scores)
        return out

    @classmethod
    def from_dict(cls, d: dict) -> "MemoryChoice":
        if "memory" in d:
            memory, order = str(d["memory"]), int(d.get("hysteresis_order", 0))
        else:  # files before the fields: the chosen memory as text
            match = _CHOSEN.match(str(d.get("chosen", "none")))
            memory, order = (match["memory"], int(match["order"] or 0)) if match else (str(d.get("chosen")), 0)
        scores = d.get("scores_dps", d.get("scores_bic", {})) or {}
        return cls(memory, order, float(d.get("lag_time_constant_s", 0.0)),
                   None if d.get("order") is None else int(d["order"]), d.get("weighting"),
                   {str(k): _number(v) for k, v in scores.items()},
                   {int(o): float(v) for o, v in (d.get("order_scores") or {}).items()})


@dataclass(frozen=True)
class HysteresisReport:
    """Thermal lag and turning-point hysteresis: the mode asked for, how the memory was chosen
    (``leave-one-run-out``, ``bic``, or why none was), and the choice per axis."""

    mode: str
    selection: str
    axes: dict[str, MemoryChoice]

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
            out["axes"] = {axis: choice.to_dict(self.by_bic) for axis, choice in self.axes.items()}
        return out

    @classmethod
    def from_dict(cls, d: dict) -> "HysteresisReport":
        return cls(str(d.get("mode", "auto")), str(d.get("selection", "none")),
                   {str(a): MemoryChoice.from_dict(v) for a, v in (d.get("axes") or {}).items()})


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
    validation RMS of each restart [deg/s] and the epochs of the one kept."""

    hidden: tuple[int, ...]
    restarts: int
    seed: int
    training: str
    validation_rmse_dps: dict[str, tuple[float, ...]]
    epochs: dict[str, Any]

    def to_dict(self) -> dict:
        """As the model file stores it."""
        return {"hidden": list(self.hidden), "restarts": self.restarts, "seed": self.seed, "training": self.training,
                "axes": {a: {"validation_rmse_dps": list(self.validation_rmse_dps[a]), "epochs": self.epochs.get(a)}
                         for a in self.validation_rmse_dps}}

    @classmethod
    def from_dict(cls, d: dict) -> "NetworkReport":
        axes = d.get("axes", {})
        return cls(tuple(int(h) for h in d["hidden"]), int(d.get("restarts", 1)), int(d.get("seed", 0)),
                   str(d.get("training", "")),
                   {a: tuple(float(v) for v in i.get("validation_rmse_dps", ())) for a, i in axes.items()},
                   {a: i.get("epochs") for a, i in axes.items()})


@dataclass(frozen=True)
class GSensitivityRow:
    """One gyro axis's row of G [deg/s/g] and its standard errors (None: not fitted, the axis was not excited);
    with ``matrix2``, also its g x g sensitivities to xx, yy, zz, xy, xz, yz [deg/s/g^2] and their errors."""

    g_sensitivity_dps_per_g: tuple[float, ...]
    standard_error_dps_per_g: tuple[float | None, ...]
    g_squared_dps_per_g2: tuple[float | None, ...] | None = None
    g_squared_standard_error_dps_per_g2: tuple[float | None, ...] | None = None

    def to_dict(self) -> dict:
        out = {"g_sensitivity_dps_per_g": list(self.g_sensitivity_dps_per_g),
               "standard_error_dps_per_g": list(self.standard_error_dps_per_g)}
        if self.g_squared_dps_per_g2 is not None:
            out["g_squared_dps_per_g2"] = list(self.g_squared_dps_per_g2)
            out["g_squared_standard_error_dps_per_g2"] = list(self.g_squared_standard_error_dps_per_g2 or ())
        return out

    @classmethod
    def from_dict(cls, d: dict) -> "GSensitivityRow":
        squared = d.get("g_squared_dps_per_g2")
        errors = d.get("g_squared_standard_error_dps_per_g2")
        return cls(tuple(float(v) for v in d["g_sensitivity_dps_per_g"]),
                   tuple(_number(v) for v in d.get("standard_error_dps_per_g", (None,) * 3)),
                   None if squared is None else tuple(_number(v) for v in squared),
                   None if errors is None else tuple(_number(v) for v in errors))


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
        return cls(str(d.get("mode", "none")), d.get("why"), tuple(int(s) for s in d.get("static_segments", ())),
                   tuple(d.get("excited_axes", ())),
                   {a: GSensitivityRow.from_dict(i) for a, i in (d.get("axes") or {}).items()
                    if "g_sensitivity_dps_per_g" in i},
                   None if d.get("hidden") is None else tuple(int(h) for h in d["hidden"]))


@dataclass(frozen=True)
class AxisFit:
    """One axis's fitted curve: its order (an int for a polynomial, the network's name for a network), the
    temperature range it was fitted on [degC], and its fit RMS [deg/s or g] where the fit reported one."""

    order: int | str | None
    t_min_degc: float | None
    t_max_degc: float | None
    fit_rms: float | None


@dataclass(frozen=True)
class FitReport:
    """How a calibration was fitted (see the module). ``method`` is the temperature model's family
    (``polynomial``, ``mlp``, ``population prior``, ...; None without a temperature model)."""

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
    def from_dict(cls, d: dict | None) -> "FitReport":
        """Read the ``fit_report`` object of a model file (any schema version)."""
        d = d or {}
        axes_in = d.get("axes") or {}
        axes = {a: AxisFit(i.get("order"), _number(i.get("t_min_degc")), _number(i.get("t_max_degc")),
                           _number(i.get("fit_rms_dps"))) for a, i in axes_in.items()}
        scores = {a: {int(p): float(v) for p, v in i["scores"].items()} for a, i in axes_in.items() if i.get("scores")}
        order_selection = (OrderSelection(str(d.get("order_selection", "")), scores)
                           if scores and "network" not in d else None)
        hysteresis = d.get("hysteresis")
        acceleration = d.get("acceleration")
        return cls(
            method=d.get("temperature"), axes=axes, order_selection=order_selection,
            selection={a: SelectionReport.from_dict(s) for a, s in (d.get("selection") or {}).items()},
            hysteresis=HysteresisReport.from_dict(hysteresis) if isinstance(hysteresis, dict) else None,
            network=NetworkReport.from_dict(d["network"]) if d.get("network") else None,
            acceleration=GSensitivityReport.from_dict(acceleration) if isinstance(acceleration, dict) else None,
            pipeline=d.get("pipeline"),
            stages=tuple(cls.from_dict(s) for s in d.get("stages") or ()),
            accel=cls.from_dict(d["accel"]) if isinstance(d.get("accel"), dict) else None,
            sections={k: v for k, v in d.items() if k not in _TYPED})


__all__ = ["AxisFit", "Candidate", "CandidateResult", "FitReport", "GSensitivityReport", "GSensitivityRow",
           "HysteresisReport", "MEMORIES", "MemoryChoice", "NetworkReport", "OrderSelection", "SelectionReport",
           "Weighting", "memory_label", "memory_name"]
