"""``gyrocomp demo``: the main job on built-in simulated data, through the same files and functions a user's data takes.

A simulated Xsens MTi-10 (the ``mti10`` preset: temperature drift, thermal lag, hysteresis on
cooling, g-sensitivity) is cycled cold-hot-cold three times while it is turned through six
orientations (recording paused while it is turned); a compensation is fitted on those runs
(polynomial, thermal lag and hysteresis where the data supports them, and the 3x3 g-sensitivity
matrix, jointly); a fourth run, at other temperatures and twelve other orientations, is compensated
and scored against its exact truth, effect by effect.
"""

from __future__ import annotations

import json
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .calibration import Calibration
from .comparison import AUTOPILOT_METHODS
from .compensate import apply
from .errors import DataQualityWarning, MissingDependencyError
from .io import read_table, write_gyro_back, write_recording, write_text_atomic
from .metrics import Evaluation, evaluate_run, moving_average, smoothed_residual_rms, window_samples
from .models.pipelines import fit_calibration
from .simulate import get_profile, simulate, tumble_positions

PRESET = "mti10"
CALIBRATION_SEEDS = (1, 2, 3)
HELDOUT_SEED = 99
RATE_HZ = 2.0
#: moving-average window of the effect table [s]
EFFECT_WINDOW_S = 100.0


@dataclass(frozen=True)
class EffectSize:
    """Peak-to-peak of one deterministic effect in the held-out run, per axis, moving-averaged [deg/s],
    and what the fitted model does about it."""

    effect: str
    size_dps: dict[str, float]
    compensated: str


@dataclass(frozen=True)
class DemoResult:
    """What the demo did: the model, the held-out evaluation, the effects, and a summary to print."""

    calibration: Calibration
    evaluation: Evaluation
    perfect_residual_rms_dps: dict[str, float]
    effects: list[EffectSize]
    residual_dps: dict[str, float]
    #: deterministic error left in the held-out run (RMS of the moving average) [deg/s] per method and axis:
    #: raw, gyrocomp's model, and the cubics PX4's and ArduPilot's tools fit on the same calibration runs
    deterministic_left_rms_dps: dict[str, dict[str, float]]
    summary: str
    files: list[Path]
    #: why report.html was not written (matplotlib missing), or None when it was
    report_skipped: str | None = None


