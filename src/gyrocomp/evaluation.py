"""Judging a calibration on runs: apply it and compute the thesis's figures of merit, whole or stage by stage.

The layer above fitting and applying: :mod:`gyrocomp.metrics` holds the figures (raw and compensated
recordings in), this module runs the calibration to get the compensated one.
"""

from __future__ import annotations

import warnings
from dataclasses import asdict, dataclass

from .calibration import Calibration
from .compensate import apply
from .errors import DataQualityWarning
from .metrics import AxisMetrics, Evaluation, default_window_s, evaluate_run
from .recording import Recording


def evaluate(calibration: Calibration, recordings: list[Recording] | Recording, *, window_s: float | None = None,
             turn_on_window_s: float | None = None) -> Evaluation:
    """Apply ``calibration`` to each recording and compare raw with compensated (:func:`evaluate_run`).

    Parameters
    ----------
    calibration : Calibration
    recordings : Recording or list of Recording
        Runs to judge (not those the calibration was fitted on, for an honest figure).
    window_s : float, optional
        Moving-average window [s]; default: tau at each raw run's Allan minimum, at least 1 s.
    turn_on_window_s : float, optional
        Estimate each run's turn-on constant from its first seconds [s].
    """
    recordings = [recordings] if isinstance(recordings, Recording) else list(recordings)
    return Evaluation([evaluate_run(rec, apply(calibration, rec, turn_on_window_s=turn_on_window_s),
                                    window_s=window_s, accel=bool(calibration.accel_axes)) for rec in recordings])


@dataclass(frozen=True)
class StageEvaluation:
    """One run through the stages of a calibration (the thesis's Table 4.4): ``stages`` maps a stage
    name (raw, temperature only, + acceleration, + hysteresis) to each axis's figures."""

    file: str
    window_s: float
    stages: dict[str, dict[str, AxisMetrics]]

    def to_dict(self) -> dict:
        return {"file": self.file, "window_s": self.window_s,
                "stages": {name: {a: asdict(m) for a, m in axes.items()} for name, axes in self.stages.items()}}


def stage_calibrations(calibration) -> dict:
    """The stages a calibration has, in the thesis's order, each as a calibration with the later parts off."""
    stages = {}
    later = [p for p, on in (("acceleration", calibration.has_acceleration), ("hysteresis", calibration.has_hysteresis))
             if on]
    stages["temperature only"] = calibration.without(*later)
    if calibration.has_acceleration:
        stages["temperature + acceleration"] = calibration.without(*[p for p in later if p != "acceleration"])
    if calibration.has_hysteresis:
        name = "temperature + acceleration + hysteresis" if calibration.has_acceleration else "temperature + hysteresis"
        stages[name] = calibration
    return stages


def evaluate_stages(calibration, recording: Recording, *, window_s: float | None = None,
                    turn_on_window_s: float | None = None) -> StageEvaluation:
    """Bias offset, improvement, bias instability and integration time of a run at each stage of the calibration."""
    if window_s is None:
        window_s = default_window_s(recording)
    stages: dict[str, dict[str, AxisMetrics]] = {}
    for name, cal in stage_calibrations(calibration).items():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DataQualityWarning)
            result = evaluate_run(recording, apply(cal, recording, turn_on_window_s=turn_on_window_s), window_s=window_s)
        stages[name] = {axis: m for axis, m in result.axes.items() if axis in calibration.axes}
    return StageEvaluation(recording.source, float(window_s), stages)


__all__ = ["StageEvaluation", "evaluate", "evaluate_stages", "stage_calibrations"]
