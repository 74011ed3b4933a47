"""``gyrocomp apply``: parse its options, call the library, print the result."""

from __future__ import annotations

from pathlib import Path

import click

from ..calibration import Calibration
from ..files.apply import apply_file
from ..io import detect_format, output_format, refuse_to_overwrite_inputs
from .common import FINITE, OUTPUT_FILE, pop_read_options, progress_bar, read_options, read_settings


@click.command()
@click.argument("model", type=click.Path())
@click.argument("input_path", metavar="IN", type=click.Path())
@click.option("-o", "--output", required=True, type=OUTPUT_FILE, help="Compensated output file.")
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
    with progress_bar(f"reading {Path(input_path).name}") as progress:
        result = apply_file(calibration, input_path, output, options=read_settings(opts), fmt=opts["fmt"],
                            out_fmt=out_fmt, axes=named, turn_on_window_s=turn_on_window_s, progress=progress)
    rows, done = result.rows, result.axes
    if not ctx.obj["quiet"]:
        click.echo(f"wrote {output}: {rows} rows, {', '.join(done)} compensated")


__all__ = ["apply"]
