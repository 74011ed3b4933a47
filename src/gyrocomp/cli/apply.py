"""``gyrocomp apply``: parse its options, call the library, print the result."""

from __future__ import annotations

from pathlib import Path

import click

from ..calibration import Calibration
from ..files.apply import apply_file
from ..files.apply_bag import apply_bag, apply_bag_instances
from ..io import detect_format, instances, output_format, refuse_to_overwrite_inputs
from .common import (
    settings_for,
    echo,
    FINITE,
    OUTPUT_FILE,
    instance_model_path,
    pop_read_options,
    progress_bar,
    read_options,
    read_settings,
)


@click.command()
@click.argument("model", type=click.Path())
@click.argument("input_path", metavar="IN", type=click.Path())
@click.option(
    "-o",
    "--output",
    required=True,
    type=OUTPUT_FILE,
    help="Compensated output file: a table (.csv, .parquet), or for a ROS bag a bag of the same kind (a "
    ".bag file for ROS 1, a new folder for a ROS 2 bag, a .mcap file for a bare MCAP file; with "
    "--instance all, each IMU topic with MODEL's model of its instance, MODEL_imuN).",
)
@click.option(
    "--turn-on-window",
    "turn_on_window_s",
    type=FINITE,
    default=None,
    help="Estimate the turn-on bias from the first S seconds of IN [s] (default: the model's mean).",
)
@click.option(
    "--axes",
    "axes",
    default=None,
    metavar="AXES",
    help="Gyro axes to compensate, e.g. gyro_z (default: all; data with an axis the model lacks is "
    "refused unless the axes are named, and the others are then left raw).",
)
@click.option(
    "--noise",
    "noise_path",
    type=click.Path(dir_okay=False),
    default=None,
    help="A bag out: write the IMU messages' covariances from this noise model (gyrocomp noise --export "
    "json), the variance of one sample at the bag's rate; default: left as they were.",
)
@read_options
@click.pass_context
def apply(ctx, model, input_path, output, turn_on_window_s, axes, noise_path, **kwargs):
    """Compensate IN with MODEL: same columns and rows out, gyro columns compensated (a ROS bag into a bag: every
    message copied, the IMU topic compensated)."""
    opts = pop_read_options(kwargs)
    in_fmt = detect_format(input_path, opts["fmt"]) if Path(input_path).exists() else None
    bag_out = in_fmt == "rosbag" and Path(output).suffix.lower() in ("", ".bag", ".mcap")  # a bag of the input's kind
    if bag_out and str(opts["instance"]).strip().lower() == "all":
        _apply_instances(ctx, model, input_path, output, opts, noise_path)
        return
    refuse_to_overwrite_inputs(output, [input_path, model] + ([noise_path] if noise_path else []))
    calibration = Calibration.load(model)
    if bag_out:
        done = apply_bag(calibration, input_path, output, options=read_settings(opts), noise=noise_path)
        if not ctx.obj["quiet"]:
            said = (
                f"{' and '.join(done.covariances)} written from {noise_path}"
                if done.covariances
                else "covariances left as they were"
            )
            _said_bag(output, [done], f"every other message copied as it was; {said}")
        return
    if noise_path is not None:
        raise click.BadParameter(
            "a noise model is written into a bag's covariances: give a bag out", param_hint="--noise"
        )
    out_fmt = output_format(output, default=in_fmt)  # a bad output is refused before the work
    named = None if axes is None else tuple(a.strip() for a in axes.split(",") if a.strip())
    with progress_bar(f"reading {Path(input_path).name}") as progress:
        result = apply_file(
            calibration,
            input_path,
            output,
            options=settings_for(input_path, opts),
            fmt=opts["fmt"],
            out_fmt=out_fmt,
            axes=named,
            turn_on_window_s=turn_on_window_s,
            progress=progress,
        )
    rows, done = result.rows, result.axes
    if not ctx.obj["quiet"]:
        echo(f"wrote {output}: {rows} rows, {', '.join(done)} compensated")


def _apply_instances(ctx, model, input_path, output, opts: dict, noise_path) -> None:
    """``--instance all`` with a bag out: each IMU topic with the model of its instance (MODEL's name with
    ``_imuN``, as ``fit --instance all`` writes them)."""
    if noise_path is not None:
        raise click.BadParameter(
            "one noise model describes one IMU: give --instance N or --imu-topic with it", param_hint="--noise"
        )
    found = instances(input_path, opts["fmt"])
    paths = {k: instance_model_path(model, k) for k in found}
    refuse_to_overwrite_inputs(output, [input_path, *paths.values()])
    missing = [str(p) for p in paths.values() if not p.is_file()]
    if missing:
        raise click.BadParameter(
            f"the bag has {len(found)} IMU topic(s), instances {', '.join(map(str, found))}; "
            f"no model file {', '.join(missing)} (gyrocomp fit -o {model} --instance all writes "
            "one per instance)",
            param_hint="--instance",
        )
    done = apply_bag_instances(
        {k: Calibration.load(p) for k, p in paths.items()},
        input_path,
        output,
        options=read_settings({**opts, "instance": None}),
    )
    if not ctx.obj["quiet"]:
        _said_bag(output, done, "every other message copied as it was; covariances left as they were")


def _said_bag(output, done, rest: str) -> None:
    topics = "; ".join(
        f"{d.compensated} messages of {d.imu_topic} compensated (angular velocity"
        f"{' and linear acceleration' if d.accel else ''})"
        for d in done
    )
    whole = "" if all(d.streamed for d in done) else " (read whole: its IMU stamps go back across batches)"
    echo(f"wrote {output}: {topics}, {rest}{whole}")


__all__ = ["apply"]
