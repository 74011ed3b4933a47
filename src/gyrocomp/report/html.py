"""One self-contained HTML test report: a model and the runs it was judged on.

Images are PNGs embedded as data URIs and the style sheet is inline, so the file opens anywhere with
no network access. Sections (each an ``<section id=...>``): ``summary`` (the model: type, order, inputs,
valid ranges, validation scores, the candidates compared), ``planning`` when a plan is given (the drift to expect
on a use profile and the next run, as ``gyrocomp plan`` gives them), ``validation`` when a
:class:`~gyrocomp.evaluation.validation.ValidationResult` is given (held-out drift of raw, the autopilots' cubics, a
plain cubic and gyrocomp's default, as ``gyrocomp validate`` prints it), ``evaluation`` (the thesis's figures of merit,
by stage when the model has stages), one ``axis-<name>`` per axis (bias against temperature with the
heating and cooling branches, fitted curve, turning points and residual; raw and compensated output
against time), ``allan`` (raw and compensated Allan deviation per run), ``g-sensitivity`` when the
model has a g-sensitivity matrix, ``firmware`` when it has a gyro temperature curve (the PX4 and ArduPilot files
exported from it as each firmware applies them: their correction against the model's and the bias offset they
leave on each run), and ``scale-factor`` when it has a gyro or accelerometer triad (K with standard
errors, scale-factor error against temperature, and the residual of each still pose (|a| - 1 g) and each turn
between poses (the gravity direction the gyro predicts) before and after), and ``stillness`` for runs that move
most of the time (field logs): their still segments drawn over the rate and temperature, and listed.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable

import numpy as np

from ..calibration import Calibration
from ..calibration.compensate import apply
from ..errors import DataQualityWarning, InputError, TemperatureRangeWarning
from ..evaluation import evaluate_stages, stage_calibrations, triad_residuals
from ..export.firmware import BEYOND_DEGC, firmware_corrected_axes, firmware_costs
from ..io import TIME_RANGE_KEY
from ..measures.merit import bias_offset, evaluate_run, window_samples
from ..measures.noise import analyse_noise
from ..measures.noise_model import noise_model
from ..recording import ACCEL_AXES, Recording
from ..rounding import with_error
from ..fitting.gsensitivity import EXCITATION_G
from ..motion.positions import static_segments
from ..motion.stillness import detect_still
from ..models.field import moves_most_of_the_time
from ..evaluation.run_advice import WORTHWHILE_GAIN, CalibrationPlan
from ..evaluation.validation import ValidationResult
from . import figures
from .page import Report, cell_text, escape_text, figure_html, html_page, table_html

SECTIONS = ("summary", "evaluation", "allan")


def _describe(ax) -> str:
    if ax.temperature is None:
        return "constant"
    text = ax.temperature.describe()
    if ax.lag_time_constant_s > 0:
        text += f", thermal lag {ax.lag_time_constant_s:.3g} s"
    if ax.hysteresis is not None:
        text += f", {ax.hysteresis.describe()}"
    if ax.rate_term is not None:
        text += f", {ax.rate_term.describe(ax.unit)}"
    if ax.has_acceleration_stage:
        text += ", g-sensitivity"
    return text


def _expected(drift: float, standard_error: float | None, unit: str) -> str:
    return f"{with_error(drift, standard_error)} {unit}"


def _summary(calibration: Calibration) -> str:
    report = calibration.report
    parts = [
        f"<p>Model <b>{escape_text(calibration.model)}</b> (schema {calibration.schema_version}). "
        f"Units: rate deg/s, acceleration g, temperature degC, time s.</p>",
        _axis_table(calibration),
    ]
    if calibration.accel_axes:
        parts.append(
            f"<p class=note>Accelerometer corrections are relative to {calibration.accel_reference_degc:.2f} "
            "degC (its constant cannot be told from gravity at rest).</p>"
        )
    parts += _expected_drift(report.expected_drift())
    selection = report.order_selection
    if selection is not None:
        orders = selection.orders
        parts.append(
            table_html(
                ["axis"] + [f"order {p}" for p in orders],
                [[a] + [s.get(p) for p in orders] for a, s in selection.scores.items()],
                f"polynomial order by {selection.method} (lower is better)",
            )
        )
    hyst = report.hysteresis
    scored = {a: c for a, c in hyst.axes.items() if c.scores} if hyst is not None else {}
    if scored:
        names = hyst.memories_scored
        parts.append(
            table_html(
                ["axis"] + list(names) + ["chosen"],
                [[a] + [c.scores.get(m) for m in names] + [c.label] for a, c in scored.items()],
                f"hysteresis / thermal lag candidates by {hyst.selection} (lower is better)",
            )
        )
    prov = calibration.provenance
    if prov:
        files = ", ".join(str(f.get("file", f)) if isinstance(f, dict) else str(f) for f in prov.get("inputs", []))
        parts.append(
            f"<p class=note>Fitted {escape_text(str(prov.get('created_utc', '')))} by gyrocomp "
            f"{escape_text(str(prov.get('gyrocomp_version', '')))} on {escape_text(files)}.</p>"
        )
    return "\n".join(parts)


def _axis_table(calibration: Calibration) -> str:
    """The table of the model's axes: model, inputs, valid range [degC], fit RMS, run constants."""
    report = calibration.report
    rows = []
    for group, axes, unit in (("gyro", calibration.axes, "deg/s"), ("accelerometer", calibration.accel_axes, "g")):
        fits = (report.accel.axes if report.accel is not None else {}) if group == "accelerometer" else report.axes
        for name, ax in axes.items():
            inputs = ", ".join(ax.temperature.inputs) if ax.temperature else "-"
            t = ax.temperature
            rng = "-" if t is None else f"{t.t_min_degc:.2f} .. {t.t_max_degc:.2f}"
            rms = fits[name].fit_rms if name in fits else None
            rms_text = "-" if rms is None else f"{rms:.3g} {unit}"
            rows.append([name, _describe(ax), inputs, rng, rms_text, len(ax.turn_on_biases)])
    header = ["axis", "model", "inputs", "valid range [degC]", "fit RMS", "run constants"]
    if all(row[4] == "-" for row in rows):  # no fit recorded one: no empty column
        header, rows = header[:4] + header[5:], [row[:4] + row[5:] for row in rows]
    return table_html(header, rows)


