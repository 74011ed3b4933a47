"""The commands of the ``gyrocomp`` command line: each parses its options, calls the library and prints its
tables. :mod:`gyrocomp.cli` loads this module only when a command runs (``gyrocomp --help`` does not need the
library), and maps errors to exit codes.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import sys
import warnings
from pathlib import Path

import click
import numpy as np
from rich.console import Console
from rich.progress import BarColumn, Progress, TaskProgressColumn, TextColumn, TimeElapsedColumn
from rich.table import Table

from ..allan import KINDS
from ..calibration import Calibration
from ..compensate import apply as apply_calibration
from ..errors import DataQualityWarning, InputError, TemperatureRangeWarning
from ..io import (
    FORMATS,
    ReadOptions,
    TableLayout,
    detect_format,
    parse_column_mapping,
    output_format,
    read_input,
    refuse_to_overwrite_inputs,
    write_gyro_back,
    write_recording,
    write_text_atomic,
)
from ..io.schedule import apply_schedule, read_rate_schedule
from ..export.kalibr import kalibr_imu, kalibr_imu_yaml
from ..comparison import compare_methods
from ..demo import run_demo
from ..evaluation import evaluate as evaluate_calibration
from ..export.autopilot import ardupilot_params_file, px4_params_file
from ..export.c_code import write_c_sources
from ..evaluation import evaluate_stages
from ..metrics import Evaluation, default_window_s
from ..report.figures import allan_plot, require_matplotlib, save_figure, temperature_plot, timeseries_plot
from ..report.html import build_report
from ..simulate import ONE_TEMPERATURE_PROFILES, Simulation, preset_model, resolve_profile, run_profiles
from ..simulate import simulate as run_simulation
from ..models.acceleration import ACCELERATION_CHOICES
from ..models.mlp import DEFAULT_HIDDEN
from ..models.pipelines import SCALE_FACTOR_CHOICES, fit_channels, parse_channels
from ..models.selection import FOLD_KINDS
from ..models.temperature import MAX_ORDER
from ..models.thermal import CANDIDATES, HYSTERESIS_CHOICES
from ..validation import ValidationResult, validate as validate_runs
from ..noise import NoiseAnalysis, analyse_noise
from ..report.figures import allan_figure, check_figure_path



def _console() -> Console:
    return Console(width=None if sys.stdout.isatty() else 160, highlight=False, markup=False)


def read_options(func):
    """Options every command that reads data files shares."""
    options = [
        click.option("--columns", "columns", metavar="CH=COL,...",
                     help="Map channels to the file's columns, e.g. gyro_z=GyrZ,temperature=T."),
        click.option("--gyro-unit", default="deg/s", show_default=True, help="deg/s, rad/s or mdps."),
        click.option("--accel-unit", default="g", show_default=True, help="g, mg or m/s2."),
        click.option("--time-unit", default="s", show_default=True, help="s, ms, us or ns."),
        click.option("--format", "fmt", default=None,
                     help=f"Input format (default: told from the file): {', '.join(FORMATS)}."),
        click.option("--delimiter", default=None,
                     help="CSV field separator (default: told from the header: comma, semicolon or tab; 'tab' for a tab)."),
        click.option("--decimal", default=None, help="CSV decimal point, . or , (default: told from the first row)."),
        click.option("--drop-nan", is_flag=True, help="Drop rows with empty/NaN values (says how many) instead of refusing the file."),
        click.option("--instance", type=int, default=None,
                     help="Sensor instance in PX4/ArduPilot logs (uORB multi_id, IMU number from 0; default 0)."),
        click.option("--device-id", "device_id", type=int, default=None, help="PX4 device id of the gyro to read."),
        click.option("--imu-topic", default=None, help="ROS bag: the sensor_msgs/Imu topic (default: the only one)."),
        click.option("--temperature-topic", default=None,
                     help="ROS bag: the sensor_msgs/Temperature topic (default: the only one)."),
        click.option("--record", default=None, help="ArduPilot log: IMU (default) or TCLR (onboard learning records)."),
    ]
    for option in reversed(options):
        func = option(func)
    return func


def _layout(columns, gyro_unit, accel_unit, time_unit, delimiter=None, decimal=None) -> TableLayout:
    return TableLayout(parse_column_mapping(columns), gyro_unit, accel_unit, time_unit,
                       "\t" if delimiter == "tab" else delimiter, decimal)


_READ_OPTIONS = ("columns", "gyro_unit", "accel_unit", "time_unit", "fmt", "drop_nan", "instance", "device_id",
                 "imu_topic", "temperature_topic", "record", "delimiter", "decimal")


@contextlib.contextmanager
def progress_bar(description: str, indeterminate: bool = False):
    """A progress callback drawing a bar on stderr when it is a terminal and --quiet is off; else None.
    ``indeterminate``: a pulsing bar for work that does not report its fraction done."""
    ctx = click.get_current_context(silent=True)
    quiet = bool(ctx and ctx.find_root().obj and ctx.find_root().obj.get("quiet"))
    if quiet or not sys.stderr.isatty():
        yield None
        return
    with Progress(TextColumn("{task.description}"), BarColumn(), TaskProgressColumn(), TimeElapsedColumn(),
                  console=Console(stderr=True), transient=True) as bar:
        task = bar.add_task(description, total=None if indeterminate else 1.0)
        yield lambda fraction: bar.update(task, completed=min(max(fraction, 0.0), 1.0))


def _read(path, opts: dict):
    layout = _layout(opts["columns"], opts["gyro_unit"], opts["accel_unit"], opts["time_unit"], opts["delimiter"],
                     opts["decimal"])
    options = ReadOptions(layout=layout, drop_nonfinite=opts["drop_nan"], instance=opts["instance"],
                          device_id=opts["device_id"], imu_topic=opts["imu_topic"],
                          temperature_topic=opts["temperature_topic"], record=opts["record"])
    with progress_bar(f"reading {Path(path).name}") as progress:
        return read_input(path, options, fmt=opts["fmt"], progress=progress)


def _pop_read_options(kwargs: dict) -> dict:
    return {k: kwargs.pop(k) for k in _READ_OPTIONS}


def parse_hidden(text: str) -> tuple[int, ...]:
    """``"mlp"`` -> (3,), ``"mlp:5"`` -> (5,), ``"mlp:5x4"`` -> (5, 4)."""
    text = text.strip().lower()
    if text == "mlp":
        return DEFAULT_HIDDEN
    try:
        hidden = tuple(int(h) for h in text.split(":", 1)[1].split("x"))
    except (IndexError, ValueError):
        hidden = ()
    if not hidden or any(h < 1 or h > 50 for h in hidden) or len(hidden) > 3:
        raise InputError(f"--temperature: {text!r}; use mlp, mlp:H (H hidden tanh neurons, 1..50) or mlp:HxH")
    return hidden


def parse_temperature_option(text: str) -> int | str | tuple | None:
    """``"poly"`` -> ``"auto"``, ``"poly:3"`` -> 3, ``"mlp"``/``"mlp:5"`` -> ("mlp", hidden), ``"none"`` -> None."""
    text = text.strip().lower()
    if text == "mlp" or text.startswith("mlp:"):
        return ("mlp", parse_hidden(text))
    if text in ("poly", "auto"):
        return "auto"
    if text == "none":
        return None
    if text.startswith("poly:"):
        try:
            order = int(text[5:])
        except ValueError:
            order = -1
        if 0 <= order <= MAX_ORDER:
            return order
        raise InputError(f"--temperature: {text!r}: the order must be a whole number from 0 to {MAX_ORDER}")
    raise InputError(f"--temperature: {text!r}: use poly (automatic order), poly:N (N = 0..{MAX_ORDER}), "
                     "mlp (the thesis's 1-3-1 network), mlp:H or none")


# -- simulate ---------------------------------------------------------------------------------------
def _float_list(text: str | None, option: str) -> tuple[float, ...] | None:
    if text is None:
        return None
    try:
        values = tuple(float(v) for v in text.split(",") if v.strip())
    except ValueError:
        values = ()
    if not values:
        raise click.BadParameter("give comma-separated numbers, e.g. -20,70", param_hint=option)
    return values


@click.command()
@click.option("--preset", default="mti10", show_default=True,
              help="Sensor: adxrs450, mti10, adis16488 or consumer (values from datasheets; see the docs).")
@click.option("--profile", default="chamber", show_default=True,
              help="static, warmup, chamber, cycle, tumble, combined or ratetable.")
@click.option("--duration", "duration_s", type=float, default=None,
              help="Run length [s] (default: the profile's own; a set duration stretches the profile).")
@click.option("--rate", "rate_hz", type=float, default=100.0, show_default=True, help="Sample rate [Hz].")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of run 0; run i uses seed + i.")
@click.option("--runs", type=int, default=1, show_default=True,
              help="Write K power-ons (own turn-on bias and noise) as OUT_0.csv ... OUT_{K-1}.csv.")
@click.option("--unit", type=int, default=None, help="Simulate unit N of the preset's production spread (default: nominal).")
@click.option("--axes", default=None, help="Gyro axes to simulate, e.g. z or x,y,z (default: all of the preset's).")
@click.option("--disable", default=None, metavar="TERM,...",
              help="Switch error terms off: temperature, lag, hysteresis, g-sensitivity, scale-factor, "
                   "misalignment, turn-on, noise, quantization, temperature-noise.")
@click.option("--set-points", "set_points", default=None, metavar="T1,T2,...",
              help="Chamber set points [degC] (default: the preset's range); static, tumble and ratetable: one run "
                   "per set point.")
@click.option("--ramp-rate", "ramp_rate", type=float, default=None, help="Ramp rate between set points [degC/min].")
@click.option("--dwell", "dwell_s", type=float, default=None, help="Time held at each set point [s].")
@click.option("--cycles", type=int, default=None, help="Cold-hot-cold repetitions of the cycle profile.")
@click.option("--position-time", "position_s", type=float, default=None,
              help="Time at each tumble position or rate-table rate [s].")
@click.option("--rates", "rates", default=None, metavar="R1,R2,...",
              help="ratetable: rates applied about each axis in turn [deg/s], e.g. 100,-100,300,-300 (the file gets "
                   "ref_rate_x/y/z columns; the first --set-points value is the table's temperature).")
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False), help="Output CSV or Parquet.")
@click.option("--truth", type=click.Path(dir_okay=False), help="Write every parameter used as JSON here.")
@click.option("--truth-columns", is_flag=True,
              help="Add true_error_gyro_*, true_noise_gyro_*, true_rate_gyro_* and true_structure_temperature columns.")
@click.pass_context
def simulate(ctx, preset, profile, duration_s, rate_hz, seed, runs, unit, axes, disable, set_points, ramp_rate, dwell_s,
             cycles, position_s, rates, output, truth, truth_columns):
    """Simulate calibration runs of a sensor preset through a test profile, with the exact truth."""

    model = preset_model(preset, unit)
    if axes:
        model = model.subset(tuple(f"gyro_{a.strip()}" for a in axes.split(",") if a.strip()))
    if disable:
        model = model.without(*(t.strip() for t in disable.split(",") if t.strip()))
    if runs < 1:
        raise click.BadParameter("must be at least 1", param_hint="--runs")
    prof = resolve_profile(profile, preset, set_points_degc=_float_list(set_points, "--set-points"),
                           ramp_rate_degc_per_min=ramp_rate, dwell_s=dwell_s, cycles=cycles, position_s=position_s,
                           rates_dps=_float_list(rates, "--rates"))
    if runs == 1 and prof.name in ONE_TEMPERATURE_PROFILES and len(prof.set_points_degc) > 1:
        runs = len(prof.set_points_degc)  # one run per temperature
    profiles = run_profiles(prof, runs)
    output_format(output)
    out = Path(output)
    paths = [out] if runs == 1 else [out.with_name(f"{out.stem}_{i}{out.suffix}") for i in range(runs)]
    if truth and any(Path(truth).resolve() == p.resolve() for p in paths):
        raise InputError(f"--truth {truth}: the same file as a data output; choose another path")
    records = []
    for i, path in enumerate(paths):
        sim = run_simulation(model, profile=profiles[i], duration_s=duration_s, rate_hz=rate_hz, seed=seed + i,
                             source=str(path))
        sim = Simulation(sim.recording, dataclasses.replace(sim.truth, preset=preset, unit=unit))
        write_recording(sim.recording, path, extra_columns=sim.truth.truth_columns() if truth_columns else None)
        records.append((path, sim))
        if not ctx.obj["quiet"]:
            rec = sim.recording
            gaps = f", {len(rec.gaps)} gaps" if rec.gaps else ""
            click.echo(f"wrote {path}: {rec.n_samples} rows, {rec.duration_s:g} s at {rate_hz:g} Hz{gaps}")
    if truth:
        first = records[0][1].truth.to_dict()
        doc = {k: v for k, v in first.items() if k not in ("seed", "turn_on_bias_dps", "samples",
                                                            "deterministic_error_range_dps")}
        doc["runs"] = [{"file": path.name, "seed": sim.truth.seed, "samples": sim.recording.n_samples,
                        "turn_on_bias_dps": sim.truth.to_dict()["turn_on_bias_dps"],
                        "deterministic_error_range_dps": sim.truth.to_dict()["deterministic_error_range_dps"]}
                       for path, sim in records]
        write_text_atomic(truth, json.dumps(doc, indent=2) + "\n")


# -- fit --------------------------------------------------------------------------------------------
@click.command()
@click.argument("runs", nargs=-1, required=True, type=click.Path())
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False), help="Model file to write (JSON).")
@click.option("--temperature", default="poly", show_default=True,
              help="poly (order by cross-validation), poly:N (N = 0..5), mlp (the thesis's 1-3-1 network, "
                   "Levenberg-Marquardt), mlp:H (H hidden neurons) or none.")
@click.option("--seed", "mlp_seed", type=int, default=0, show_default=True,
              help="Seed of the network's initializations (mlp); the same seed gives the same model.")
@click.option("--bin-width", "bin_width_degc", type=float, default=None, help="Temperature bin width [degC] (default: span/100).")
@click.option("--hysteresis", type=click.Choice(HYSTERESIS_CHOICES), default="auto", show_default=True,
              help="Thermal lag and/or turning-point hysteresis; auto compares all by leave-one-run-out error "
                   "when the runs both heat and cool.")
@click.option("--hysteresis-order", default="auto", show_default=True,
              help="Order of the turning-point polynomial in |T - T_turn|: auto (validated) or 1..3.")
@click.option("--hysteresis-band", "hysteresis_band", default=None, metavar="LO,HI",
              help="Limit the hysteresis to this temperature band [degC], e.g. 55,80.")
@click.option("--acceleration", type=click.Choice(["auto", *ACCELERATION_CHOICES]), default="auto", show_default=True,
              help="g-sensitivity fitted jointly on the static segments: matrix (3x3), matrix2 (+ g x g terms), "
                   "none; auto: matrix when the runs turn the unit between positions.")
@click.option("--pipeline", default="joint", show_default=True,
              help="joint (temperature, lag/hysteresis, G and run constants in one fit), or a cascade fitted stage by "
                   "stage: 'poly>matrix', 'matrix>poly', 'mlp>matrix', or 'joint-mlp' (one network reading the "
                   "temperature and the three accelerations). Quote the > in a shell.")
@click.option("--min-static", "static_min_duration_s", type=float, default=10.0, show_default=True,
              help="Shortest still stretch used as a static position [s].")
@click.option("--channels", default="gyro", show_default=True,
              help="What to model: gyro, accel (the accelerometer's bias against temperature, in g) or gyro,accel "
                   "(then G reads the temperature-compensated accelerations).")
@click.option("--folds", type=click.Choice(FOLD_KINDS), default="auto", show_default=True,
              help="What the model choice holds out: each run, each heating or cooling leg, or time blocks; "
                   "auto: runs with three runs or more, else legs.")
@click.option("--scale-factor", "scale_factor", type=click.Choice(SCALE_FACTOR_CHOICES), default="auto",
              show_default=True,
              help="Gyro scale factor and misalignment from the runs with ref_rate_x/y/z columns (rate table) or, "
                   "without them, from the turns between the still poses of multi-position runs: matrix (constant), "
                   "matrix-temperature (linear in temperature), none; auto: when such runs are given, the order by "
                   "leave-one-run-out.")
@click.option("--rate-schedule", "rate_schedule", type=click.Path(), default=None, metavar="FILE",
              help="A rate table's schedule (CSV: file,start_s,end_s,ref_rate_x,ref_rate_y,ref_rate_z [deg/s]) "
                   "giving the reference rates of the runs it names, instead of ref_rate_x/y/z columns.")
@read_options
@click.pass_context
def fit(ctx, runs, output, temperature, mlp_seed, bin_width_degc, hysteresis, hysteresis_order, hysteresis_band,
        acceleration, pipeline, static_min_duration_s, channels, folds, scale_factor, rate_schedule, **kwargs):
    """Fit a compensation model on calibration RUNS (each one power-on, the gyro at rest)."""
    opts = _pop_read_options(kwargs)
    order = parse_temperature_option(temperature)
    if hysteresis_order != "auto":
        if hysteresis_order not in ("1", "2", "3"):
            raise click.BadParameter("use auto, 1, 2 or 3", param_hint="--hysteresis-order")
        hysteresis_order = int(hysteresis_order)
    band = _float_list(hysteresis_band, "--hysteresis-band")
    if band is not None and (len(band) != 2 or not band[0] < band[1]):
        raise click.BadParameter("give LO,HI in degC with LO < HI, e.g. 55,80", param_hint="--hysteresis-band")
    channels = parse_channels(channels)
    refuse_to_overwrite_inputs(output, runs)
    recordings = [_read(path, opts).recording for path in runs]
    if rate_schedule is not None:
        recordings = apply_schedule(read_rate_schedule(rate_schedule), recordings, list(runs))
    with progress_bar("fitting", indeterminate=True):
        calibration = fit_channels(recordings, channels, pipeline, temperature=order, bin_width_degc=bin_width_degc,
                                   hysteresis=hysteresis, hysteresis_order=hysteresis_order,
                                   hysteresis_band_degc=band, mlp_seed=mlp_seed, acceleration=acceleration,
                                   static_min_duration_s=static_min_duration_s, scale_factor=scale_factor,
                                   **({} if folds == "auto" else {"folds": folds}))
    calibration.save(output)
    if not ctx.obj["quiet"]:
        _print_fit(calibration, output)


def _print_fit(calibration: Calibration, output) -> None:
    console = _console()
    if not calibration.axes and not calibration.accel_axes:
        console.print(f"gyrocomp fit: {calibration.model}  ->  {output}")
    if calibration.axes:
        _print_axis_fits(console, calibration.axes, calibration.fit_report, f"gyrocomp fit: {calibration.model}  ->  "
                         f"{output}", "deg/s")
    if calibration.accel_axes:
        _print_axis_fits(console, calibration.accel_axes, calibration.fit_report.get("accel", {}),
                         f"accelerometer (correction relative to {calibration.accel_reference_degc:.2f} degC; "
                         "constants per run or per static position)" + ("" if calibration.axes else f"  ->  {output}"),
                         "g")
    for name, triad in (("gyro", calibration.gyro_triad), ("accelerometer", calibration.accel_triad)):
        if triad is not None:
            _print_triad(console, name, triad)


def _print_triad(console, name: str, triad) -> None:
    """K (and its standard errors) of a triad, with its scale-factor errors in ppm."""
    table = Table(title=f"{name} scale factor and misalignment ({triad.method}"
                  + (f", K linear in temperature about {triad.reference_degc:.1f} degC" if triad.temperature_order else "")
                  + ")")
    for col in ("axis", "K row (+- standard error)", "scale error [ppm]", f"bias [{triad.unit}]"):
        table.add_column(col)
    for i, axis in enumerate("xyz"):
        row = "  ".join(f"{k:+.6f}+-{e:.1g}" for k, e in zip(triad.sensitivity[i], triad.sensitivity_stderr[i]))
        table.add_row(axis, row, f"{triad.scale_factor_error[i] * 1e6:+.0f}", f"{triad.bias[i]:+.5g}")
    console.print(table)


def _describe_axis(ax) -> str:
    """An axis's model in words: curve, lag, hysteresis."""
    order = None if ax.temperature is None else ax.temperature.order
    model = "constant" if order is None else (f"poly order {order}" if isinstance(order, int) else order)
    if ax.lag_time_constant_s > 0:
        model += f", lag {ax.lag_time_constant_s:.3g} s"
    if ax.hysteresis is not None:
        model += f", hysteresis order {ax.hysteresis.order}"
        if ax.hysteresis.band_degc is not None:
            model += f" in {ax.hysteresis.band_degc[0]:g}..{ax.hysteresis.band_degc[1]:g} degC"
    return model


