"""Tables the commands print (rich): fits, triads, evaluations, comparisons, validation, noise."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from rich.table import Table

from ..rounding import with_error
from .common import make_console

if TYPE_CHECKING:  # types only: `gyrocomp allan` need not import the fitting to print its table
    from ..calibration import Calibration
    from ..calibration.fit_report import FitReport, GSensitivityReport, OrderSelection, SelectionReport
    from ..measures.merit import Evaluation
    from ..measures.noise import NoiseAnalysis
    from ..measures.noise_model import NoiseModel
    from ..evaluation.validation import ValidationResult
    from ..evaluation.run_advice import CalibrationPlan


def print_fit(calibration: Calibration, output) -> None:
    console = make_console()
    if not calibration.axes and not calibration.accel_axes:
        console.print(f"gyrocomp fit: {calibration.model}  ->  {output}")
    report = calibration.report
    if calibration.axes:
        _print_axis_fits(console, calibration.axes, report, f"gyrocomp fit: {calibration.model}  ->  {output}", "deg/s")
    if calibration.accel_axes and report.accel is not None:
        _print_axis_fits(
            console,
            calibration.accel_axes,
            report.accel,
            f"accelerometer (correction relative to {calibration.accel_reference_degc:.2f} degC; "
            "constants per run or per static position)" + ("" if calibration.axes else f"  ->  {output}"),
            "g",
        )
    for name, triad in (("gyro", calibration.gyro_triad), ("accelerometer", calibration.accel_triad)):
        if triad is not None:
            _print_triad(console, name, triad)


def print_installed(results) -> None:
    """The installed autopilot calibration against the model, per log and axis (residual RMS)."""
    console = make_console()
    for r in results:
        where = f"{r.data_s / 60:.1f} min of still segments" if r.still_only else f"all {r.data_s / 60:.1f} min"
        console.print(
            f"{Path(r.file).name}: {r.installed or f'no {r.autopilot} thermal calibration installed'} vs "
            f"the model, on {where} (residual RMS of the {r.window_s:.3g} s moving average, deg/s)"
        )
        table = Table()
        for col in ("axis", "raw" + (" (corrected onboard)" if r.corrected_onboard else ""), "installed", "model"):
            table.add_column(col, justify="right")
        for axis in r.raw_dps:
            table.add_row(axis, *(_number(v[axis]) for v in (r.raw_dps, r.installed_dps, r.model_dps)))
        console.print(table)
        if r.note:
            console.print(r.note)
        if r.corrected_onboard:
            console.print(
                "the logged data are already corrected onboard: the model would correct them twice "
                "(log the raw sensor, or disable the onboard calibration)"
            )


def _number(value: float) -> str:
    return "-" if value != value else f"{value:.5g}"


def print_contributions(contributions) -> None:
    """What each field log gave the fit: still minutes and segments, and the temperature range they cover."""
    table = Table(title="field logs: still data used")
    for col in ("log", "length [min]", "still [min]", "still %", "segments", "temperature [degC]", "used"):
        table.add_column(col)
    for c in contributions:
        span = (
            "-" if c.temperature_min_degc is None else f"{c.temperature_min_degc:.1f} .. {c.temperature_max_degc:.1f}"
        )
        table.add_row(
            Path(c.source).name,
            f"{c.duration_s / 60:.1f}",
            f"{c.still_s / 60:.1f}",
            f"{100 * c.still_fraction:.0f}",
            str(c.segments),
            span,
            "still segments" if c.still_only else "whole run",
        )
    make_console().print(table)


def print_learner(learner, contributions, output) -> None:
    """What each replayed log gave the online learner, and the model it learned."""
    table = Table(title="logs replayed (each one power-on)")
    for col in ("log", "length [min]", "still used [min]", "rejected pieces", "temperature [degC]"):
        table.add_column(col)
    for c in contributions:
        table.add_row(
            Path(c.source).name,
            f"{c.duration_s / 60:.1f}",
            f"{c.still_s / 60:.1f}",
            str(c.rejected),
            f"{c.temperature_min_degc:.1f} .. {c.temperature_max_degc:.1f}",
        )
    console = make_console()
    console.print(table)
    st = learner.status
    console.print(
        f"learned: curve of degree {st.degree} in the temperature through a {st.lag_time_constant_s:g} s lag, "
        f"{st.t_min_degc:.1f}..{st.t_max_degc:.1f} degC, from {st.still_s / 60:.1f} still minutes of "
        f"{st.sessions} power-on(s) ({st.points} points, {st.rejected_outliers} outliers and "
        f"{st.rejected_bound} out-of-bound pieces rejected)"
    )
    console.print(
        "residual RMS [deg/s]: "
        + ", ".join(f"{a} {v:.4f}" for a, v in zip("xyz", st.rms_dps))
        + "; standard error of the model [deg/s]: "
        + ", ".join(f"{a} {v:.4f}" for a, v in zip("xyz", st.uncertainty_dps))
    )
    console.print(f"wrote {output}")


def _print_triad(console, name: str, triad) -> None:
    """K (and its standard errors) of a triad, with its scale-factor errors in ppm."""
    table = Table(
        title=f"{name} scale factor and misalignment ({triad.method}"
        + (f", K linear in temperature about {triad.reference_degc:.1f} degC" if triad.temperature_order else "")
        + ")"
    )
    for col in ("axis", "K row (+- standard error)", "scale error [ppm]", f"bias [{triad.unit}]"):
        table.add_column(col)
    for i, axis in enumerate("xyz"):
        row = "  ".join(with_error(k, e, sign=True) for k, e in zip(triad.sensitivity[i], triad.sensitivity_stderr[i]))
        table.add_row(axis, row, f"{triad.scale_factor_error[i] * 1e6:+.0f}", f"{triad.bias[i]:+.5g}")
    console.print(table)


def _describe_axis(ax) -> str:
    """An axis's model in words: curve, lag, hysteresis, rate term."""
    model = "constant" if ax.temperature is None else ax.temperature.describe()
    if ax.lag_time_constant_s > 0:
        model += f", lag {ax.lag_time_constant_s:.3g} s"
    if ax.hysteresis is not None:
        model += f", {ax.hysteresis.describe()}"
    if ax.rate_term is not None:
        model += f", {ax.rate_term.describe(ax.unit)}"
    return model