def _expected_drift(expected: dict) -> list[str]:
    """The table of the held-out drift to expect per axis, and a note when the folds are few."""
    if not expected:
        return []
    first = next(iter(expected.values()))
    rows = [
        [
            e.axis,
            e.model,
            _expected(e.drift, e.standard_error, e.unit),
            "-" if e.constant_drift is None else f"{e.constant_drift:.3g} {e.unit}",
        ]
        for e in expected.values()
    ]
    parts = [
        table_html(
            ["axis", "model", "expected held-out drift", "run constant alone"],
            rows,
            f"drift to expect on unseen data: mean +- standard error over {first.folds} held-out "
            f"{first.fold_kind} ({first.window_s:g} s moving average)",
        )
    ]
    if first.thin:
        parts.append(
            f"<p class=note>Only {first.folds} folds: thin evidence; more runs, or runs that heat and "
            "cool more than once, make these figures firmer.</p>"
        )
    if first.ramp_note:
        parts.append(f"<p class=note>Ramp rates: {escape_text(first.ramp_note)}.</p>")
    return parts


def _planning(result: CalibrationPlan) -> str:
    """The planning section: the drift to expect on the use profile per axis, then each candidate run (the
    numbers of ``gyrocomp plan --json``, at four significant figures)."""
    now = result.now
    rows = [
        [
            f.axis,
            f.drift_dps,
            f.low_dps,
            f.high_dps,
            f.coefficients_dps,
            f.noise_dps,
            f.extrapolation_dps,
            f.model_choice_dps,
            f.lag_s,
            f.lag_standard_error_s,
        ]
        for f in now.axes.values()
    ]
    header = [
        "axis",
        "expected [deg/s]",
        "95 % low [deg/s]",
        "95 % high [deg/s]",
        "coefficients [deg/s]",
        "own noise [deg/s]",
        "past the range [deg/s]",
        "model choice [deg/s]",
        "lag [s]",
        "lag s.e. [s]",
    ]
    caption = f"drift to expect on {now.profile} ({now.window_s:g} s moving average)"
    worst = now.worst.axis
    runs = [
        [a.run.name, a.run.description, a.run.hours, a.after.axes[worst].drift_dps, a.gain_dps_per_h, a.resolves]
        for a in result.advice
    ]
    runs_header = ["run", "what", "hours [h]", f"{worst} after [deg/s]", "gain per hour [deg/s/h]", "what it resolves"]
    lo, hi = result.range_degc
    body = [
        table_html(header, rows, caption),
        table_html(
            runs_header,
            runs,
            f"the next run (calibrated {lo:.1f}..{hi:.1f} degC at {result.ramp_degc_per_min:.2g} degC/min), the best "
            "gain per hour of chamber time first",
        ),
    ]
    if result.sequence:
        order = ", then ".join(f"{a.run.name} ({a.run.hours:.1f} h)" for a in result.sequence)
        body.append(
            f"<p>Runs to record in turn: {escape_text(order)}; the worst axis "
            f"{cell_text(now.worst.drift_dps)} -> {cell_text(result.sequence[-1].after.worst.drift_dps)} deg/s.</p>"
        )
    elif result.enough:
        body.append(f"<p>No candidate run lowers the worst axis's expected drift by {WORTHWHILE_GAIN:.0%} or more.</p>")
    return "\n".join(body)