def _print_axis_fits(console, axes: dict, report: dict, title: str, unit: str) -> None:
    table = Table(title=title)
    for col in ("axis", "model", "range [degC]", f"fit RMS [{unit}]", f"constants [{unit}]"):
        table.add_column(col)
    for axis, ax in axes.items():
        info = report.get("axes", {}).get(axis, {})
        model = _describe_axis(ax)
        rng = "-" if ax.temperature is None else f"{ax.temperature.t_min_degc:.2f} .. {ax.temperature.t_max_degc:.2f}"
        rms = f"{info['fit_rms_dps']:.3g}" if "fit_rms_dps" in info else "-"
        constants = ax.turn_on_biases_dps
        shown = ", ".join(f"{c:+.4g}" for c in constants[:6]) + (f" ... ({len(constants)})" if len(constants) > 6 else "")
        table.add_row(axis, model, rng, rms, shown)
    console.print(table)
    net = report.get("network")
    if net:
        console.print(f"network: 1-{'-'.join(map(str, net['hidden']))}-1 tanh/linear, {net['restarts']} restarts "
                      f"(seed {net['seed']}), {net['training']}; validation RMS of the restarts [{unit}]: " + "; ".join(
                          f"{a} " + ", ".join(f"{v:.4g}" for v in info["validation_rmse_dps"])
                          for a, info in net["axes"].items()))
    scores = {a: i.get("scores") for a, i in report.get("axes", {}).items() if i.get("scores")}
    if net:
        scores = {}
    if scores:
        how = report.get("order_selection")
        unit_label = f"CV RMS [{unit}]" if how == "leave-one-run-out" else "BIC"
        st = Table(title=f"order selection by {how} ({unit_label}; lower is better)")
        st.add_column("axis")
        orders = sorted({int(p) for s in scores.values() for p in s})
        for p in orders:
            st.add_column(f"order {p}", justify="right")
        for axis, s in scores.items():
            chosen = axes[axis].temperature.order
            st.add_row(axis, *[(f"{s[str(p)]:.4g}*" if p == chosen else f"{s[str(p)]:.4g}")
                               if str(p) in s else "-" for p in orders])
        console.print(st)
    if report.get("selection"):
        _print_selection(console, report["selection"], unit)
        return _print_g_sensitivity(console, report)
    hyst = report.get("hysteresis", {})
    if hyst.get("axes") and any(len(a.get("scores_dps", a.get("scores_bic", {}))) > 1 for a in hyst["axes"].values()):
        bic = hyst["selection"] == "bic"
        ht = Table(title="hysteresis / thermal lag by " + ("BIC (lower is better)" if bic else
                   f"leave-one-run-out residual drift RMS [{unit}] (60 s moving average; lower is better)"))
        ht.add_column("axis")
        for name in CANDIDATES:
            ht.add_column(name, justify="right")
        ht.add_column("chosen")
        for axis, info in hyst["axes"].items():
            scores = info.get("scores_bic" if bic else "scores_dps", {})
            chosen = info["chosen"].split(" (")[0]
            cells = [("-" if scores.get(c) is None else f"{scores[c]:.4g}" + ("*" if c == chosen else ""))
                     if c in scores else "-" for c in CANDIDATES]
            ht.add_row(axis, *cells, info["chosen"])
        console.print(ht)
    _print_g_sensitivity(console, report)