def _print_axis_fits(console, axes: dict, report: FitReport, title: str, unit: str) -> None:
    table = Table(title=title)
    # the fit RMS only where a fit records one (the binned fits do; the choice by held-out drift shows its scores)
    with_rms = any(report.axes.get(a) is not None and report.axes[a].fit_rms is not None for a in axes)
    for col in ("axis", "model", "range [degC]", *([f"fit RMS [{unit}]"] if with_rms else []), f"constants [{unit}]"):
        table.add_column(col)
    for axis, ax in axes.items():
        fit = report.axes.get(axis)
        model = _describe_axis(ax)
        rng = "-" if ax.temperature is None else f"{ax.temperature.t_min_degc:.2f} .. {ax.temperature.t_max_degc:.2f}"
        rms = ["-" if fit is None or fit.fit_rms is None else f"{fit.fit_rms:.3g}"] if with_rms else []
        constants = ax.turn_on_biases
        shown = ", ".join(f"{c:+.4g}" for c in constants[:6]) + (
            f" ... ({len(constants)})" if len(constants) > 6 else ""
        )
        table.add_row(axis, model, rng, *rms, shown)
    console.print(table)
    net = report.network
    if net:
        console.print(
            f"network: 1-{'-'.join(map(str, net.hidden))}-1 tanh/linear, {net.restarts} restarts "
            f"(seed {net.seed}), {net.training}; validation RMS of the restarts [{unit}]: "
            + "; ".join(f"{a} " + ", ".join(f"{v:.4g}" for v in rmse) for a, rmse in net.validation_rmse.items())
        )
    if report.order_selection is not None:
        _print_order_selection(console, axes, report.order_selection, unit)
    if report.selection:
        _print_selection(console, report.selection, unit)
        return _print_g_sensitivity(console, report.acceleration)
    hyst = report.hysteresis
    if hyst is not None and any(len(choice.scores) > 1 for choice in hyst.axes.values()):
        ht = Table(
            title="hysteresis / thermal lag by "
            + (
                "BIC (lower is better)"
                if hyst.by_bic
                else f"leave-one-run-out residual drift RMS [{unit}] (60 s moving average; lower is better)"
            )
        )
        ht.add_column("axis")
        candidates = hyst.memories_scored
        for name in candidates:
            ht.add_column(name, justify="right")
        ht.add_column("chosen")
        for axis, choice in hyst.axes.items():
            cells = [
                (
                    "-"
                    if choice.scores.get(c) is None
                    else f"{choice.scores[c]:.4g}" + ("*" if c == choice.memory else "")
                )
                if c in choice.scores
                else "-"
                for c in candidates
            ]
            ht.add_row(axis, *cells, choice.label)
        console.print(ht)
    _print_g_sensitivity(console, report.acceleration)