def _validation(result: ValidationResult) -> str:
    """The held-out drift table: mean +- standard error per method and axis [deg/s], and against the cubic."""
    header, rows = result.table_rows()
    caption = f"{result.title}: each method fitted without the fold it is scored on"
    folds = f"<p class=note>folds: {escape_text(', '.join(result.folds))}</p>"
    return table_html(header, rows, caption) + folds


_STAGE_HEADERS = [
    "run",
    "axis",
    "window [s]",
    "stage",
    "bias offset [deg/s]",
    "improvement (raw/stage)",
    "bias instability [deg/h]",
    "integration time [s]",
]
_EVALUATION_HEADERS = [
    "run",
    "axis",
    "window [s]",
    "offset raw [deg/s]",
    "offset comp [deg/s]",
    "improvement",
    "BI raw [deg/h]",
    "BI comp [deg/h]",
    "int. time raw [s]",
    "int. time comp [s]",
]
_ACCEL_HEADERS = ["run", "axis", "offset raw [g]", "offset comp [g]", "improvement", "BI raw [ug]", "BI comp [ug]"]


def _evaluation(
    calibration: Calibration, runs: list[Recording], evaluations: list, turn_on_window_s: float | None
) -> str:
    """The evaluation table: ``evaluations`` (:func:`evaluate_run` of each run), or the stages of a staged model
    over the same windows."""
    staged = len(stage_calibrations(calibration)) > 1
    rows, accel_rows = [], []
    for rec, ev in zip(runs, evaluations):
        name = rec.source.rsplit("/", 1)[-1]  # a table cell: escaped once, by table_html
        if staged:
            rows += _stage_rows(calibration, rec, name, ev.window_s, turn_on_window_s)
        else:
            rows += _evaluation_rows(ev, name)
        for axis, m in ev.accel_axes.items():
            improvement = f"{m.offset_improvement:.3g}x"
            accel_rows.append([name, axis, m.bias_offset_raw_g, m.bias_offset_comp_g, improvement])
            accel_rows[-1] += [m.bias_instability_raw_ug, m.bias_instability_comp_ug]
    if staged:
        parts = [table_html(_STAGE_HEADERS, rows, "stages of the compensation (the thesis's Table 4.4)")]
    else:
        parts = [table_html(_EVALUATION_HEADERS, rows)]
    if accel_rows:
        parts.append(table_html(_ACCEL_HEADERS, accel_rows, "accelerometer"))
    parts.append(
        "<p class=note>Bias offset: peak-to-peak of the moving average (window: tau at the raw Allan "
        "minimum, at least 1 s); bias instability: Allan minimum / 0.664 (IEEE Std 952).</p>"
    )
    shares = [  # a list: two runs of one name in other folders are two runs
        (
            rec.source.rsplit("/", 1)[-1],
            calibration.fitted_share(rec.metadata.get("path"), rec.metadata.get(TIME_RANGE_KEY)),
        )
        for rec in runs
    ]
    fitted_on = [name for name, share in shares if share == "all"]
    partly = [name for name, share in shares if share == "part"]
    if fitted_on:
        parts.append(
            f"<p class=note><b>In-sample</b>: the model was fitted on these rows of {escape_text(', '.join(fitted_on))}; "
            "its figures there are not the drift to expect on new data (the held-out drift in the model "
            "section is).</p>"
        )
    if partly:
        parts.append(
            f"<p class=note><b>Partly in-sample</b>: the model was fitted on part of the rows judged of "
            f"{escape_text(', '.join(partly))} (the window its fit read overlaps this one).</p>"
        )
    return "\n".join(parts)


