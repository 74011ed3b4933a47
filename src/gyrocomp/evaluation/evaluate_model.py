"""Judging a calibration on runs: apply it and compute the thesis's figures of merit, whole or stage by stage.

The layer above fitting and applying: :mod:`gyrocomp.measures.merit` holds the figures (raw and compensated
recordings in), this module runs the calibration to get the compensated one, on recordings (:func:`evaluate`);
:func:`gyrocomp.files.evaluate_file` does it on a file of any length.
"""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass

import numpy as np

from ..calibration import Calibration
from ..calibration.compensate import apply
from ..errors import DataQualityWarning, InputError
from ..measures.merit import AxisMetrics, Evaluation, TriadResiduals, default_window_s, evaluate_run
from ..fitting.pose_rotation import rotation_errors
from ..fitting.rate_table import MIN_REFERENCE_RATE_DPS, rate_segments
from ..fitting.triad_fit import find_poses, spans_axes
from ..recording import GYRO_AXES, Recording
from ..calibration.triad import TriadCalibration
from ..calibration.installed import installed_calibration, installed_correction_dps, px4_slot
from ..models.field import field_recordings


def evaluate(
    calibration: Calibration,
    recordings: list[Recording] | Recording,
    *,
    window_s: float | None = None,
    turn_on_window_s: float | None = None,
) -> Evaluation:
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
    compensated = [apply(calibration, rec, turn_on_window_s=turn_on_window_s) for rec in recordings]
    runs = [
        evaluate_run(rec, comp, window_s=window_s, accel=bool(calibration.accel_axes))
        for rec, comp in zip(recordings, compensated)
    ]
    return Evaluation(
        runs, [r for rec, comp in zip(recordings, compensated) for r in triad_residuals(calibration, rec, comp)]
    )


def triad_residuals(calibration: Calibration, raw: Recording, compensated: Recording) -> list[TriadResiduals]:
    """The residuals a model's triads decide on one run, raw and compensated (the run ``compensated`` by
    ``calibration``): with an accelerometer triad, |a| - 1 g of each still pose of a multi-position run [g]; with a
    gyro triad, the gravity direction's error after each turn between poses [deg] and, on a rate-table run, the
    rate error of each constant stretch [deg/s] (the raw output less its mean where the table stood still)."""
    out = []
    name = raw.source
    if calibration.gyro_triad is None and calibration.accel_triad is None:
        return out
    if calibration.gyro_triad is not None and raw.reference_rate_dps is not None:
        before, after = rate_segments([raw]), rate_segments([compensated])
        ref = np.array([s.reference_dps for s in before])
        still = np.all(ref == 0, axis=1)
        moving = np.linalg.norm(ref, axis=1) >= MIN_REFERENCE_RATE_DPS
        if np.any(still) and np.any(moving):
            bias = np.mean([s.gyro_dps for s, k in zip(before, still) if k], axis=0)

            def err(segs, b):
                return np.array([np.linalg.norm(s.gyro_dps - b - s.reference_dps) for s, k in zip(segs, moving) if k])

            out.append(TriadResiduals(name, "rate_error_dps", err(before, bias), err(after, 0.0)))
    if raw.accel_g is None or raw.accel_g.shape[1] != 3 or raw.reference_rate_dps is not None:
        return out
    poses = find_poses(raw)
    if len(poses) < 6 or not spans_axes(poses):
        return out
    if calibration.accel_triad is not None and compensated.accel_g is not None:
        norm = lambda a: np.linalg.norm(a) - 1.0  # noqa: E731
        out.append(
            TriadResiduals(
                name,
                "pose_norm_g",
                np.array([norm(p.accel_g) for p in poses]),
                np.array([norm(compensated.accel_g[p.start_index : p.stop_index].mean(axis=0)) for p in poses]),
            )
        )
    if calibration.gyro_triad is not None and raw.gyro_axes == GYRO_AXES:
        try:
            before, after = (
                rotation_errors(r, TriadCalibration.identity(), accel_calibration=calibration.accel_triad)
                for r in (raw, dataclasses.replace(raw, gyro_dps=compensated.gyro_dps))
            )
        except InputError:
            return out
        out.append(
            TriadResiduals(
                name,
                "turn_direction_deg",
                np.array([m.error_after_deg for m in before]),
                np.array([m.error_after_deg for m in after]),
            )
        )
    return out