def _print_order_selection(console, axes: dict, selection: OrderSelection, unit: str) -> None:
    """Each axis's score of every polynomial order tried, the chosen one starred."""
    unit_label = f"CV RMS [{unit}]" if selection.method == "leave-one-run-out" else "BIC"
    st = Table(title=f"order selection by {selection.method} ({unit_label}; lower is better)")
    st.add_column("axis")
    orders = selection.orders
    for p in orders:
        st.add_column(f"order {p}", justify="right")
    for axis, s in selection.scores.items():
        chosen = axes[axis].temperature.order if axes[axis].temperature is not None else 0
        st.add_row(axis, *[(f"{s[p]:.4g}*" if p == chosen else f"{s[p]:.4g}") if p in s else "-" for p in orders])
    console.print(st)


def _score(value: float | None, spec: str = ".4g") -> str:
    """A held-out score for a table cell; '-' where the folds held too little data to compute it."""
    return "-" if value is None else format(value, spec)


def _print_selection(console, selection: dict[str, SelectionReport], unit: str) -> None:
    """The model choice: per axis the chosen and best candidates against the run constant alone, then the fold
    scores of those three (every candidate's are in the model file)."""
    first = next(iter(selection.values()))
    table = Table(
        title=f"model choice by held-out drift ({first.fold_kind}: {len(first.folds)} folds, "
        f"{first.window_s:g} s moving average, simplest within one standard error) [{unit}]",
        caption=first.ramp_note or None,
    )
    decided = any(sel.decided_by for sel in selection.values())  # files written before it was stored have none
    columns = ("axis", "chosen", "held-out drift", "best", "best drift", "constant only") + (
        ("decided by",) if decided else ()
    )
    for col in columns:
        table.add_column(col, justify="left" if col in ("axis", "chosen", "best", "decided by") else "right")
    for axis, sel in selection.items():
        chosen, best = sel.result(sel.chosen.label), sel.result(sel.best.label)
        table.add_row(
            axis,
            sel.chosen.label + (" (the die's lag)" if sel.lag_from_unit else ""),
            with_error(chosen.mean_drift, chosen.standard_error),
            sel.best.label,
            _score(best.mean_drift),
            _score(sel.raw_drift),
            *((sel.decided_by,) if decided else ()),
        )
    console.print(table)
    # one row per fold, one column per axis and model: as narrow for twelve legs as for three runs
    folds = Table(title=f"held-out drift per fold [{unit}]: each axis's chosen model, the best, the constant")
    folds.add_column("fold")
    roles = {}  # axis -> {label: role}, a model named once (the chosen one may be the best, or the constant)
    for axis, sel in selection.items():
        roles[axis] = {}
        for role, label in (("chosen", sel.chosen.label), ("best", sel.best.label), ("constant", "constant (time)")):
            roles[axis].setdefault(label, role)
    for axis, named in roles.items():
        for role in named.values():
            folds.add_column(f"{axis} {role}", justify="right")
    for f, name in enumerate(first.folds):
        folds.add_row(
            name,
            *[_score(selection[axis].result(label).fold_drift[f]) for axis, named in roles.items() for label in named],
        )
    console.print(folds)