def run_demo(out_dir: Path, *, rate_hz: float = RATE_HZ, report: bool = True) -> DemoResult:
    """Simulate calibration cycles, fit on them, compensate a held-out tumbling cycle, and score it.

    Writes to ``out_dir``: the calibration runs and the held-out run (CSV), ``model.json``,
    ``heldout_compensated.csv``, ``metrics.json``, ``effects.json``, ``heldout_truth.json`` and, with
    ``report`` and matplotlib installed, ``report.html`` (the model judged on the held-out run).
    """
    out_dir.mkdir(parents=True, exist_ok=True)
    cal_profile = get_profile("combined", set_points_degc=(-25.0, 90.0), ramp_rate_degc_per_min=1.0, dwell_s=900.0)
    cal_paths = []
    for seed in CALIBRATION_SEEDS:
        sim = simulate(PRESET, profile=cal_profile, rate_hz=rate_hz, seed=seed)
        path = out_dir / f"calibration_run_{seed}.csv"
        write_recording(sim.recording, path)
        cal_paths.append(path)
    # other temperatures, other orientations (+-0.5 g on each axis), 20 minutes at each
    held = simulate(PRESET, profile=get_profile("combined", set_points_degc=(-10.0, 70.0), position_s=1200.0,
                                                positions_g=tumble_positions((0.5, -0.5))),
                    rate_hz=rate_hz, seed=HELDOUT_SEED)
    held_path = out_dir / "heldout_run.csv"
    write_recording(held.recording, held_path)
    write_text_atomic(out_dir / "heldout_truth.json", json.dumps(held.truth.to_dict(), indent=2) + "\n")

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DataQualityWarning)  # the pauses while turning the unit are the profile's
        cal_runs = [read_table(p).recording for p in cal_paths]
        calibration = fit_calibration(cal_runs)
        autopilots = {name: fit(cal_runs) for name, fit in AUTOPILOT_METHODS.items()}
    calibration.save(out_dir / "model.json")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DataQualityWarning)  # the pauses are the profile's; said in the summary
        held_data = read_table(held_path)
        compensated = apply(calibration, held_data.recording)
        run_eval = evaluate_run(held_data.recording, compensated)
        by_method = {f"gyrocomp: {calibration.model}": compensated}
        by_method.update({name: apply(cal, held_data.recording) for name, cal in autopilots.items()})
    write_gyro_back(held_data, compensated.gyro_dps, out_dir / "heldout_compensated.csv")
    evaluation = Evaluation([run_eval])
    write_text_atomic(out_dir / "metrics.json", json.dumps(evaluation.to_dict(), indent=2) + "\n")

    axes = held.recording.gyro_axes
    w_eff = window_samples(EFFECT_WINDOW_S, rate_hz, held.recording.n_samples)
    truth = held.truth
    modelled = calibration.axes.values()
    status = {
        "temperature": "compensated" + (" (with fitted thermal lag on " + ", ".join(
            a for a, ax in calibration.axes.items() if ax.lag_time_constant_s > 0) + ")"
            if any(ax.lag_time_constant_s > 0 for ax in modelled) else ""),
        "hysteresis": "compensated on " + ", ".join(a for a, ax in calibration.axes.items() if ax.hysteresis)
        if any(ax.hysteresis for ax in modelled) else "not modelled: the data chose no hysteresis",
        "acceleration": "compensated: 3x3 G fitted jointly" if calibration.has_acceleration
        else "not modelled",
    }
    effects = [
        EffectSize(name, {a: float(np.ptp(moving_average(truth.components_dps[key][:, j], w_eff)))
                          for j, a in enumerate(axes)}, compensated=status[key])
        for name, key in (("temperature (with thermal lag)", "temperature"), ("hysteresis", "hysteresis"),
                          ("g-sensitivity", "acceleration"))
    ]
    # what each compensation left: output minus what it should be (true rate + noise) [deg/s]
    lefts = {name: rec.gyro_dps - truth.true_rate_dps - truth.noise.total_dps
             for name, rec in {"raw (no compensation)": held.recording, **by_method}.items()}
    left = lefts[f"gyrocomp: {calibration.model}"]
    residual = {a: float(np.ptp(moving_average(left[:, j] - left[:, j].mean(), w_eff))) for j, a in enumerate(axes)}

    w = window_samples(run_eval.window_s, rate_hz, held.recording.n_samples)
    perfect = {axis: smoothed_residual_rms(truth.noise.total_dps[:, j], w) for j, axis in enumerate(axes)}
    methods_rms = {name: {axis: smoothed_residual_rms(d[:, j], w_eff) for j, axis in enumerate(axes)}
                   for name, d in lefts.items()}
    write_text_atomic(out_dir / "effects.json", json.dumps(
        {"window_s": EFFECT_WINDOW_S, "effects_peak_to_peak_dps": {e.effect: e.size_dps for e in effects},
         "residual_peak_to_peak_dps": residual,
         "deterministic_error_left_rms_dps_by_method": methods_rms}, indent=2) + "\n")
    hours = held.recording.duration_s / 3600
    lines = [
        f"Simulated {len(cal_paths)} cold-hot-cold calibration cycles (-25 -> 90 -> -25 degC at 1 degC/min, "
        f"{rate_hz:g} Hz) of the '{PRESET}' preset (Xsens MTi-10 raw output: temperature drift, 120 s thermal lag, "
        "hysteresis on cooling, g-sensitivity), the unit turned to +-1 g on each axis every 5 minutes, each run "
        "with its own turn-on bias;",
        f"fitted {calibration.model} (polynomial order, thermal lag and hysteresis chosen by leave-one-run-out "
        "error; G jointly on the static segments).",
        f"Held out: a {hours:.1f} h cycle over -10..70 degC with the unit at 12 other orientations "
        f"(20 min each, {len(held.recording.gaps)} one-minute pauses while turning; Allan sums pooled over the stretches).",
        f"Deterministic effects in the held-out run (peak-to-peak of a {EFFECT_WINDOW_S:g} s moving average) [deg/s]:",
    ]
    for e in effects:
        lines.append(f"  {e.effect:32s} " + "  ".join(f"{a} {v:.2g}" for a, v in e.size_dps.items())
                     + f"   ({e.compensated})")
    lines.append(f"  {'left after compensation':32s} " + "  ".join(f"{a} {v:.2g}" for a, v in residual.items()))
    lines.append("Residual drift of the held-out run (RMS of the moving average) against what perfect "
                 "compensation leaves:")
    for axis, m in run_eval.axes.items():
        lines.append(f"  {axis}: {m.residual_rms_dps:.3g} deg/s compensated, {perfect[axis]:.3g} deg/s noise alone "
                     f"(ratio {m.residual_rms_dps / perfect[axis]:.2f}); raw bias offset {m.bias_offset_raw_dps:.3g} "
                     f"-> {m.bias_offset_comp_dps:.3g} deg/s")
    lines.append("Against the cubics the autopilots' own tools fit on the same three runs: the deterministic error each "
                 f"leaves in the held-out run (output - true rate - noise; RMS of a {EFFECT_WINDOW_S:g} s moving "
                 "average) [deg/s]:")
    for name, rms in methods_rms.items():
        lines.append(f"  {name:60.60s} " + "  ".join(f"{a} {v:.2g}" for a, v in rms.items()))
    skipped = _write_report(calibration, held_data.recording, out_dir / "report.html") if report else "not asked for"
    if skipped is None:
        lines.append(f"Report of the model on the held-out run: {out_dir / 'report.html'} (open it in a browser).")
    files = sorted(out_dir.iterdir())
    return DemoResult(calibration, evaluation, perfect, effects, residual, methods_rms, "\n".join(lines), files,
                      skipped)


def _write_report(calibration: Calibration, run, path: Path) -> str | None:
    """Write the HTML report; return why not (the missing [plot] extra), or None."""
    try:
        from .report.html import build_report

        html = build_report(calibration, [run]).html
    except MissingDependencyError as exc:
        return str(exc)
    write_text_atomic(path, html)
    return None


__all__ = ["DemoResult", "EffectSize", "run_demo"]
