"""A calibration judged on recordings: whole, by stage, against an autopilot's installed calibration
(:mod:`.evaluate_model`); the thesis's method comparison (:mod:`.comparison`); held-out validation
(:mod:`.validation`)."""

from __future__ import annotations

from .evaluate_model import (
    compare_installed,
    evaluate,
    evaluate_stages,
    InstalledComparison,
    stage_calibrations,
    StageEvaluation,
    triad_residuals,
)

__all__ = [
    "InstalledComparison",
    "StageEvaluation",
    "compare_installed",
    "evaluate",
    "evaluate_stages",
    "stage_calibrations",
    "triad_residuals",
]
