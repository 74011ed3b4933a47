"""``gyrocomp apply``: parse its options, call the library, print the result."""

from __future__ import annotations

from pathlib import Path

import click

from ..calibration import Calibration
from ..files.apply import apply_file
from ..files.apply_bag import apply_bag
from ..io import detect_format, output_format, refuse_to_overwrite_inputs
from .common import FINITE, OUTPUT_FILE, pop_read_options, progress_bar, read_options, read_settings


@click.command()
@click.argument("model", type=click.Path())
@click.argument("input_path", metavar="IN", type=click.Path())
@click.option("-o", "--output", required=True, type=OUTPUT_FILE,
              help="Compensated output file: a table (.csv, .parquet), or for a ROS bag a bag of the same kind (a "
                   ".bag file for ROS 1, a new folder for a ROS 2 bag).")
@click.option("--turn-on-window", "turn_on_window_s", type=FINITE, default=None,
              help="Estimate the turn-on bias from the first S seconds of IN [s] (default: the model's mean).")
@click.option("--axes", "axes", default=None, metavar="AXES",
              help="Gyro axes to compensate, e.g. gyro_z (default: all; data with an axis the model lacks is "
                   "refused unless the axes are named, and the others are then left raw).")
@click.option("--noise", "noise_path", type=click.Path(dir_okay=False), default=None,
              help="A bag out: write the IMU messages' covariances from this noise model (gyrocomp noise --export "
                   "json), the variance of one sample at the bag's rate; default: left as they were.")
@read_options
@click.pass_context
def apply(ctx, model, input_path, output, turn_on_window_s, axes, noise_path, **kwargs):
    """Compensate IN with MODEL: same columns and rows out, gyro columns compensated (a ROS bag into a bag: every
    message copied, the IMU topic compensated)."""
    opts = pop_read_options(kwargs)
    refuse_to_overwrite_inputs(output, [input_path, model] + ([noise_path] if noise_path else []))
    calibration = Calibration.load(model)
    in_fmt = detect_format(input_path, opts["fmt"]) if Path(input_path).exists() else None
    if in_fmt == "rosbag" and Path(output).suffix.lower() in ("", ".bag"):  # a bag out: the same kind as in
        done = apply_bag(calibration, input_path, output, options=read_settings(opts), noise=noise_path)
        if not ctx.obj["quiet"]:
            said = (f"{' and '.join(done.covariances)} written from {noise_path}" if done.covariances
                    else "covariances left as they were")
            click.echo(f"wrote {output}: {done.compensated} messages of {done.imu_topic} compensated (angular velocity"
                       f"{' and linear acceleration' if done.accel else ''}), every other message copied as it was; "
                       f"{said}" + ("" if done.streamed else " (read whole: its IMU stamps go back across batches)"))
        return
    if noise_path is not None:
        raise click.BadParameter("a noise model is written into a bag's covariances: give a bag out", param_hint="--noise")
    out_fmt = output_format(output, default=in_fmt)  # a bad output is refused before the work
    named = None if axes is None else tuple(a.strip() for a in axes.split(",") if a.strip())
    with progress_bar(f"reading {Path(input_path).name}") as progress:
        result = apply_file(calibration, input_path, output, options=read_settings(opts), fmt=opts["fmt"],
                            out_fmt=out_fmt, axes=named, turn_on_window_s=turn_on_window_s, progress=progress)
    rows, done = result.rows, result.axes
    if not ctx.obj["quiet"]:
        click.echo(f"wrote {output}: {rows} rows, {', '.join(done)} compensated")


__all__ = ["apply"]