def _print_g_sensitivity(console, acc: GSensitivityReport | None) -> None:
    """The G table, for the gyro axes where some column was fitted (a chamber run in one orientation fits none:
    no table of "not fitted" cells then)."""
    fitted = (
        {}
        if acc is None
        else {axis: row for axis, row in acc.axes.items() if any(e is not None for e in row.standard_error_dps_per_g)}
    )
    if fitted:
        gt = Table(
            title=f"g-sensitivity G [deg/s/g] +- standard error (cluster-robust over {sum(acc.static_segments)} "
            f"static segments; excited: {', '.join(acc.excited_axes) or 'none'})"
        )
        gt.add_column("gyro axis")
        for name in ("accel_x", "accel_y", "accel_z"):
            gt.add_column(name, justify="right")
        for axis, row in fitted.items():
            cells = [
                with_error(g, e, sign=True) if e is not None else "not fitted"
                for g, e in zip(row.g_sensitivity_dps_per_g, row.standard_error_dps_per_g)
            ]
            gt.add_row(axis, *cells)
        console.print(gt)


def print_validation(result: ValidationResult) -> None:
    console = make_console()
    table = Table(title=result.title)
    header, rows = result.table_rows()
    table.add_column(header[0])
    for column in header[1:]:
        table.add_column(column, justify="right")
    for row in rows:
        table.add_row(*row)
    console.print(table)
    console.print("folds: " + ", ".join(result.folds))


def _figures_table(title: str, what: str) -> Table:
    """A table of the thesis's figures per axis and ``what`` (stage, method)."""
    table = Table(title=title)
    for col in ("axis", what):
        table.add_column(col, no_wrap=True)
    for col in (
        "bias offset\n[deg/s]",
        f"improvement\n(raw/{what})",
        "bias instability\n[deg/h]",
        "integration time\n[s]",
    ):
        table.add_column(col, justify="right")
    return table


def print_stages(staged) -> None:
    console = make_console()
    for run in staged:
        table = _figures_table(
            f"{Path(run.file).name}: stages of the compensation (window {run.window_s:.4g} s)", "stage"
        )
        first = next(iter(run.stages.values()))
        for axis in first:
            m0 = first[axis]
            table.add_row(
                axis,
                "raw",
                f"{m0.bias_offset_raw_dps:.4g}",
                "1x",
                f"{m0.bias_instability_raw_dph:.4g}",
                f"{m0.integration_time_raw_s:.4g}",
            )
            for name, axes in run.stages.items():
                m = axes[axis]
                table.add_row(
                    "",
                    name,
                    f"{m.bias_offset_comp_dps:.4g}",
                    f"{m.offset_improvement:.3g}x",
                    f"{m.bias_instability_comp_dph:.4g}",
                    f"{m.integration_time_comp_s:.4g}",
                )
        console.print(table)


def print_comparison(result) -> None:
    console = make_console()
    table = _figures_table(f"methods compared ({result.how})", "method")
    for row in result.rows:
        table.add_row(
            row.axis,
            row.method,
            f"{row.bias_offset_dps:.4g}",
            f"{row.improvement:.3g}x",
            f"{row.bias_instability_deg_per_h:.4g}",
            f"{row.integration_time_s:.4g}",
        )
    console.print(table)


def _metrics_table(title: str, evaluation: Evaluation, rows_of) -> Table | None:
    """One table of raw and compensated figures; ``rows_of(run)`` gives (axis, figures) pairs of one sensor (the
    figures say their units)."""
    rows = [(run, axis, m) for run in evaluation.runs for axis, m in rows_of(run)]
    if not rows:
        return None
    unit, bi_unit = rows[0][2].unit, rows[0][2].bias_instability_unit
    table = Table(title=title)
    table.add_column("run", no_wrap=True)
    table.add_column("axis", no_wrap=True)
    for col in (
        "window\n[s]",
        f"offset raw\n[{unit}]",
        f"offset comp\n[{unit}]",
        "improvement\n(raw/comp)",
        f"BI raw\n[{bi_unit}]",
        f"BI comp\n[{bi_unit}]",
        "int. time raw\n[s]",
        "int. time comp\n[s]",
        f"residual RMS\n[{unit}]",
    ):
        table.add_column(col, justify="right")
    for run, axis, m in rows:
        table.add_row(
            Path(run.file).name,
            axis,
            f"{run.window_s:.4g}",
            f"{m.offset_raw:.4g}",
            f"{m.offset_comp:.4g}",
            f"{m.offset_improvement:.3g}x",
            f"{m.bias_instability_raw:.4g}",
            f"{m.bias_instability_comp:.4g}",
            f"{m.integration_time_raw_s:.4g}",
            f"{m.integration_time_comp_s:.4g}",
            f"{m.residual_rms:.3g}",
        )
    return table