def _evaluation_rows(ev, name: str) -> list:
    """One row per gyro axis of a run's evaluation: window [s], bias offsets [deg/s], improvement, bias
    instabilities [deg/h], integration times [s]."""
    rows = []
    for axis, m in ev.axes.items():
        row = [name, axis, f"{ev.window_s:.3g}", m.bias_offset_raw_dps, m.bias_offset_comp_dps]
        row += [f"{m.offset_improvement:.3g}x", m.bias_instability_raw_dph, m.bias_instability_comp_dph]
        rows.append(row + [m.integration_time_raw_s, m.integration_time_comp_s])
    return rows


def _stage_rows(calibration: Calibration, rec: Recording, name: str, window_s: float, turn_on_window_s) -> list:
    """Per gyro axis of a run, its raw figures then each stage's (:func:`evaluate_stages`) over ``window_s`` [s]."""
    st = evaluate_stages(calibration, rec, window_s=window_s, turn_on_window_s=turn_on_window_s)
    first = next(iter(st.stages.values()))
    rows = []
    for axis in first:
        m0 = first[axis]
        rows.append([name, axis, f"{window_s:.3g}", "raw", m0.bias_offset_raw_dps, "1x"])
        rows[-1] += [m0.bias_instability_raw_dph, m0.integration_time_raw_s]
        for stage, axes in st.stages.items():
            m = axes[axis]
            rows.append(["", "", "", stage, m.bias_offset_comp_dps, f"{m.offset_improvement:.3g}x"])
            rows[-1] += [m.bias_instability_comp_dph, m.integration_time_comp_s]
    return rows


def _g_positions(calibration: Calibration, runs: list[Recording], min_static_s: float):
    """Per gyro axis: gravity of every static position and its offset with temperature and run constants out."""
    no_g = calibration.without("acceleration")
    gravity, offsets = [], []
    for rec in runs:
        if rec.accel_g is None or not set(ACCEL_AXES) <= set(rec.accel_axes):
            continue
        segments = static_segments(rec, min_duration_s=min_static_s)
        if len(segments) < 2:
            continue
        out = apply(no_g, rec)
        accel = out.accel_g[:, [rec.accel_axes.index(a) for a in ACCEL_AXES]]
        g = np.array([accel[s.start : s.stop].mean(axis=0) for s in segments])
        y = np.array([out.gyro_dps[s.start : s.stop].mean(axis=0) for s in segments])
        gravity.append(g)
        offsets.append(y)
    result = {}
    for j, axis in enumerate(runs[0].gyro_axes):
        row = calibration.axes.get(axis)
        if row is None or row.g_sensitivity_dps_per_g is None or not gravity:
            continue
        G = np.asarray(row.g_sensitivity_dps_per_g)
        ys = [y[:, j] - np.mean(y[:, j] - g @ G) for g, y in zip(gravity, offsets)]  # each run's constant out
        result[axis] = (np.vstack(gravity), np.concatenate(ys))
    return result


