"""``gyrocomp noise``: parse its options, call the library, print the noise model or write an export."""

from __future__ import annotations

from pathlib import Path

import click
from rich.table import Table

from ..calibration import Calibration
from ..evaluation.bias_process_noise import compensated_noise
from ..export.estimator_noise import NOISE_EXPORTS
from ..files.noise_file import analyse_noise_file
from ..io import refuse_to_overwrite_inputs, write_text_atomic
from ..io.inputs import expand_runs
from ..measures.noise_model import NoiseModel, noise_model, noise_over_temperature
from .common import OUTPUT_FILE, make_console, pop_read_options, progress_bar, read_options, read_run, read_settings


@click.command()
@click.argument("logs", nargs=-1, required=True, type=click.Path())
@click.option("--export", "export_format", type=click.Choice(tuple(NOISE_EXPORTS)), default=None,
              help="Write the model for an estimator: kalibr (imu.yaml), openvins (kalibr_imu_chain.yaml), vins "
                   "(acc_n, gyr_n, acc_w, gyr_w), ros (sensor_msgs/Imu covariances), px4 (EKF2_*_NOISE, .params), "
                   "ardupilot (EK3_*_P_NSE, .parm) or json (the whole model).")
@click.option("-o", "--output", type=OUTPUT_FILE, default=None, help="The file --export writes.")
@click.option("--rostopic", default="/imu0", show_default=True, help="The IMU topic written into the export.")
@click.option("--axes", "axes", default=None,
              help="Columns to model, e.g. gyro_x,gyro_z,accel_z (default: every gyro and accelerometer axis).")
@click.option("--split-gaps/--no-split-gaps", default=False,
              help="Pool the contiguous stretches of a log with time gaps instead of refusing it.")
@click.option("--model", "model_path", type=click.Path(dir_okay=False), default=None,
              help="A model file: the logs are static runs through a temperature profile, held out from its fit; "
                   "say the bias random walk a filter needs with the raw and the compensated gyro, and model (and "
                   "export) the compensated gyro's noise.")
@click.option("--dwells", is_flag=True,
              help="Each log is a chamber run: model the noise of each of its temperature dwells (the first 300 s "
                   "of each left out, at least 600 s kept) and bound them all, with the per-temperature table.")
@read_options
@click.pass_context
def noise(ctx, logs, export_format, output, rostopic, axes, split_gaps, model_path, dwells, **kwargs):
    """Noise model of static LOGS for an estimator: white noise and random walk (and Gauss-Markov terms) whose Allan
    deviation is at or above the upper end of every log's 95 % interval at every averaging time, beside the IEEE
    952 fit."""
    opts = pop_read_options(kwargs)
    if (export_format is None) != (output is None):
        raise click.BadParameter("give --export and -o together",
                                 param_hint="--export" if export_format is None else "-o")
    paths = expand_runs(logs)
    if output is not None:
        refuse_to_overwrite_inputs(output, paths + ([model_path] if model_path else []), option="-o")
    named = [a.strip() for a in axes.split(",") if a.strip()] if axes else None
    benefit = None
    if model_path is not None:
        if dwells:
            raise click.BadParameter("give --model or --dwells, not both", param_hint="--model")
        model, benefit = compensated_noise(Calibration.load(model_path), [read_run(path, opts).recording
                                                                          for path in paths],
                                           named, with_accel=named is None, split_gaps=split_gaps)
    elif dwells:
        model = noise_over_temperature([read_run(path, opts).recording for path in paths], named,
                                       with_accel=named is None)
    else:
        analyses = []
        for path in paths:
            with progress_bar(f"reading {Path(path).name}") as progress:
                analyses.append(analyse_noise_file(path, named, options=read_settings(opts), fmt=opts["fmt"],
                                                   with_accel=named is None, split_gaps=split_gaps,
                                                   progress=progress))
        model = noise_model(analyses)
    if export_format is not None:
        write_text_atomic(output, NOISE_EXPORTS[export_format](model, rostopic))
    if not ctx.obj["quiet"]:
        print_noise_model(model)
        if benefit is not None:
            print_bias_process_noise(benefit)
        if export_format is not None:
            click.echo(f"wrote {output} ({export_format})")


def print_noise_model(model: NoiseModel) -> None:
    """Per axis: the IEEE 952 fit beside the two bounds, and each log's own bound."""
    console = make_console()
    table = Table(title=f"noise model at {model.rate_hz:g} Hz: at or above the measured Allan deviation's upper "
                        "95 % interval (ratio: model / measured over the bounded taus)")
    for col in ("axis", "unit u", "IEEE 952 N [u/sqrt(Hz)]", "IEEE 952 K [u/sqrt(s)]", "bound N", "bound K",
                "ratio median / max", "with Gauss-Markov: terms", "ratio median / max ", "taus bounded [s]"):
        table.add_column(col, justify="left" if col in ("axis", "unit u") else "right")
    for name, a in model.axes.items():
        table.add_row(name, a.unit, f"{a.ieee.white_noise_density:.4g}",
                      f"{a.ieee.random_walk:.4g}", f"{a.bound.white_noise_density:.4g}",
                      f"{a.bound.random_walk:.4g}", f"{a.bound.ratio_median:.2f} / {a.bound.ratio_max:.2f}",
                      str(len(a.markov.markov)), f"{a.markov.ratio_median:.2f} / {a.markov.ratio_max:.2f}",
                      f"{a.bound.taus_s[0]:.3g} .. {a.max_tau_s:.3g}")
    console.print(table)
    if any(len(a.logs) > 1 for a in model.axes.values()):
        logs = Table(title="each log's own bound (white noise N, random walk K) and N read at one sample with its "
                           "95 % interval")
        for col in ("axis", "log", "temperature [degC]", "bound N", "bound K", "N at one sample [95 %]"):
            logs.add_column(col, justify="left" if col in ("axis", "log") else "right")
        for name, a in model.axes.items():
            for log in a.logs:
                low, value, high = log.white_noise_interval
                logs.add_row(name, Path(log.source).name,
                             "-" if log.temperature_degc is None else f"{log.temperature_degc:.1f}",
                             f"{log.bound.white_noise_density:.4g}", f"{log.bound.random_walk:.4g}",
                             f"{value:.4g} [{low:.4g}, {high:.4g}]")
        console.print(logs)


def print_bias_process_noise(benefit: dict) -> None:
    """Per gyro axis: the bias random walk a filter needs with the raw and with the compensated gyro."""
    table = Table(title="the bias random walk a filter needs on these runs (white noise and random walk at or above "
                        "the Allan curve up to a quarter of the run) [deg/s/sqrt(s)]")
    for col in ("axis", "raw K", "compensated K", "raw / compensated", "raw N", "compensated N"):
        table.add_column(col, justify="left" if col == "axis" else "right")
    for name, b in benefit.items():
        table.add_row(name, f"{b.raw.random_walk:.4g}", f"{b.compensated.random_walk:.4g}",
                      f"{b.random_walk_ratio:.1f}", f"{b.raw.white_noise_density:.4g}",
                      f"{b.compensated.white_noise_density:.4g}")
    make_console().print(table)


__all__ = ["noise", "print_bias_process_noise", "print_noise_model"]