def _score(value: float | None, spec: str = ".4g") -> str:
    """A held-out score for a table cell; '-' where the folds held too little data to compute it."""
    return "-" if value is None else format(value, spec)


def _print_selection(console, selection: dict, unit: str) -> None:
    """The model choice: per axis the chosen and best candidates against the run constant alone, then the fold
    scores of those three (every candidate's are in the model file)."""
    first = next(iter(selection.values()))
    table = Table(title=f"model choice by held-out drift ({first['fold_kind']}: {len(first['folds'])} folds, "
                        f"{first['window_s']:g} s moving average, simplest within one standard error) [{unit}]")
    for col in ("axis", "chosen", "held-out drift", "best", "best drift", "constant only"):
        table.add_column(col, justify="left" if col in ("axis", "chosen", "best") else "right")
    for axis, sel in selection.items():
        scores = {c["label"]: c for c in sel["candidates"]}
        chosen, best = scores[sel["chosen"]["label"]], scores[sel["best"]["label"]]
        table.add_row(axis, chosen["label"],
                      f"{_score(chosen['mean_drift_dps'])} +- {_score(chosen['standard_error_dps'], '.2g')}",
                      best["label"], _score(best["mean_drift_dps"]), _score(sel["raw_drift_dps"]))
    console.print(table)
    folds = Table(title=f"held-out drift per fold [{unit}]")
    folds.add_column("axis")
    folds.add_column("model")
    for name in first["folds"]:
        folds.add_column(name, justify="right")
    for axis, sel in selection.items():
        scores = {c["label"]: c for c in sel["candidates"]}
        shown = dict.fromkeys([sel["chosen"]["label"], sel["best"]["label"], "constant (time)"])
        for label in shown:
            folds.add_row(axis, label, *[_score(v) for v in scores[label]["fold_drift_dps"]])
    console.print(folds)