#: how the report labels each scale-factor residual, and the factor to its unit
_RESIDUAL_LABELS = {
    "pose_norm_g": ("accelerometer |a| - 1 g [mg]", 1e3),
    "turn_direction_deg": ("gyro: gravity direction after each turn [deg]", 1.0),
    "rate_error_dps": ("gyro: rate error on each rate-table stretch [deg/s]", 1.0),
}


def _pose_residuals(calibration: Calibration, runs: list[Recording], compensated: list[Recording]) -> dict:
    """Label -> (raw, compensated) of every still pose, turn and rate-table stretch of the runs
    (:func:`gyrocomp.evaluation.triad_residuals`), the runs one after the other."""
    merged: dict[str, tuple[list, list]] = {}
    for rec, comp in zip(runs, compensated):
        for r in triad_residuals(calibration, rec, comp):
            label, factor = _RESIDUAL_LABELS[r.figure]
            merged.setdefault(label, ([], []))
            merged[label][0].extend(r.raw * factor)
            merged[label][1].extend(r.compensated * factor)
    return {label: (np.array(a), np.array(b)) for label, (a, b) in merged.items()}


def _triads(calibration: Calibration, runs: list[Recording], compensated: list[Recording]) -> str:
    """The scale-factor section: each triad's K with standard errors, its scale-factor error against
    temperature and the residual per pose or turn."""
    triads = {
        name: t
        for name, t in (("gyro", calibration.gyro_triad), ("accelerometer", calibration.accel_triad))
        if t is not None
    }
    rows = []
    for name, triad in triads.items():
        for i, axis in enumerate("xyz"):
            rows.append(
                [f"{name} {axis}", triad.method]
                + [with_error(k, e, sign=True) for k, e in zip(triad.sensitivity[i], triad.sensitivity_stderr[i])]
                + [f"{triad.scale_factor_error[i] * 1e6:+.0f}", f"{triad.bias[i]:+.5g} {triad.unit}"]
            )
    temps = [rec.temperature_degc for rec in runs if rec.temperature_degc is not None]
    span = (float(min(np.min(t) for t in temps)), float(max(np.max(t) for t in temps))) if temps else None
    body = [
        table_html(
            ["triad", "method", "K column x", "K column y", "K column z", "scale error [ppm]", "bias"],
            rows,
            "raw = K(T) v + bias, corrected v = K(T)^-1 (raw - bias); K at the reference temperature +- standard error",
        ),
        figure_html(
            figures.triad_plot(triads, span, _pose_residuals(calibration, runs, compensated)),
            "scale-factor error against temperature, residual per pose",
        ),
    ]
    return "\n".join(body)


def _axis_sections(
    calibration: Calibration, runs: list[Recording], compensated: list[Recording], windows: list[float]
) -> dict:
    """One section per modelled axis: bias against temperature, raw and compensated output of each run."""
    modelled = [a for a in runs[0].gyro_axes if a in calibration.axes]
    modelled += [a for a in calibration.accel_axes if runs[0].accel_g is not None]
    sections = {}
    for axis in modelled:
        unit = "g" if axis.startswith("accel") else "deg/s"
        body = []
        if runs[0].temperature_degc is not None:
            body.append(
                figure_html(
                    figures.temperature_plot(runs, compensated, axis, unit), f"{axis}: bias against temperature"
                )
            )
        for rec, comp, w in zip(runs, compensated, windows):
            body.append(
                figure_html(
                    figures.timeseries_plot(rec, comp, axis, w, unit, title=f"{axis}: {rec.source.rsplit('/', 1)[-1]}"),
                    f"{axis}: raw and compensated output",
                )
            )
        sections[f"axis-{axis}"] = (f"Axis {axis}", "\n".join(body))
    return sections