def print_plan(result: CalibrationPlan, shown: int = 5) -> None:
    """The drift to expect on the use profile, per axis, then the best ``shown`` candidate runs."""
    console = make_console()
    now = result.now
    table = Table(title=f"drift to expect on {now.profile} ({now.window_s:g} s moving average, 95 % interval)")
    for col in ("axis", "expected", "95 % interval", "coefficients", "own noise", "past the range", "lag"):
        table.add_column(col, justify="left" if col == "axis" else "right")
    for f in now.axes.values():
        lag = "-" if f.lag_s is None else f"{f.lag_s:.3g} +- {f.lag_standard_error_s:.2g} s"
        table.add_row(
            f.axis,
            f"{f.drift_dps:.3g} deg/s",
            f"{f.low_dps:.3g}..{f.high_dps:.3g}",
            f"{f.coefficients_dps:.2g}",
            f"{f.noise_dps:.2g}",
            f"{f.extrapolation_dps:.2g}"
            + (f" ({f.outside_range_fraction:.0%} of the time)" if f.outside_range_fraction else ""),
            lag,
        )
    console.print(table)
    lo, hi = result.range_degc
    runs = Table(
        title=f"next run (calibrated {lo:.1f}..{hi:.1f} degC at {result.ramp_degc_per_min:.2g} degC/min; "
        "best gain per hour of chamber time first)"
    )
    for col in ("run", "what", "hours", f"{now.worst.axis} after", "gain per hour", "what it resolves"):
        runs.add_column(col, justify="right" if col in ("hours", "gain per hour") or col.endswith("after") else "left")
    for a in result.advice[:shown]:
        after = a.after.axes[now.worst.axis]
        runs.add_row(
            a.run.name,
            a.run.description,
            f"{a.run.hours:.1f}",
            f"{after.drift_dps:.3g} ({after.low_dps:.2g}..{after.high_dps:.2g})",
            f"{a.gain_dps_per_h:.2g} deg/s/h",
            a.resolves,
        )
    console.print(runs)


def print_expected_drift(expected: dict) -> None:
    """What the fit's held-out folds say the drift on unseen data will be, per axis (``FitReport.expected_drift``)."""
    if not expected:
        return
    first = next(iter(expected.values()))
    table = Table(
        title=f"drift to expect on unseen data (the model file's {first.folds} held-out {first.fold_kind}, "
        f"{first.window_s:g} s moving average" + ("; thin evidence" if first.thin else "") + ")",
        caption=first.ramp_note or None,
    )
    for col in ("axis", "model", "expected drift", "run constant alone"):
        table.add_column(col, justify="left" if col in ("axis", "model") else "right")
    for e in expected.values():
        table.add_row(
            e.axis, e.model, f"{with_error(e.drift, e.standard_error)} {e.unit}", f"{_score(e.constant_drift)} {e.unit}"
        )
    make_console().print(table)


def print_evaluation(evaluation: Evaluation, title: str = "gyrocomp evaluate") -> None:
    console = make_console()
    for table in (
        _metrics_table(title, evaluation, lambda run: run.axes.items()),
        _metrics_table(f"{title}: accelerometer", evaluation, lambda run: run.accel_axes.items()),
    ):
        if table is not None:
            console.print(table)
    if evaluation.triads:
        table = Table(title=f"{title}: scale factor and misalignment (RMS over the run's poses, turns or stretches)")
        for col in ("run", "figure", "count", "raw", "compensated", "improvement"):
            table.add_column(col, justify="left" if col in ("run", "figure") else "right")
        for t in evaluation.triads:
            label, scale, unit = _TRIAD_FIGURES[t.figure]
            table.add_row(
                Path(t.file).name,
                label,
                str(t.raw.size),
                f"{t.rms_raw * scale:.3g} {unit}",
                f"{t.rms_compensated * scale:.3g} {unit}",
                f"{t.rms_raw / t.rms_compensated:.3g}x" if t.rms_compensated > 0 else "-",
            )
        console.print(table)