def _print_g_sensitivity(console, report: dict) -> None:
    acc = report.get("acceleration", {})
    if acc.get("axes"):
        gt = Table(title=f"g-sensitivity G [deg/s/g] +- standard error (cluster-robust over {sum(acc['static_segments'])} "
                         f"static segments; excited: {', '.join(acc['excited_axes']) or 'none'})")
        gt.add_column("gyro axis")
        for name in ("accel_x", "accel_y", "accel_z"):
            gt.add_column(name, justify="right")
        for axis, info in acc["axes"].items():
            cells = [f"{g:+.4g} +- {e:.2g}" if e is not None else "not fitted"
                     for g, e in zip(info["g_sensitivity_dps_per_g"], info["standard_error_dps_per_g"])]
            gt.add_row(axis, *cells)
        console.print(gt)


# -- apply ------------------------------------------------------------------------------------------
@click.command()
@click.argument("model", type=click.Path())
@click.argument("input_path", metavar="IN", type=click.Path())
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False), help="Compensated output file.")
@click.option("--turn-on-window", "turn_on_window_s", type=float, default=None,
              help="Estimate the turn-on bias from the first S seconds of IN [s] (default: the model's mean).")
@click.option("--axes", "axes", default=None, metavar="AXES",
              help="Gyro axes to compensate, e.g. gyro_z (default: all; data with an axis the model lacks is "
                   "refused unless the axes are named, and the others are then left raw).")
@read_options
@click.pass_context
def apply(ctx, model, input_path, output, turn_on_window_s, axes, **kwargs):
    """Compensate IN with MODEL: same columns and rows out, gyro columns compensated."""
    opts = _pop_read_options(kwargs)
    refuse_to_overwrite_inputs(output, [input_path, model])
    calibration = Calibration.load(model)
    in_fmt = detect_format(input_path, opts["fmt"]) if Path(input_path).exists() else None
    out_fmt = output_format(output, default=in_fmt)  # a bad output is refused before the work
    data = _read(input_path, opts)
    named = None if axes is None else tuple(a.strip() for a in axes.split(",") if a.strip())
    compensated = apply_calibration(calibration, data.recording, turn_on_window_s=turn_on_window_s, axes=named)
    accel = compensated.accel_g if calibration.accel_axes else None
    write_gyro_back(data, compensated.gyro_dps, output, fmt=out_fmt, accel_g=accel)
    if not ctx.obj["quiet"]:
        done = [a for a in data.recording.gyro_axes if a in calibration.axes and (named is None or a in named)]
        done += list(data.recording.accel_axes) if accel is not None else []
        click.echo(f"wrote {output}: {data.recording.n_samples} rows, {', '.join(done)} compensated")