def _g_sensitivity(calibration: Calibration, runs: list[Recording], min_static_s: float) -> str:
    """The g-sensitivity section: G with standard errors, and the static positions against it."""
    positions = _g_positions(calibration, runs, min_static_s)
    fitted = calibration.report.acceleration
    acc = fitted.axes if fitted is not None else {}
    rows, g_matrix = [], {}
    for axis, ax in calibration.axes.items():
        if ax.g_sensitivity_dps_per_g is None:
            continue
        errors = acc[axis].standard_error_dps_per_g if axis in acc else (None, None, None)
        g_matrix[axis] = (ax.g_sensitivity_dps_per_g, errors)
        rows.append([axis] + [with_error(g, e, sign=True) for g, e in zip(ax.g_sensitivity_dps_per_g, errors)])
    body = [
        table_html(
            ["gyro axis", "accel_x", "accel_y", "accel_z"], rows, "g-sensitivity matrix G [deg/s/g] +- standard error"
        )
    ]
    spread = max((float(np.max(np.std(g, axis=0))) for g, _ in positions.values()), default=0.0)
    if positions and spread > EXCITATION_G:
        body.append(figure_html(figures.g_sensitivity_plot(positions, g_matrix), "g-sensitivity"))
    elif positions:
        body.append(
            f"<p class=note>The runs judged here hold their static positions at one attitude (gravity spread under "
            f"{EXCITATION_G:g} g along every axis): no slope of the bias against gravity to draw. G was fitted on "
            "the calibration runs' positions.</p>"
        )
    else:
        body.append("<p class=note>These runs have no static positions to draw.</p>")
    return "\n".join(body)


def build_report(
    calibration: Calibration,
    runs: list[Recording],
    *,
    window_s: float | None = None,
    turn_on_window_s: float | None = None,
    min_static_s: float = 10.0,
    progress: Callable[[float], None] | None = None,
    validation: ValidationResult | None = None,
    lead: dict[str, tuple[str, str]] | None = None,
    plan: CalibrationPlan | None = None,
) -> Report:
    """The report of ``calibration`` judged on ``runs`` (see the module doc for what it holds).

    Parameters
    ----------
    window_s, turn_on_window_s : float, optional
        Moving-average window [s] (default: tau at each raw run's Allan minimum, at least 1 s); estimate each run's
        turn-on constant from its first seconds [s].
    min_static_s : float
        Shortest static position drawn in the g-sensitivity figure [s].
    progress : callable, optional
        Called with the fraction done.
    validation, lead : ValidationResult, dict, optional
        Held-out drift of the methods on the calibration runs (:func:`gyrocomp.evaluation.validation.validate`);
        sections to open the page with, id -> (title, HTML body) (the demo's case where compensation matters).
    plan : CalibrationPlan, optional
        The drift to expect and the next run (:func:`gyrocomp.evaluation.run_advice.plan`): a ``planning``
        section.
    """
    figures._pyplot()  # fail early, in one line, without matplotlib
    steps = 3 + 2 * len(runs)
    done = [0]

    def tick() -> None:
        done[0] += 1
        if progress:
            progress(min(done[0] / steps, 1.0))

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TemperatureRangeWarning)
        warnings.simplefilter("ignore", DataQualityWarning)
        compensated = [apply(calibration, rec, turn_on_window_s=turn_on_window_s) for rec in runs]
        tick()
        sections: dict[str, tuple[str, str]] = dict(lead or {})
        sections["summary"] = ("Model", _summary(calibration))
        if validation is not None:
            sections["validation"] = ("Validation", _validation(validation))
        if plan is not None:
            sections["planning"] = ("How much chamber time", _planning(plan))
        # the Allan curves drawn below, raw and compensated: their minima are the bias instabilities (once)
        noise = [_noise(rec, comp) for rec, comp in zip(runs, compensated)]
        evaluations = _evaluations(calibration, runs, compensated, noise, window_s)
        sections["evaluation"] = ("Evaluation", _evaluation(calibration, runs, evaluations, turn_on_window_s))
        tick()
        sections.update(_axis_sections(calibration, runs, compensated, [ev.window_s for ev in evaluations]))
        costs = firmware_costs(calibration)
        if costs:
            sections["firmware"] = ("On the autopilot", _firmware(calibration, runs, evaluations, costs))
        tick()
        sections["allan"] = ("Allan deviation", _allan(runs, noise, tick))
        sections.update(_closing_sections(calibration, runs, compensated, min_static_s))
        tick()
    return Report(_page(calibration, runs, sections), tuple(sections))