#: how ``evaluate`` prints each scale-factor figure: label, factor to the printed unit, unit
_TRIAD_FIGURES = {
    "pose_norm_g": ("|a| - 1 g at each still pose", 1e3, "mg"),
    "turn_direction_deg": ("gravity direction after each turn", 1.0, "deg"),
    "rate_error_dps": ("rate error on each rate-table stretch", 1.0, "deg/s"),
}


def print_noise(analysis: NoiseAnalysis) -> None:
    console = make_console()
    for name, a in analysis.axes.items():
        c = a.curve
        table = Table(title=f"{Path(analysis.source).name}: {name} {c.kind.upper()} [{a.unit}]")
        for col in ("tau [s]", "deviation", "ci low", "ci high", "n", "alpha", "noise type by"):
            table.add_column(col, justify="left" if col == "noise type by" else "right")
        methods = c.noise_method or ("",) * len(c.tau)
        for row in zip(c.tau, c.deviation, c.ci_low, c.ci_high, c.n, c.alpha, methods):
            table.add_row(
                f"{row[0]:.6g}",
                f"{row[1]:.5g}",
                f"{row[2]:.5g}",
                f"{row[3]:.5g}",
                f"{row[4]:d}",
                "-" if np.isnan(row[5]) else f"{row[5]:+.0f}",
                row[6] or "-",
            )
        console.print(table)
    table = Table(title="noise terms (IEEE Std 952 fit; B = Allan minimum / 0.664)")
    table.add_column("axis", no_wrap=True)
    table.add_column("term")
    table.add_column("value", justify="right")
    table.add_column("read-off", justify="right")
    for name, a in analysis.axes.items():
        n = a.noise
        if a.sensor == "gyro":
            rows = [
                ("N [deg/s/sqrt(Hz)]", n.noise_density_dps_per_sqrt_hz, n.noise_density_readoff_dps_per_sqrt_hz),
                ("ARW [deg/sqrt(h)]", n.arw_deg_per_sqrt_h, None),
                ("B [deg/h]", n.bias_instability_deg_per_h, None),
                ("integration time [s]", n.integration_time_s, None),
                ("K [deg/h/sqrt(h)]", n.rrw_deg_per_h_per_sqrt_h, n.rrw_readoff_deg_per_h_per_sqrt_h),
                ("Q [deg]", n.quantization_deg, None),
                ("R [deg/h^2]", n.rate_ramp_deg_per_h2, None),
            ]
        else:
            rows = [
                ("N [g/sqrt(Hz)]", n.noise_density_g_per_sqrt_hz, n.noise_density_readoff_g_per_sqrt_hz),
                ("VRW [m/s/sqrt(h)]", n.vrw_m_per_s_per_sqrt_h, None),
                ("B [micro-g]", n.bias_instability_micro_g, None),
                ("integration time [s]", n.integration_time_s, None),
                ("K [m/s^3/sqrt(Hz)]", n.random_walk_m_per_s3_per_sqrt_hz, n.random_walk_readoff_m_per_s3_per_sqrt_hz),
                ("Q [m/s]", n.quantization_m_per_s, None),
                ("R [m/s^3]", n.ramp_m_per_s3, None),
            ]
        for i, (term, value, readoff) in enumerate(rows):
            table.add_row(name if i == 0 else "", term, f"{value:.4g}", "" if readoff is None else f"{readoff:.4g}")
        if not n.floor_reached:
            table.add_row("", "(no floor: B is an upper bound)", "", "")
    console.print(table)


