"""``gyrocomp convert``: parse its options, call the library, print the result."""

from __future__ import annotations

from pathlib import Path

import click

from ..files.convert import convert_file
from ..files.convert_bag import convert_bag
from ..io import detect_format, output_format, refuse_to_overwrite_inputs
from ..io.rosbag import KIND_WORDS
from .common import OUTPUT_FILE, pop_read_options, progress_bar, read_options, echo, settings_for


@click.command()
@click.argument("input_path", metavar="IN", type=click.Path())
@click.argument("output", metavar="OUT", type=OUTPUT_FILE)
@read_options
@click.pass_context
def convert(ctx, input_path, output, **kwargs):
    """Write IN (any format gyrocomp reads) as the canonical CSV or Parquet table OUT, or a bag as another bag.

    Columns: time [s], gyro_x/y/z [deg/s], accel_x/y/z [g], temperature [degC]. A ROS bag IN with OUT named
    out.bag (ROS 1), out.mcap (a bare MCAP file) or without a suffix (a ROS 2 folder) is rewritten as that kind of
    bag, every message kept.
    """
    opts = pop_read_options(kwargs)
    refuse_to_overwrite_inputs(output, [input_path], option="OUT")
    in_fmt = detect_format(input_path, opts["fmt"]) if Path(input_path).exists() else None
    if in_fmt == "rosbag" and Path(output).suffix.lower() in ("", ".bag", ".mcap"):
        done = convert_bag(input_path, output)
        if not ctx.obj["quiet"]:
            echo(
                f"wrote {output}: {KIND_WORDS[done.kind]}, every message of {input_path} ({KIND_WORDS[done.from_kind]})"
            )
        return
    out_fmt = output_format(output, option="OUT")
    with progress_bar(f"reading {Path(input_path).name}") as progress:
        result = convert_file(
            input_path,
            output,
            options=settings_for(input_path, opts),
            fmt=opts["fmt"],
            out_fmt=out_fmt,
            progress=progress,
        )
    rows, duration_s, rate_hz, gaps, channels = (
        result.rows,
        result.duration_s,
        result.rate_hz,
        result.gaps,
        result.channels,
    )
    if not ctx.obj["quiet"]:
        said = f", {gaps} time gap(s)" if gaps else ""
        echo(f"wrote {output}: {rows} rows, {duration_s:.6g} s at {rate_hz:.6g} Hz{said}; {', '.join(channels)}")


__all__ = ["convert"]