@dataclass(frozen=True)
class StageEvaluation:
    """One run through the stages of a calibration (the thesis's Table 4.4): ``stages`` maps a stage
    name (raw, temperature only, + acceleration, + hysteresis) to each axis's figures."""

    file: str
    window_s: float
    stages: dict[str, dict[str, AxisMetrics]]

    def to_dict(self) -> dict:
        return {
            "file": self.file,
            "window_s": self.window_s,
            "stages": {name: {a: m.to_dict() for a, m in axes.items()} for name, axes in self.stages.items()},
        }


def stage_calibrations(calibration) -> dict:
    """The stages a calibration has, in the thesis's order, each as a calibration with the later parts off."""
    stages = {}
    later = [
        p
        for p, on in (("acceleration", calibration.has_acceleration), ("hysteresis", calibration.has_hysteresis))
        if on
    ]
    stages["temperature only"] = calibration.without(*later)
    if calibration.has_acceleration:
        stages["temperature + acceleration"] = calibration.without(*[p for p in later if p != "acceleration"])
    if calibration.has_hysteresis:
        name = "temperature + acceleration + hysteresis" if calibration.has_acceleration else "temperature + hysteresis"
        stages[name] = calibration
    return stages


def evaluate_stages(
    calibration: Calibration,
    recording: Recording,
    *,
    window_s: float | None = None,
    turn_on_window_s: float | None = None,
) -> StageEvaluation:
    """Bias offset, improvement, bias instability and integration time of a run at each stage of the calibration."""
    if window_s is None:
        window_s = default_window_s(recording)
    stages: dict[str, dict[str, AxisMetrics]] = {}
    for name, cal in stage_calibrations(calibration).items():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DataQualityWarning)
            result = evaluate_run(
                recording, apply(cal, recording, turn_on_window_s=turn_on_window_s), window_s=window_s
            )
        stages[name] = {axis: m for axis, m in result.axes.items() if axis in calibration.axes}
    return StageEvaluation(recording.source, float(window_s), stages)


@dataclass(frozen=True)
class InstalledComparison:
    """A log's installed autopilot calibration against a gyrocomp model on the same data (its still segments when
    it moves most of the time): per gyro axis, the residual RMS [deg/s] (of the moving average about its mean)
    raw, with the installed calibration as the firmware applies it, and with the model. ``installed`` is None
    when the log's parameters hold no calibration the firmware applies to this sensor (``note`` says why);
    ``corrected_onboard`` when the logged data already went through it (raw is then the installed one, and a model
    on top would correct twice: its figures are then NaN)."""

    file: str
    autopilot: str
    installed: str | None
    corrected_onboard: bool
    still_only: bool
    data_s: float
    window_s: float
    raw_dps: dict[str, float]
    installed_dps: dict[str, float]
    model_dps: dict[str, float]
    note: str = ""


def _installed_slot(recording: Recording, autopilot: str) -> tuple[int | None, str]:
    """The slot the firmware applies to the logged sensor (PX4: the ``TC_G{i}`` whose id is the gyro's device
    id, else the log's instance when it names no device id; ArduPilot: the IMU's ``INS_TCAL{n}``, n from 1),
    or None and why."""
    params = recording.metadata["autopilot_parameters"]
    instance = int(recording.metadata.get("instance") or 0)
    if autopilot == "ardupilot":
        return instance + 1, ""
    device_id = recording.metadata.get("device_id")
    if device_id is None:
        return instance, ""
    slot = px4_slot(params, device_id)
    if slot is None and int(params.get("TC_G_ENABLE", 0)) == 1:
        return None, (
            f"no TC_G*_ID is the gyro's device id {device_id}: PX4 applies no thermal correction to it "
            "(export with device_id= that id)"
        )
    return slot, ""