def print_noise_model(model: NoiseModel) -> None:
    """Per axis: the IEEE 952 fit beside the two bounds, and each log's own bound."""
    console = make_console()
    table = Table(
        title=f"noise model at {model.rate_hz:g} Hz: at or above the measured Allan deviation's upper "
        "95 % interval (ratio: model / measured over the bounded taus)"
    )
    for col in (
        "axis",
        "unit u",
        "IEEE 952 N [u/sqrt(Hz)]",
        "IEEE 952 K [u/sqrt(s)]",
        "bound N",
        "bound K",
        "ratio median / max",
        "with Gauss-Markov: terms",
        "ratio median / max ",
        "taus bounded [s]",
    ):
        table.add_column(col, justify="left" if col in ("axis", "unit u") else "right")
    for name, a in model.axes.items():
        table.add_row(
            name,
            a.unit,
            f"{a.ieee.white_noise_density:.4g}",
            f"{a.ieee.random_walk:.4g}",
            f"{a.bound.white_noise_density:.4g}",
            f"{a.bound.random_walk:.4g}",
            f"{a.bound.ratio_median:.2f} / {a.bound.ratio_max:.2f}",
            str(len(a.markov.markov)),
            f"{a.markov.ratio_median:.2f} / {a.markov.ratio_max:.2f}",
            f"{a.bound.taus_s[0]:.3g} .. {a.max_tau_s:.3g}",
        )
    console.print(table)
    if any(len(a.logs) > 1 for a in model.axes.values()):
        logs = Table(
            title="each log's own bound (white noise N, random walk K; with Gauss-Markov terms: how many, its "
            "median / largest ratio to the log's curve) and N read at one sample with its 95 % interval"
        )
        columns = ("axis", "log", "temperature [degC]", "bound N", "bound K", "Gauss-Markov", "N at one sample [95 %]")
        for col in columns:
            logs.add_column(col, justify="left" if col in ("axis", "log") else "right")
        for name, a in model.axes.items():
            for log in a.logs:
                low, value, high = log.white_noise_interval
                logs.add_row(
                    name,
                    Path(log.source).name,
                    "-" if log.temperature_degc is None else f"{log.temperature_degc:.1f}",
                    f"{log.bound.white_noise_density:.4g}",
                    f"{log.bound.random_walk:.4g}",
                    f"{len(log.markov.markov)}: {log.markov.ratio_median:.2f} / {log.markov.ratio_max:.2f}",
                    f"{value:.4g} [{low:.4g}, {high:.4g}]",
                )
        console.print(logs)


def print_bias_process_noise(benefit: dict) -> None:
    """Per gyro axis: the bias random walk a filter needs with the raw and with the compensated gyro."""
    table = Table(
        title="the bias random walk a filter needs on these runs (white noise and random walk at or above "
        "the Allan curve up to a quarter of the run) [deg/s/sqrt(s)]"
    )
    for col in ("axis", "raw K", "compensated K", "raw / compensated", "raw N", "compensated N"):
        table.add_column(col, justify="left" if col == "axis" else "right")
    for name, b in benefit.items():
        table.add_row(
            name,
            f"{b.raw.random_walk:.4g}",
            f"{b.compensated.random_walk:.4g}",
            f"{b.random_walk_ratio:.1f}",
            f"{b.raw.white_noise_density:.4g}",
            f"{b.compensated.white_noise_density:.4g}",
        )
    make_console().print(table)


__all__ = [
    "print_bias_process_noise",
    "print_comparison",
    "print_evaluation",
    "print_expected_drift",
    "print_fit",
    "print_noise",
    "print_noise_model",
    "print_stages",
    "print_validation",
]


def print_station_status(stations, store) -> None:
    """``gyrocomp fleet status``: one row per station."""
    console = make_console()
    if not stations:
        console.print(f"{store}: no calibration stored and no unit being fitted")
        return
    table = Table(title=f"stations of {store}")
    for column in ("station", "ok", "failed", "last write (UTC)", "fitting now", "stale claims"):
        table.add_column(column, overflow="fold")
    for s in stations:
        fitting = ", ".join(s.fitting[:5]) + (f" (+{len(s.fitting) - 5})" if len(s.fitting) > 5 else "")
        table.add_row(
            s.station,
            str(s.ok),
            str(s.failed),
            "" if s.last_utc is None else f"{s.last_utc:%Y-%m-%d %H:%M:%S}",
            fitting or "-",
            f"{s.stale} (rerun the station)" if s.stale else "0",
        )
    console.print(table)
