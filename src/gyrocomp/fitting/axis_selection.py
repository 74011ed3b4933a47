"""The model choice's result for one axis (:class:`AxisSelection`): how the data were held out, every candidate's
fold scores, the best and the chosen candidate and the rule that chose, as the model file stores it. The choice
itself is :mod:`gyrocomp.fitting.selection` (the scores) and :mod:`gyrocomp.fitting.choice` (the rule per axis)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..calibration.candidate import Candidate
from ..calibration.fit_report import BranchTest, OrderTest
from ..measures.ramp_rate import ramp_rates_separate
from ..units import AxisUnit, in_unit, unit_suffix
from .folds import FoldKind
from .scores import CandidateScore, json_number


@dataclass(frozen=True)
class AxisSelection:
    """The choice for one axis, with every candidate's fold scores.

    Attributes
    ----------
    axis : str
    fold_kind : {"runs", "legs", "blocks"}
    folds : tuple of str
        Name of each fold (``run 2``, ``run 1 leg 3 (cooling)``, ``run 1 block 2``).
    window_s : float
        Moving-average window of the drift score [s].
    temperature_step_degc : float
        Step of a coarsely quantized temperature register [degC], 0 when the temperature is fine-grained.
    scores : tuple of CandidateScore
    best : Candidate
        The lowest mean held-out drift.
    chosen : Candidate
        The simplest candidate within one standard error of the best.
    band_degc : (lo, hi) or None
        The band where the branches part in the data [degC], tried with the turning-point candidates.
    unit : {"deg/s", "g"}
        The unit of the axis, and of every drift here.
    fold_note : str
        Why the folds are not of the kind asked for (empty when they are).
    branch_test : BranchTest or None
        Where no fold could judge a branch model (one heating and one cooling leg), the test that decided
        whether the chosen model gets one (:func:`gyrocomp.fitting.branch_evidence.branch_test`); None elsewhere.
    lag_from_unit : bool
        Whether the chosen lag was taken because another axis of the same die chose one, the folds being unable
        to tell it from the same model without (:func:`gyrocomp.fitting.choice.choose_axis`).
    ramp_rates_degc_per_min : tuple of float
        Each calibration recording's typical ramp rate [degC/min] (NaN: it does not ramp); empty where not known.
    """

    axis: str
    fold_kind: FoldKind
    folds: tuple[str, ...]
    window_s: float
    temperature_step_degc: float
    scores: tuple[CandidateScore, ...]
    best: Candidate
    chosen: Candidate
    band_degc: tuple[float, float] | None = None
    unit: AxisUnit = "deg/s"
    fold_note: str = ""
    branch_test: BranchTest | None = None
    lag_from_unit: bool = False
    #: where ``lag_from_unit``, the choice this axis made on its own (the final fit falls back to it where this
    #: axis's own runs do not see the die's lag: ThermalHysteresisModel.lag_evidence_)
    alone: "AxisSelection | None" = field(default=None, repr=False, compare=False)
    #: the rule that made the final choice, in one line (:func:`gyrocomp.fitting.choice.choose_axis`)
    decided_by: str = ""
    #: where two held-out legs are all there is, what all the data say of the polynomial's order
    order_test: OrderTest | None = None
    ramp_rates_degc_per_min: tuple[float, ...] = ()

    @property
    def rates_separate(self) -> bool:
        """Whether the runs' ramp rates can tell a lag or a rate term from a memory of the turn
        (:func:`gyrocomp.measures.ramp_rate.ramp_rates_separate`)."""
        return ramp_rates_separate(self.ramp_rates_degc_per_min)

    def score_of(self, candidate: Candidate) -> CandidateScore:
        return next(s for s in self.scores if s.candidate == candidate)

    @property
    def raw_drift(self) -> float:
        """Mean held-out drift with the run constant alone (time-weighted) [``unit``]."""
        return self.score_of(Candidate(0)).mean_drift

    @property
    def chosen_drift(self) -> float:
        """Mean held-out drift of the chosen candidate [``unit``]."""
        return self.score_of(self.chosen).mean_drift

    @property
    def chosen_standard_error(self) -> float:
        """Standard error of the chosen candidate's mean held-out drift [``unit``]: with its mean, the drift
        expected on data like a held-out fold (the next heating or cooling leg, or the next run)."""
        return self.score_of(self.chosen).standard_error

    raw_drift_dps = in_unit("raw_drift", "deg/s", "raw_drift_dps")
    chosen_drift_dps = in_unit("chosen_drift", "deg/s", "chosen_drift_dps")

    @property
    def validated(self) -> bool:
        """Whether the folds held enough data to score the run constant alone."""
        return bool(np.isfinite(self.raw_drift))

    @property
    def generalizes(self) -> bool:
        """Whether some temperature model beat the run constant alone on held-out data."""
        return self.chosen.has_temperature_model

    def to_dict(self) -> dict:
        """As the model file stores it: the drifts under names that say the axis's unit."""
        u = unit_suffix(self.unit)
        return {
            "axis": self.axis,
            "fold_kind": self.fold_kind,
            "folds": list(self.folds),
            "window_s": self.window_s,
            "temperature_step_degc": self.temperature_step_degc,
            "band_degc": list(self.band_degc) if self.band_degc is not None else None,
            "best": self.best.to_dict(),
            "chosen": self.chosen.to_dict(),
            f"raw_drift{u}": json_number(self.raw_drift),
            f"chosen_drift{u}": json_number(self.chosen_drift),
            f"chosen_standard_error{u}": json_number(self.chosen_standard_error),
            "fold_note": self.fold_note,
            "validated": self.validated,
            "generalizes": self.generalizes,
            "branch_test": self.branch_test.to_dict() if self.branch_test is not None else None,
            "lag_from_unit": self.lag_from_unit,
            "decided_by": self.decided_by,
            "order_test": self.order_test.to_dict() if self.order_test is not None else None,
            "ramp_rates_degc_per_min": [json_number(r) for r in self.ramp_rates_degc_per_min],
            "candidates": [s.to_dict(self.unit) for s in self.scores],
        }


__all__ = ["AxisSelection"]