def _evaluations(calibration: Calibration, runs: list, compensated: list, noise: list, window_s) -> list:
    """:func:`evaluate_run` of each run, its bias instabilities from the Allan curves already drawn."""
    return [
        evaluate_run(
            rec,
            comp,
            window_s=window_s,
            accel=bool(calibration.accel_axes),
            allan=tuple({a: n.axes[a].allan for a in rec.gyro_axes} for n in pair),
        )
        for rec, comp, pair in zip(runs, compensated, noise)
    ]


def _closing_sections(calibration: Calibration, runs: list, compensated: list, min_static_s: float) -> dict:
    """The sections that only some models or runs have: g-sensitivity, scale factor, still moments."""
    sections = {}
    if calibration.has_acceleration:
        sections["g-sensitivity"] = ("g-sensitivity", _g_sensitivity(calibration, runs, min_static_s))
    if calibration.gyro_triad is not None or calibration.accel_triad is not None:
        sections["scale-factor"] = ("Scale factor and misalignment", _triads(calibration, runs, compensated))
    moving = [(rec, found) for rec in runs for found in [detect_still(rec)] if moves_most_of_the_time(found)]
    if moving:
        sections["stillness"] = ("Still moments of the field logs", _stillness(moving))
    return sections


#: the columns of the firmware table: the differences of :class:`gyrocomp.export.firmware.FirmwareDifference`
_FIRMWARE_FIELDS = (
    "in_range_max_dps",
    "in_range_rms_dps",
    "beyond_max_dps",
    "beyond_rms_dps",
    "as_run_max_dps",
    "as_run_rms_dps",
)


def _firmware(calibration: Calibration, runs: list[Recording], evaluations: list, costs: dict) -> str:
    """What the PX4 and ArduPilot files exported from the model do, as each firmware computes them
    (:mod:`gyrocomp.export.firmware`): their correction against the model's, and the bias offset each leaves on
    the runs."""
    rows = [
        [target, axis, *(getattr(d, field)[j] for field in _FIRMWARE_FIELDS)]
        for target, d in costs.items()
        for j, axis in enumerate(d.axes)
    ]
    parts = [
        table_html(
            [
                "firmware",
                "axis",
                "in range, largest",
                "in range, RMS",
                f"{BEYOND_DEGC:g} degC beyond, largest",
                f"{BEYOND_DEGC:g} degC beyond, RMS",
                "heat-cool cycle as run, largest",
                "heat-cool cycle as run, RMS",
            ],
            rows,
            "the firmware's correction against the model's [deg/s] (about its mean): the firmware clamps at "
            "the calibrated range, carries a cubic without lag or hysteresis, and PX4 republishes at 1 Hz "
            "when the temperature moved by more than 1 degC",
        )
    ]
    run_rows = _firmware_run_rows(calibration, runs, evaluations, costs)
    if run_rows:
        parts.append(
            table_html(
                ["run", "axis", "raw", "model", "PX4 file (as run)", "ArduPilot file"],
                run_rows,
                "bias offset on each run [deg/s]: the model as gyrocomp applies it, and the exported "
                "files as each firmware applies them",
            )
        )
    return "\n".join(parts)


def _firmware_run_rows(calibration: Calibration, runs: list[Recording], evaluations: list, costs: dict) -> list:
    """Per run with a temperature and axis: the bias offset [deg/s] raw, after the model and after each firmware."""
    run_rows = []
    for rec, ev in zip(runs, evaluations):
        if rec.temperature_degc is None:
            continue
        # the bias offset of each firmware's output, over the evaluation's window (the other figures are not
        # shown here: their Allan minima would cost a report on a long run some seconds per firmware)
        w = window_samples(ev.window_s, rec.rate_hz, rec.n_samples)
        on_vehicle = {
            target: {axis: bias_offset(output, w) for axis, output in firmware_corrected_axes(calibration, rec, target)}
            for target in costs
        }
        name = rec.source.rsplit("/", 1)[-1]
        for axis, m in ev.axes.items():
            if all(axis in offsets for offsets in on_vehicle.values()):
                offsets = (on_vehicle[t][axis] for t in costs)
                run_rows.append([name, axis, m.bias_offset_raw_dps, m.bias_offset_comp_dps, *offsets])
    return run_rows


