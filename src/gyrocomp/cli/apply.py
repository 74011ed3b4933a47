"""``gyrocomp apply``: parse its options, call the library, print the result."""

from __future__ import annotations

from pathlib import Path

import click

from ..calibration import Calibration
from ..compensate import apply as apply_calibration, apply_file, compensated_axes
from ..io import detect_format, output_format, refuse_to_overwrite_inputs, write_gyro_back
from .common import FINITE, pop_read_options, progress_bar, read_run, read_options, read_settings, streams


@click.command()
@click.argument("model", type=click.Path())
@click.argument("input_path", metavar="IN", type=click.Path())
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False), help="Compensated output file.")
@click.option("--turn-on-window", "turn_on_window_s", type=FINITE, default=None,
              help="Estimate the turn-on bias from the first S seconds of IN [s] (default: the model's mean).")
@click.option("--axes", "axes", default=None, metavar="AXES",
              help="Gyro axes to compensate, e.g. gyro_z (default: all; data with an axis the model lacks is "
                   "refused unless the axes are named, and the others are then left raw).")
@read_options
@click.pass_context
def apply(ctx, model, input_path, output, turn_on_window_s, axes, **kwargs):
    """Compensate IN with MODEL: same columns and rows out, gyro columns compensated."""
    opts = pop_read_options(kwargs)
    refuse_to_overwrite_inputs(output, [input_path, model])
    calibration = Calibration.load(model)
    in_fmt = detect_format(input_path, opts["fmt"]) if Path(input_path).exists() else None
    out_fmt = output_format(output, default=in_fmt)  # a bad output is refused before the work
    named = None if axes is None else tuple(a.strip() for a in axes.split(",") if a.strip())
    if streams(in_fmt, opts):  # in chunks: memory bounded whatever the file's length
        with progress_bar(f"reading {Path(input_path).name}") as progress:
            result = apply_file(calibration, input_path, output, layout=read_settings(opts).layout, fmt=in_fmt,
                                out_fmt=out_fmt, drop_nonfinite=opts["drop_nan"], axes=named,
                                turn_on_window_s=turn_on_window_s, progress=progress)
        rows, done = result.rows, result.axes
    else:
        data = read_run(input_path, opts)
        compensated = apply_calibration(calibration, data.recording, turn_on_window_s=turn_on_window_s, axes=named)
        accel = compensated.accel_g if calibration.accel_axes or calibration.accel_triad else None
        write_gyro_back(data, compensated.gyro_dps, output, fmt=out_fmt, accel_g=accel)
        rows = data.recording.n_samples
        done = compensated_axes(calibration, data.recording, named, accel is not None)
    if not ctx.obj["quiet"]:
        click.echo(f"wrote {output}: {rows} rows, {', '.join(done)} compensated")


__all__ = ["apply"]