# -- convert ----------------------------------------------------------------------------------------
@click.command()
@click.argument("input_path", metavar="IN", type=click.Path())
@click.argument("output", metavar="OUT", type=click.Path(dir_okay=False))
@read_options
@click.pass_context
def convert(ctx, input_path, output, **kwargs):
    """Write IN (any format gyrocomp reads) as the canonical CSV or Parquet table OUT.

    Columns: time [s], gyro_x/y/z [deg/s], accel_x/y/z [g], temperature [degC].
    """
    opts = _pop_read_options(kwargs)
    refuse_to_overwrite_inputs(output, [input_path], option="OUT")
    out_fmt = output_format(output, option="OUT")
    recording = _read(input_path, opts).recording
    write_recording(recording, output, fmt=out_fmt)
    if not ctx.obj["quiet"]:
        channels = [*recording.gyro_axes, *recording.accel_axes, *recording.temperature_columns]
        gaps = f", {len(recording.gaps)} time gap(s)" if recording.gaps else ""
        click.echo(f"wrote {output}: {recording.n_samples} rows, {recording.duration_s:.6g} s at "
                   f"{recording.rate_hz:.6g} Hz{gaps}; {', '.join(channels)}")


# -- validate ---------------------------------------------------------------------------------------
@click.command()
@click.argument("runs", nargs=-1, required=True, type=click.Path())
@click.option("--folds", type=click.Choice(FOLD_KINDS), default="auto", show_default=True,
              help="Hold out each run, each heating or cooling leg, or time blocks; auto: runs with three runs "
                   "or more, else legs.")
@click.option("--window", "window_s", type=float, default=None,
              help="Moving-average window of the drift [s] (default: a tenth of the median fold, 60..600 s).")
@click.option("--candidate", "candidates", multiple=True, metavar="SPEC",
              help="Also validate gyrocomp fitted with --temperature SPEC (poly:N, poly, mlp); repeatable.")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON on stdout.")
@read_options
@click.pass_context
def validate(ctx, runs, folds, window_s, candidates, as_json, **kwargs):
    """Held-out drift on RUNS of raw, PX4's cubic, ArduPilot's cubic, a plain cubic and gyrocomp's default.

    Each method is fitted without the fold it is scored on (leave one run out, or one heating or cooling leg
    with fewer than three runs); the score is the RMS of the moving-averaged compensated output about its mean.
    """
    opts = _pop_read_options(kwargs)
    if window_s is not None and not window_s > 0:
        raise click.BadParameter(f"must be positive, got {window_s:g}", param_hint="--window")
    named = {}
    for spec in candidates:
        order = parse_temperature_option(spec)
        if order is None:
            raise click.BadParameter("a candidate needs a temperature model (poly, poly:N or mlp)",
                                     param_hint="--candidate")
        named[f"gyrocomp {spec}"] = {"temperature": order}
    recordings = [_read(path, opts).recording for path in runs]
    with progress_bar("validating", indeterminate=True):
        result = validate_runs(recordings, folds=folds, window_s=window_s, candidates=named)
    if as_json:
        click.echo(json.dumps(result.to_dict(), indent=2))
    elif not ctx.obj["quiet"]:
        print_validation(result)


def print_validation(result: ValidationResult) -> None:
    console = _console()
    table = Table(title=result.title)
    header, rows = result.table_rows()
    table.add_column(header[0])
    for column in header[1:]:
        table.add_column(column, justify="right")
    for row in rows:
        table.add_row(*row)
    console.print(table)
    console.print("folds: " + ", ".join(result.folds))


# -- evaluate ---------------------------------------------------------------------------------------
@click.command()
@click.argument("paths", nargs=-1, required=True, type=click.Path(), metavar="MODEL RUNS... | --compare RUNS...")
@click.option("--window", "window_s", type=float, default=None,
              help="Moving-average window [s] (default: tau at the raw Allan minimum, at least 1 s).")
@click.option("--turn-on-window", "turn_on_window_s", type=float, default=None,
              help="Estimate each run's turn-on bias from its first S seconds [s].")
@click.option("--compare", is_flag=True,
              help="The thesis's comparison on RUNS: raw, polynomial, network, each with and without hysteresis "
                   "(leave one run out with two runs or more).")
@click.option("--hysteresis-band", "hysteresis_band", default=None, metavar="LO,HI",
              help="With --compare: limit the hysteresis to this band [degC].")
@click.option("--stages", is_flag=True,
              help="Report each stage of MODEL (the thesis's Table 4.4): raw, temperature only, + acceleration, "
                   "+ hysteresis.")
@click.option("--json", "as_json", is_flag=True, help="Print the figures as JSON on stdout.")
@click.option("--rate-schedule", "rate_schedule", type=click.Path(), default=None, metavar="FILE",
              help="A rate table's schedule for the RUNS it names (as for fit): adds their rate error.")
@read_options
@click.pass_context
def evaluate(ctx, paths, window_s, turn_on_window_s, compare, hysteresis_band, stages, as_json, rate_schedule, **kwargs):
    """Bias offset, bias instability and integration time of RUNS, raw and compensated with MODEL.

    With --compare, no model is given: the methods of the reference thesis are fitted on the runs and compared.
    """
    opts = _pop_read_options(kwargs)
    if window_s is not None and not window_s > 0:
        raise click.BadParameter(f"must be positive, got {window_s:g}", param_hint="--window")
    if compare:

        band = _float_list(hysteresis_band, "--hysteresis-band")
        if band is not None and (len(band) != 2 or not band[0] < band[1]):
            raise click.BadParameter("give LO,HI in degC with LO < HI, e.g. 55,80", param_hint="--hysteresis-band")
        recordings = [_read(path, opts).recording for path in paths]
        result = compare_methods(recordings, window_s=window_s, hysteresis_band_degc=band)
        if as_json:
            click.echo(json.dumps(result.to_dict(), indent=2))
        elif not ctx.obj["quiet"]:
            print_comparison(result)
        return
    if len(paths) < 2:
        raise click.UsageError("give MODEL and at least one run, or --compare RUNS...")
    model, runs = paths[0], paths[1:]
    calibration = Calibration.load(model)
    if stages:
        if not calibration.axes:
            raise InputError(f"--stages: {model} has no gyro axes (an accelerometer-only model has one stage); "
                             "evaluate it without --stages")
        staged = [evaluate_stages(calibration, _read(path, opts).recording, window_s=window_s,
                                  turn_on_window_s=turn_on_window_s) for path in runs]
        if as_json:
            click.echo(json.dumps({"runs": [s.to_dict() for s in staged]}, indent=2))
        elif not ctx.obj["quiet"]:
            print_stages(staged)
        return
    recordings = [_read(path, opts).recording for path in runs]
    if rate_schedule is not None:
        recordings = apply_schedule(read_rate_schedule(rate_schedule), recordings, list(runs))
    evaluation = evaluate_calibration(calibration, recordings, window_s=window_s, turn_on_window_s=turn_on_window_s)
    if as_json:
        click.echo(json.dumps(evaluation.to_dict(), indent=2))
    else:
        print_evaluation(evaluation)


def _figures_table(title: str, what: str) -> Table:
    """A table of the thesis's figures per axis and ``what`` (stage, method)."""
    table = Table(title=title)
    for col in ("axis", what):
        table.add_column(col, no_wrap=True)
    for col in ("bias offset\n[deg/s]", f"improvement\n(raw/{what})", "bias instability\n[deg/h]",
                "integration time\n[s]"):
        table.add_column(col, justify="right")
    return table