def compare_installed(
    calibration: Calibration, recording: Recording, *, window_s: float | None = None
) -> InstalledComparison:
    """Judge the thermal calibration installed on the vehicle that wrote ``recording`` (a PX4 ULog's ``TC_G*`` or
    an ArduPilot log's ``INS_TCAL*`` parameters) against ``calibration`` on the same data: the log's still segments
    when it moves most of the time (:func:`gyrocomp.models.field.field_recordings`), else all of it. The installed
    calibration is applied as its firmware applies it (:func:`gyrocomp.calibration.installed.installed_correction_dps`: the
    slot whose id is the sensor's, float32, clamped, PX4's 1 Hz / 1 degC republish, ArduPilot's calibration
    temperature; a parameter the log leaves out has the firmware's default).

    Parameters
    ----------
    calibration : Calibration
        gyrocomp's model of the same sensor.
    recording : Recording
        A log read by :func:`gyrocomp.read` (its ``metadata`` carries the autopilot's parameters).
    window_s : float, optional
        Moving-average window [s] (default as :func:`evaluate`).
    """
    autopilot = recording.metadata.get("autopilot")
    if autopilot not in ("px4", "ardupilot") or "autopilot_parameters" not in recording.metadata:
        raise InputError(
            f"{recording.source}: not a PX4 ULog or ArduPilot DataFlash log; the installed calibration "
            "is read from a log's parameters"
        )
    params = recording.metadata["autopilot_parameters"]
    slot, note = _installed_slot(recording, autopilot)
    installed = (
        None if slot is None else installed_calibration(params, autopilot, slot if autopilot == "px4" else slot - 1)
    )
    onboard = bool(recording.metadata.get("corrected_onboard"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DataQualityWarning)
        runs, contributions = field_recordings([recording], "auto")
    data = runs[0]
    still_only = bool(contributions and contributions[0].still_only)
    window = window_s if window_s is not None else default_window_s(data)
    raw = _residual_rms(data, data, window)
    nothing = {a: float("nan") for a in data.gyro_axes}
    if onboard or installed is None:
        by_installed = raw if onboard else nothing
    else:
        by_installed = _residual_rms(data, _installed_output(data, recording, params, autopilot, slot), window)
    by_model = nothing if onboard else _residual_rms(data, apply(calibration, data), window)
    return InstalledComparison(
        recording.source,
        autopilot,
        None if installed is None else installed.model,
        onboard,
        still_only,
        data.duration_s if not still_only else contributions[0].still_s,
        window,
        raw,
        by_installed,
        by_model,
        note,
    )


def _residual_rms(data: Recording, output: Recording, window_s: float) -> dict[str, float]:
    """Each gyro axis's residual RMS [deg/s] of ``output`` (``data`` compensated), over ``window_s`` [s]."""
    return {a: m.residual_rms_dps for a, m in evaluate_run(data, output, window_s=window_s).axes.items()}


def _installed_output(data: Recording, recording: Recording, params: dict, autopilot: str, slot: int) -> Recording:
    """``data`` (samples of ``recording``) corrected by the installed calibration: the firmware runs over the whole
    log (PX4's republish follows its time), then the same samples are judged."""
    rows = np.searchsorted(recording.time_s, data.time_s)  # the samples kept, in the whole log
    correction = installed_correction_dps(params, autopilot, recording.time_s, recording.temperature_degc, slot)
    cols = [GYRO_AXES.index(a) for a in data.gyro_axes]
    return data.with_gyro(data.gyro_dps - correction[rows][:, cols])


__all__ = [
    "InstalledComparison",
    "StageEvaluation",
    "compare_installed",
    "evaluate",
    "evaluate_stages",
    "stage_calibrations",
    "triad_residuals",
]
