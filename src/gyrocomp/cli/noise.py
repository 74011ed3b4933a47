"""``gyrocomp noise``: parse its options, call the library, print the noise model or write an export."""

from __future__ import annotations

from pathlib import Path

import click
from ..calibration import Calibration
from ..evaluation.bias_process_noise import compensated_noise
from ..export.estimator_noise import NOISE_EXPORTS
from ..files.noise_file import analyse_noise_file
from ..io import refuse_to_overwrite_inputs, write_text_atomic
from ..io.inputs import expand_runs
from ..measures.noise_model import noise_model, noise_over_temperature
from .common import (
    settings_for,
    OUTPUT_FILE,
    fit_taus_option,
    pop_read_options,
    progress_bar,
    read_options,
    read_run,
    echo,
)
from .render import print_bias_process_noise, print_noise_model


@click.command()
@click.argument("logs", nargs=-1, required=True, type=click.Path())
@click.option(
    "--export",
    "export_format",
    type=click.Choice(tuple(NOISE_EXPORTS)),
    default=None,
    help="Write the model for an estimator: kalibr (imu.yaml), openvins (kalibr_imu_chain.yaml), vins "
    "(acc_n, gyr_n, acc_w, gyr_w), ros (sensor_msgs/Imu covariances), px4 (EKF2_*_NOISE, .params), "
    "ardupilot (EK3_*_P_NSE, .parm) or json (the whole model).",
)
@click.option("-o", "--output", type=OUTPUT_FILE, default=None, help="The file --export writes.")
@click.option("--rostopic", default="/imu0", show_default=True, help="The IMU topic written into the export.")
@click.option(
    "--axes",
    "axes",
    default=None,
    help="Columns to model, e.g. gyro_x,gyro_z,accel_z (default: every gyro and accelerometer axis).",
)
@click.option(
    "--split-gaps/--no-split-gaps",
    default=False,
    help="Pool the contiguous stretches of a log with time gaps instead of refusing it.",
)
@click.option(
    "--model",
    "model_path",
    type=click.Path(dir_okay=False),
    default=None,
    help="A model file: the logs are static runs through a temperature profile, held out from its fit; "
    "say the bias random walk a filter needs with the raw and the compensated gyro, and model (and "
    "export) the compensated gyro's noise.",
)
@click.option(
    "--dwells",
    is_flag=True,
    help="Each log is a chamber run: model the noise of each of its temperature dwells (the first 300 s "
    "of each left out, at least 600 s kept) and bound them all, with the per-temperature table.",
)
@fit_taus_option()
@read_options
@click.pass_context
def noise(ctx, logs, export_format, output, rostopic, axes, split_gaps, model_path, dwells, fit_taus_s, **kwargs):
    """Noise model of static LOGS for an estimator: white noise and random walk (and Gauss-Markov terms) whose Allan
    deviation is at or above the upper end of every log's 95 % interval at every averaging time, beside the IEEE
    952 fit."""
    opts = pop_read_options(kwargs)
    if (export_format is None) != (output is None):
        raise click.BadParameter(
            "give --export and -o together", param_hint="--export" if export_format is None else "-o"
        )
    paths = expand_runs(logs)
    if output is not None:
        refuse_to_overwrite_inputs(output, paths + ([model_path] if model_path else []), option="-o")
    named = [a.strip() for a in axes.split(",") if a.strip()] if axes else None
    benefit = None
    if model_path is not None:
        if dwells:
            raise click.BadParameter("give --model or --dwells, not both", param_hint="--model")
        model, benefit = compensated_noise(
            Calibration.load(model_path),
            [read_run(path, opts).recording for path in paths],
            named,
            with_accel=named is None,
            split_gaps=split_gaps,
            fit_taus_s=fit_taus_s,
        )
    elif dwells:
        model = noise_over_temperature(
            [read_run(path, opts).recording for path in paths], named, with_accel=named is None, fit_taus_s=fit_taus_s
        )
    else:
        analyses = []
        for path in paths:
            with progress_bar(f"reading {Path(path).name}") as progress:
                analyses.append(
                    analyse_noise_file(
                        path,
                        named,
                        options=settings_for(path, opts),
                        fmt=opts["fmt"],
                        with_accel=named is None,
                        split_gaps=split_gaps,
                        fit_taus_s=fit_taus_s,
                        progress=progress,
                    )
                )
        model = noise_model(analyses)
    if export_format is not None:
        write_text_atomic(output, NOISE_EXPORTS[export_format](model, rostopic))
    if not ctx.obj["quiet"]:
        print_noise_model(model)
        if benefit is not None:
            print_bias_process_noise(benefit)
        if export_format is not None:
            echo(f"wrote {output} ({export_format})")


__all__ = ["noise"]