def print_stages(staged) -> None:
    console = _console()
    for run in staged:
        table = _figures_table(f"{Path(run.file).name}: stages of the compensation (window {run.window_s:.4g} s)",
                               "stage")
        first = next(iter(run.stages.values()))
        for axis in first:
            m0 = first[axis]
            table.add_row(axis, "raw", f"{m0.bias_offset_raw_dps:.4g}", "1x", f"{m0.bias_instability_raw_dph:.4g}",
                          f"{m0.integration_time_raw_s:.4g}")
            for name, axes in run.stages.items():
                m = axes[axis]
                table.add_row("", name, f"{m.bias_offset_comp_dps:.4g}", f"{m.offset_improvement:.3g}x",
                              f"{m.bias_instability_comp_dph:.4g}", f"{m.integration_time_comp_s:.4g}")
        console.print(table)


def print_comparison(result) -> None:
    console = _console()
    table = _figures_table(f"methods compared ({result.how})", "method")
    for row in result.rows:
        table.add_row(row.axis, row.method, f"{row.bias_offset_dps:.4g}", f"{row.improvement:.3g}x",
                      f"{row.bias_instability_deg_per_h:.4g}", f"{row.integration_time_s:.4g}")
    console.print(table)


def _metrics_table(title: str, evaluation: Evaluation, rows_of, unit: str, bi_unit: str, suffix: str) -> Table:
    """One table of raw and compensated figures; ``rows_of(run)`` gives (axis, metrics) pairs whose field
    names end in ``suffix`` (``dps``/``dph`` for the gyro, ``g``/``ug`` for the accelerometer)."""
    table = Table(title=title)
    table.add_column("run", no_wrap=True)
    table.add_column("axis", no_wrap=True)
    for col in ("window\n[s]", f"offset raw\n[{unit}]", f"offset comp\n[{unit}]", "improvement\n(raw/comp)",
                f"BI raw\n[{bi_unit}]", f"BI comp\n[{bi_unit}]", "int. time raw\n[s]", "int. time comp\n[s]",
                f"residual RMS\n[{unit}]"):
        table.add_column(col, justify="right")
    value, bi = suffix.split("/")
    for run in evaluation.runs:
        for axis, m in rows_of(run):
            get = lambda name: getattr(m, name)  # noqa: E731
            table.add_row(Path(run.file).name, axis, f"{run.window_s:.4g}", f"{get('bias_offset_raw_' + value):.4g}",
                          f"{get('bias_offset_comp_' + value):.4g}", f"{m.offset_improvement:.3g}x",
                          f"{get('bias_instability_raw_' + bi):.4g}", f"{get('bias_instability_comp_' + bi):.4g}",
                          f"{m.integration_time_raw_s:.4g}", f"{m.integration_time_comp_s:.4g}",
                          f"{get('residual_rms_' + value):.3g}")
    return table


def print_evaluation(evaluation: Evaluation, title: str = "gyrocomp evaluate") -> None:
    console = _console()
    console.print(_metrics_table(title, evaluation, lambda run: run.axes.items(), "deg/s", "deg/h", "dps/dph"))
    if any(run.accel_axes for run in evaluation.runs):
        console.print(_metrics_table(f"{title}: accelerometer", evaluation, lambda run: run.accel_axes.items(),
                                     "g", "ug", "g/ug"))
    if evaluation.triads:
        table = Table(title=f"{title}: scale factor and misalignment (RMS over the run's poses, turns or stretches)")
        for col in ("run", "figure", "count", "raw", "compensated", "improvement"):
            table.add_column(col, justify="left" if col in ("run", "figure") else "right")
        for t in evaluation.triads:
            label, scale, unit = _TRIAD_FIGURES[t.figure]
            table.add_row(Path(t.file).name, label, str(t.raw.size), f"{t.rms_raw * scale:.3g} {unit}",
                          f"{t.rms_compensated * scale:.3g} {unit}",
                          f"{t.rms_raw / t.rms_compensated:.3g}x" if t.rms_compensated > 0 else "-")
        console.print(table)


#: how ``evaluate`` prints each scale-factor figure: label, factor to the printed unit, unit
_TRIAD_FIGURES = {"pose_norm_g": ("|a| - 1 g at each still pose", 1e3, "mg"),
                  "turn_direction_deg": ("gravity direction after each turn", 1.0, "deg"),
                  "rate_error_dps": ("rate error on each rate-table stretch", 1.0, "deg/s")}


# -- allan -------------------------------------------------------------------------------------------
def _parse_taus(text: str):
    if text in ("octave", "decade", "all"):
        return text
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        values = []
    if not values or min(values) <= 0:
        raise click.BadParameter("use octave, decade, all or a comma-separated list of taus [s], e.g. 1,10,100",
                                 param_hint="--taus")
    return values


def _parse_fit_taus(text: str | None):
    if text is None:
        return None
    try:
        low, high = (float(v) for v in text.split(","))
    except ValueError:
        low = high = -1.0
    if not 0 < low < high:
        raise click.BadParameter("use MIN,MAX in seconds with 0 < MIN < MAX, e.g. 3,1000", param_hint="--fit-taus")
    return low, high


#: RMS misfit (in ln deviation) of the noise model beyond which ``gyrocomp allan`` warns
POOR_FIT_LOG_RESIDUAL = 0.25


@click.command()
@click.argument("input_path", metavar="FILE", type=click.Path())
@click.option("--axes", "axes", default=None, help="Columns to analyse, e.g. gyro_x,gyro_z,accel_z (default: every gyro axis).")
@click.option("--kind", type=click.Choice(KINDS), default="oadev", show_default=True, help="Estimator of the printed curve.")
@click.option("--taus", default="octave", show_default=True, help="octave, decade, all, or taus [s] such as 1,10,100.")
@click.option("--json", "as_json", is_flag=True, help="Print curves and noise terms as JSON on stdout.")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False), help="Write the Allan plot here (.png, .svg, .pdf).")
@click.option("--kalibr", "kalibr_path", type=click.Path(dir_okay=False), help="Write Kalibr's imu.yaml here.")
@click.option("--rostopic", default="/imu0", show_default=True, help="rostopic written into the Kalibr file.")
@click.option("--split-gaps", is_flag=True, help="Pool the contiguous stretches of a log with time gaps instead of refusing it.")
@click.option("--fit-taus", "fit_taus", default=None, metavar="MIN,MAX",
              help="Fit the noise model on taus in [MIN, MAX] s only, e.g. 3,1000 past an anti-alias filter.")