def _noise(rec: Recording, comp: Recording) -> tuple:
    """The noise analyses of a run's gyro axes, raw and compensated (pooled over time gaps). The report finds the
    moving runs itself (the stillness section), and the raw run's plausibility was checked by apply: neither is
    judged again per curve."""
    names, split = list(rec.gyro_axes), bool(rec.gaps)
    return tuple(
        analyse_noise(r, names, split_gaps=split, motion_check=False, plausibility_check=False) for r in (rec, comp)
    )


def _allan(runs: list[Recording], noise: list[tuple], tick: Callable[[], None]) -> str:
    """Raw and compensated Allan deviations of each run, one figure per run, and the compensated gyro's noise model
    for an estimator (:mod:`gyrocomp.measures.noise_model`) beside its IEEE 952 fit."""
    parts = []
    for rec, (raw, compensated) in zip(runs, noise):
        analyses = {"raw": raw, "compensated": compensated}
        parts.append(
            figure_html(
                figures.allan_plot(analyses, title=f"Allan deviation: {rec.source.rsplit('/', 1)[-1]}"),
                "Allan deviation, raw and compensated",
            )
        )
        parts.append(_noise_model_table(compensated))
        tick()
    return "\n".join(parts)


def _noise_model_table(compensated) -> str:
    """The compensated gyro's noise model for an estimator: the bound (white noise N, random walk K, at or above the
    curve's 95 % interval up to a tenth of the run) beside the IEEE 952 fit, per axis [deg/s/sqrt(Hz),
    deg/s/sqrt(s)]."""
    try:
        model = noise_model(compensated)
    except InputError as exc:  # too short a run for two averaging times
        return f"<p class=note>No noise model: {escape_text(str(exc))}</p>"
    rows = [
        [
            name,
            a.ieee.white_noise_density,
            a.ieee.random_walk,
            a.bound.white_noise_density,
            a.bound.random_walk,
            f"{a.bound.ratio_median:.2f} / {a.bound.ratio_max:.2f}",
        ]
        for name, a in model.axes.items()
    ]
    return table_html(
        ["axis", "IEEE 952 N", "IEEE 952 K", "bound N", "bound K", "bound / curve: median / largest"],
        rows,
        caption="noise model of the compensated gyro for an estimator (gyrocomp noise): N "
        "[deg/s/sqrt(Hz)] and K [deg/s/sqrt(s)] at or above the upper end of the curve's 95 % "
        "interval at every averaging time up to a tenth of the run",
    )


def _stillness(moving: list) -> str:
    """For each run that moves most of the time: its still segments drawn over its rate and temperature, and
    listed (where, how long, temperature, mean rate = the bias there)."""
    parts = []
    for rec, found in moving:
        parts.append(
            figure_html(figures.stillness_plot(rec, found), "rate and temperature with the still segments shaded")
        )
        rows = [
            [
                f"{s.start_s - rec.time_s[0]:.0f}",
                f"{s.duration_s:.0f}",
                "-" if s.temperature_degc is None else f"{s.temperature_degc:.2f}",
                *(float(v) for v in s.gyro_mean_dps),
            ]
            for s in found.segments
        ]
        total = rec.duration_s
        parts.append(
            table_html(
                ["start [s]", "length [s]", "temperature [degC]", *(f"{a} mean [deg/s]" for a in rec.gyro_axes)],
                rows,
                f"{rec.source.rsplit('/', 1)[-1]}: {len(found.segments)} still segment(s), "
                f"{found.still_s / 60:.1f} of {total / 60:.1f} min",
            )
        )
    return "\n".join(parts)


def _page(calibration: Calibration, runs: list[Recording], sections: dict) -> str:
    """The self-contained HTML page: title, navigation, the sections in order."""
    files = ", ".join(escape_text(rec.source.rsplit("/", 1)[-1]) for rec in runs)
    return html_page(f"gyrocomp report: {calibration.model}", "gyrocomp report", f"runs: {files}", sections)


__all__ = ["SECTIONS", "build_report"]
