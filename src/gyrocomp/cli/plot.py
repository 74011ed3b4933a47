"""``gyrocomp plot``: parse its options, call the library, print the result."""

from __future__ import annotations

import warnings
from pathlib import Path

import click

from ..calibration import Calibration
from ..calibration.compensate import apply as apply_calibration
from ..errors import DataQualityWarning, InputError, TemperatureRangeWarning
from ..io import refuse_to_overwrite_inputs
from ..measures.merit import default_window_s
from ..report.figures import allan_plot, require_matplotlib, save_figure, temperature_plot, timeseries_plot
from ..measures.noise import analyse_noise
from ..report.figures import check_figure_path
from .common import OUTPUT_FILE, pop_read_options, read_options, read_run, turn_on_window_option, window_option, echo


@click.group()
def plot():
    """Single figures as PNG, SVG or PDF (from the suffix of -o)."""


def _figure_output(output, inputs) -> None:

    check_figure_path(output)
    refuse_to_overwrite_inputs(output, inputs)
    require_matplotlib()


def _compensated(model, runs, opts, turn_on_window_s):
    calibration = Calibration.load(model)
    recordings = [read_run(path, opts).recording for path in runs]
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
        raise click.BadParameter(
            f"{axis!r}: the model and the data share {', '.join(known) or 'no axis'}", param_hint="--axis"
        )
    return axis


@plot.command("allan")
@click.argument("input_path", metavar="FILE", type=click.Path())
@click.option("--model", type=click.Path(), default=None, help="Also draw FILE compensated with this model.")
@click.option("--axes", default=None, help="Axes to draw, e.g. gyro_x,gyro_z (default: every gyro axis).")
@click.option("--split-gaps/--no-split-gaps", default=False, help="Pool the stretches between time gaps.")
@click.option("-o", "--output", required=True, type=OUTPUT_FILE)
@read_options
@click.pass_context
def plot_allan(ctx, input_path, model, axes, split_gaps, output, **kwargs):
    """Allan deviation of FILE (and of FILE compensated with --model) with intervals and slope lines."""

    opts = pop_read_options(kwargs)
    _figure_output(output, [input_path] + ([model] if model else []))
    with warnings.catch_warnings():
        # gaps are refused below, or split with a note, in one line of their own
        warnings.filterwarnings("ignore", message=r".*time gap\(s\) longer than", category=DataQualityWarning)
        recording = read_run(input_path, opts).recording
    names = [a.strip() for a in axes.split(",") if a.strip()] if axes else list(recording.gyro_axes)
    analyses = {"raw": analyse_noise(recording, names, split_gaps=split_gaps)}
    if model:
        _, _, (comp,) = _compensated(model, [input_path], opts, None)
        analyses["compensated"] = analyse_noise(comp, names, split_gaps=split_gaps, motion_check=False)  # said raw
    save_figure(allan_plot(analyses, title=f"Allan deviation: {Path(input_path).name}"), output)
    if not ctx.obj["quiet"]:
        echo(f"wrote {output}")


@plot.command("temperature")
@click.argument("model", type=click.Path())
@click.argument("runs", nargs=-1, required=True, type=click.Path())
@click.option("--axis", default=None, help="The axis to draw (default: the model's first).")
@click.option("-o", "--output", required=True, type=OUTPUT_FILE)
@read_options
@click.pass_context
def plot_temperature(ctx, model, runs, axis, output, **kwargs):
    """Bias against temperature of RUNS (heating and cooling branches), MODEL's correction, the residual."""

    opts = pop_read_options(kwargs)
    _figure_output(output, [model, *runs])
    calibration, recordings, comps = _compensated(model, runs, opts, None)
    if any(rec.temperature_degc is None for rec in recordings):
        raise InputError("plot temperature: every run needs a temperature column")
    axis = _axis_option(axis, calibration, recordings[0])
    save_figure(temperature_plot(recordings, comps, axis, "g" if axis.startswith("accel") else "deg/s"), output)
    if not ctx.obj["quiet"]:
        echo(f"wrote {output}")


@plot.command("timeseries")
@click.argument("model", type=click.Path())
@click.argument("run", type=click.Path())
@click.option("--axis", default=None, help="The axis to draw (default: the model's first).")
@window_option()
@turn_on_window_option("the run's")
@click.option("-o", "--output", required=True, type=OUTPUT_FILE)
@read_options
@click.pass_context
def plot_timeseries(ctx, model, run, axis, window_s, turn_on_window_s, output, **kwargs):
    """Raw and compensated output of RUN against time, with moving averages and the temperature."""

    opts = pop_read_options(kwargs)
    _figure_output(output, [model, run])
    calibration, (recording,), (comp,) = _compensated(model, [run], opts, turn_on_window_s)
    axis = _axis_option(axis, calibration, recording)
    window = window_s or default_window_s(recording)
    save_figure(
        timeseries_plot(
            recording,
            comp,
            axis,
            window,
            "g" if axis.startswith("accel") else "deg/s",
            title=f"{axis}: {Path(run).name}",
        ),
        output,
    )
    if not ctx.obj["quiet"]:
        echo(f"wrote {output}")


__all__ = ["plot", "plot_allan", "plot_temperature", "plot_timeseries"]