@read_options
@click.pass_context
def allan(ctx, input_path, axes, kind, taus, as_json, plot_path, kalibr_path, rostopic, split_gaps, fit_taus,
          **kwargs):
    """Allan deviation with 68 % intervals and IEEE 952 noise terms (N, B, K, Q, R) of each axis of FILE."""
    opts = _pop_read_options(kwargs)
    tau_spec = _parse_taus(taus)
    fit_range = _parse_fit_taus(fit_taus)
    for option, path in (("--plot", plot_path), ("--kalibr", kalibr_path)):
        if path:
            refuse_to_overwrite_inputs(path, [input_path], option=option)
    if plot_path:
        check_figure_path(plot_path)
    with warnings.catch_warnings():
        # gaps are refused below, or split with a note, in one line of their own
        warnings.filterwarnings("ignore", message=r".*time gap\(s\) longer than", category=DataQualityWarning)
        recording = _read(input_path, opts).recording
    names = [a.strip() for a in axes.split(",") if a.strip()] if axes else list(recording.gyro_axes)
    if kalibr_path:
        names += [a for a in recording.accel_axes if a not in names]
    with progress_bar("Allan deviation", indeterminate=True):
        analysis = analyse_noise(recording, names, kind=kind, taus=tau_spec, split_gaps=split_gaps,
                                 fit_taus_s=fit_range)
    if analysis.how and not ctx.obj["quiet"]:
        click.echo(f"gyrocomp: note: {analysis.how}", err=True)
    for name, a in analysis.axes.items():
        if a.terms.fit_rms_log_residual > POOR_FIT_LOG_RESIDUAL:
            warnings.warn(f"{name}: the five-term noise model misses the curve by {a.terms.fit_rms_log_residual:.0%} "
                          "RMS; compare the read-offs, or restrict the fit with --fit-taus", DataQualityWarning)
    if kalibr_path:
        write_text_atomic(kalibr_path, kalibr_imu_yaml(kalibr_imu(analysis, rostopic)))
    if plot_path:
        allan_figure(analysis, plot_path)
    if as_json:
        click.echo(json.dumps(analysis.to_dict(), indent=2))
    elif not ctx.obj["quiet"]:
        print_noise(analysis)


def print_noise(analysis: NoiseAnalysis) -> None:
    console = _console()
    for name, a in analysis.axes.items():
        c = a.curve
        table = Table(title=f"{Path(analysis.source).name}: {name} {c.kind.upper()} [{a.unit}]")
        for col in ("tau [s]", "deviation", "ci low", "ci high", "n", "alpha"):
            table.add_column(col, justify="right")
        for row in zip(c.tau, c.deviation, c.ci_low, c.ci_high, c.n, c.alpha):
            table.add_row(f"{row[0]:.6g}", f"{row[1]:.5g}", f"{row[2]:.5g}", f"{row[3]:.5g}", f"{row[4]:d}",
                          "-" if np.isnan(row[5]) else f"{row[5]:+.0f}")
        console.print(table)
    table = Table(title="noise terms (IEEE Std 952 fit; B = Allan minimum / 0.664)")
    table.add_column("axis", no_wrap=True)
    table.add_column("term")
    table.add_column("value", justify="right")
    table.add_column("read-off", justify="right")
    for name, a in analysis.axes.items():
        n = a.noise
        if a.sensor == "gyro":
            rows = [("N [deg/s/sqrt(Hz)]", n.noise_density_dps_per_sqrt_hz, n.noise_density_readoff_dps_per_sqrt_hz),
                    ("ARW [deg/sqrt(h)]", n.arw_deg_per_sqrt_h, None),
                    ("B [deg/h]", n.bias_instability_deg_per_h, None),
                    ("integration time [s]", n.integration_time_s, None),
                    ("K [deg/h/sqrt(h)]", n.rrw_deg_per_h_per_sqrt_h, n.rrw_readoff_deg_per_h_per_sqrt_h),
                    ("Q [deg]", n.quantization_deg, None),
                    ("R [deg/h^2]", n.rate_ramp_deg_per_h2, None)]
        else:
            rows = [("N [g/sqrt(Hz)]", n.noise_density_g_per_sqrt_hz, n.noise_density_readoff_g_per_sqrt_hz),
                    ("VRW [m/s/sqrt(h)]", n.vrw_m_per_s_per_sqrt_h, None),
                    ("B [micro-g]", n.bias_instability_micro_g, None),
                    ("integration time [s]", n.integration_time_s, None),
                    ("K [m/s^3/sqrt(Hz)]", n.random_walk_m_per_s3_per_sqrt_hz, n.random_walk_readoff_m_per_s3_per_sqrt_hz),
                    ("Q [m/s]", n.quantization_m_per_s, None),
                    ("R [m/s^3]", n.ramp_m_per_s3, None)]
        for i, (term, value, readoff) in enumerate(rows):
            table.add_row(name if i == 0 else "", term, f"{value:.4g}", "" if readoff is None else f"{readoff:.4g}")
        if not n.floor_reached:
            table.add_row("", "(no floor: B is an upper bound)", "", "")
    console.print(table)


# -- export -----------------------------------------------------------------------------------------
EXPORT_FORMATS = ("px4", "ardupilot", "c")


@click.command()
@click.argument("model", type=click.Path())
@click.option("--format", "fmt", type=click.Choice(EXPORT_FORMATS), required=True,
              help="px4 (TC_G* parameters, QGroundControl .params), ardupilot (INS_TCAL* parameters), "
                   "or c (the whole model as C99: gyrocomp.h and gyrocomp.c in the folder -o).")
@click.option("-o", "--output", required=True, type=click.Path(), help="Parameter file to write (c: a folder).")
@click.option("--rate", "rate_hz", type=float, default=None,
              help="c: the sample rate the code will run at [Hz] (needed when the model has thermal lag).")
@click.option("--instance", type=int, default=None, help="Sensor instance: PX4 gyro 0..3 (default 0), ArduPilot IMU 1..3 "
                                                       "(default 1).")
@click.option("--device-id", type=int, default=0, show_default=True, help="PX4: the gyro's device id (TC_G*_ID).")
@click.pass_context
def export(ctx, model, fmt, output, rate_hz, instance, device_id):
    """Write MODEL as autopilot parameters (temperature cubic, accelerometer offsets and scales) or as C code."""

    refuse_to_overwrite_inputs(output, [model])
    calibration = Calibration.load(model)
    if fmt == "c":

        written = write_c_sources(calibration, output, rate_hz=rate_hz)
        if not ctx.obj["quiet"]:
            click.echo("wrote " + " and ".join(str(p) for p in written))
        return
    if fmt == "px4":
        text = px4_params_file(calibration, instance=0 if instance is None else instance, device_id=device_id)
    else:
        text = ardupilot_params_file(calibration, instance=1 if instance is None else instance)
    write_text_atomic(output, text)
    if not ctx.obj["quiet"]:
        click.echo(f"wrote {output}")
        for line in text.splitlines()[1:]:
            if not line.startswith("#"):
                break
            click.echo(line.lstrip("# "))


# -- report and plot --------------------------------------------------------------------------------
@click.command()
@click.argument("model", type=click.Path())
@click.argument("runs", nargs=-1, required=True, type=click.Path())
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False), help="The HTML file to write.")
@click.option("--window", "window_s", type=float, default=None,
              help="Moving-average window [s] (default: tau at the raw Allan minimum, at least 1 s).")
@click.option("--turn-on-window", "turn_on_window_s", type=float, default=None,
              help="Estimate each run's turn-on bias from its first S seconds [s].")
@click.option("--min-static", "static_min_duration_s", type=float, default=10.0, show_default=True,
              help="Shortest still stretch drawn as a static position [s].")
@click.option("--validate-on", "validate_on", multiple=True, type=click.Path(),
              help="A calibration run to validate on (repeat it for each run): adds the table of gyrocomp validate.")
@read_options
@click.pass_context
def report(ctx, model, runs, output, window_s, turn_on_window_s, static_min_duration_s, validate_on, **kwargs):
    """One self-contained HTML report of MODEL judged on RUNS: the model, the figures of merit, bias against
    temperature, raw and compensated series, Allan deviations, g-sensitivity; with --validate-on, the held-out
    drift of each method on those calibration runs."""


    opts = _pop_read_options(kwargs)
    refuse_to_overwrite_inputs(output, [model, *runs, *validate_on])
    if not str(output).lower().endswith((".html", ".htm")):
        raise click.BadParameter(f"{output}: name the report .html", param_hint="-o")
    if window_s is not None and not window_s > 0:
        raise click.BadParameter(f"must be positive, got {window_s:g}", param_hint="--window")
    require_matplotlib()
    calibration = Calibration.load(model)
    recordings = [_read(path, opts).recording for path in runs]
    validation = None
    if validate_on:
        with progress_bar("validating", indeterminate=True):
            validation = validate_runs([_read(path, opts).recording for path in validate_on])
    with progress_bar("report") as progress:
        result = build_report(calibration, recordings, window_s=window_s, turn_on_window_s=turn_on_window_s,
                              min_static_s=static_min_duration_s, progress=progress, validation=validation)
    write_text_atomic(output, result.html)
    if not ctx.obj["quiet"]:
        click.echo(f"wrote {output}: {len(result.html) / 1e6:.2f} MB, sections {', '.join(result.sections)}")


@click.group()
def plot():
    """Single figures as PNG, SVG or PDF (from the suffix of -o)."""


def _figure_output(output, inputs) -> None:

    check_figure_path(output)
    refuse_to_overwrite_inputs(output, inputs)
    require_matplotlib()


def _compensated(model, runs, opts, turn_on_window_s):
    calibration = Calibration.load(model)
    recordings = [_read(path, opts).recording for path in runs]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TemperatureRangeWarning)
        comps = [apply_calibration(calibration, rec, turn_on_window_s=turn_on_window_s) for rec in recordings]
    return calibration, recordings, comps


def _axis_option(axis, calibration, recording) -> str:
    known = [a for a in recording.gyro_axes if a in calibration.axes]
    known += [a for a in calibration.accel_axes if a in recording.accel_axes]
    if axis is None:
        if not known:
            raise InputError(f"{recording.source}: no axis of the model in the data")
        return known[0]
    if axis not in known:
        raise click.BadParameter(f"{axis!r}: the model and the data share {', '.join(known) or 'no axis'}",
                                 param_hint="--axis")
    return axis


@plot.command("allan")
@click.argument("input_path", metavar="FILE", type=click.Path())
@click.option("--model", type=click.Path(), default=None, help="Also draw FILE compensated with this model.")
@click.option("--axes", default=None, help="Axes to draw, e.g. gyro_x,gyro_z (default: every gyro axis).")
@click.option("--split-gaps", is_flag=True, help="Pool the stretches between time gaps.")
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False))
@read_options
@click.pass_context
def plot_allan(ctx, input_path, model, axes, split_gaps, output, **kwargs):
    """Allan deviation of FILE (and of FILE compensated with --model) with intervals and slope lines."""

    opts = _pop_read_options(kwargs)
    _figure_output(output, [input_path] + ([model] if model else []))
    with warnings.catch_warnings():
        # gaps are refused below, or split with a note, in one line of their own
        warnings.filterwarnings("ignore", message=r".*time gap\(s\) longer than", category=DataQualityWarning)
        recording = _read(input_path, opts).recording
    names = [a.strip() for a in axes.split(",") if a.strip()] if axes else list(recording.gyro_axes)
    analyses = {"raw": analyse_noise(recording, names, split_gaps=split_gaps)}
    if model:
        _, _, (comp,) = _compensated(model, [input_path], opts, None)
        analyses["compensated"] = analyse_noise(comp, names, split_gaps=split_gaps)
    save_figure(allan_plot(analyses, title=f"Allan deviation: {Path(input_path).name}"), output)
    if not ctx.obj["quiet"]:
        click.echo(f"wrote {output}")


@plot.command("temperature")
@click.argument("model", type=click.Path())
@click.argument("runs", nargs=-1, required=True, type=click.Path())
@click.option("--axis", default=None, help="The axis to draw (default: the model's first).")
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False))
@read_options
@click.pass_context
def plot_temperature(ctx, model, runs, axis, output, **kwargs):
    """Bias against temperature of RUNS (heating and cooling branches), MODEL's correction, the residual."""

    opts = _pop_read_options(kwargs)
    _figure_output(output, [model, *runs])
    calibration, recordings, comps = _compensated(model, runs, opts, None)
    if any(rec.temperature_degc is None for rec in recordings):
        raise InputError("plot temperature: every run needs a temperature column")
    axis = _axis_option(axis, calibration, recordings[0])
    save_figure(temperature_plot(recordings, comps, axis, "g" if axis.startswith("accel") else "deg/s"), output)
    if not ctx.obj["quiet"]:
        click.echo(f"wrote {output}")


@plot.command("timeseries")
@click.argument("model", type=click.Path())
@click.argument("run", type=click.Path())
@click.option("--axis", default=None, help="The axis to draw (default: the model's first).")
@click.option("--window", "window_s", type=float, default=None,
              help="Moving-average window [s] (default: tau at the raw Allan minimum, at least 1 s).")
@click.option("--turn-on-window", "turn_on_window_s", type=float, default=None,
              help="Estimate the run's turn-on bias from its first S seconds [s].")
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False))
@read_options
@click.pass_context
def plot_timeseries(ctx, model, run, axis, window_s, turn_on_window_s, output, **kwargs):
    """Raw and compensated output of RUN against time, with moving averages and the temperature."""

    opts = _pop_read_options(kwargs)
    _figure_output(output, [model, run])
    calibration, (recording,), (comp,) = _compensated(model, [run], opts, turn_on_window_s)
    axis = _axis_option(axis, calibration, recording)
    window = window_s or default_window_s(recording)
    save_figure(timeseries_plot(recording, comp, axis, window, "g" if axis.startswith("accel") else "deg/s",
                                title=f"{axis}: {Path(run).name}"), output)
    if not ctx.obj["quiet"]:
        click.echo(f"wrote {output}")


# -- demo -------------------------------------------------------------------------------------------
@click.command()
@click.option("-o", "--output", "out_dir", default="gyrocomp-demo", show_default=True,
              type=click.Path(file_okay=False), help="Folder for the demo's files.")
@click.pass_context
def demo(ctx, out_dir):
    """The main job on built-in simulated data: fit on chamber runs, compensate a held-out run, score it,
    and write the HTML report."""

    result = run_demo(Path(out_dir))
    if result.report_skipped:
        click.echo(f"gyrocomp: note: no report.html: {result.report_skipped}", err=True)
    if not ctx.obj["quiet"]:
        console = _console()
        console.print(result.summary)
        print_validation(result.validation)
        print_evaluation(result.evaluation, title="held-out run, raw vs compensated")
        console.print(f"files in {out_dir}/: " + ", ".join(sorted(p.name for p in Path(out_dir).iterdir())))
