"""``gyrocomp convert``: parse its options, call the library, print the result."""

from __future__ import annotations

from pathlib import Path

import click

from ..io import detect_format, output_format, refuse_to_overwrite_inputs, write_recording
from ..io.stream import convert_table
from .common import pop_read_options, progress_bar, read_run, read_options, read_settings, streams


@click.command()
@click.argument("input_path", metavar="IN", type=click.Path())
@click.argument("output", metavar="OUT", type=click.Path(dir_okay=False))
@read_options
@click.pass_context
def convert(ctx, input_path, output, **kwargs):
    """Write IN (any format gyrocomp reads) as the canonical CSV or Parquet table OUT.

    Columns: time [s], gyro_x/y/z [deg/s], accel_x/y/z [g], temperature [degC].
    """
    opts = pop_read_options(kwargs)
    refuse_to_overwrite_inputs(output, [input_path], option="OUT")
    out_fmt = output_format(output, option="OUT")
    in_fmt = detect_format(input_path, opts["fmt"]) if Path(input_path).exists() else None
    if streams(in_fmt, opts):  # in chunks: memory bounded whatever the file's length
        with progress_bar(f"reading {Path(input_path).name}") as progress:
            result = convert_table(input_path, output, read_settings(opts).layout, fmt=in_fmt, out_fmt=out_fmt,
                                   drop_nonfinite=opts["drop_nan"], progress=progress)
        rows, duration_s, rate_hz, gaps, channels = (result.rows, result.duration_s, result.rate_hz, result.gaps,
                                                     result.channels)
    else:
        recording = read_run(input_path, opts).recording
        write_recording(recording, output, fmt=out_fmt)
        rows, duration_s, rate_hz, gaps = (recording.n_samples, recording.duration_s, recording.rate_hz,
                                           len(recording.gaps))
        channels = [*recording.gyro_axes, *recording.accel_axes, *recording.temperature_columns]
    if not ctx.obj["quiet"]:
        said = f", {gaps} time gap(s)" if gaps else ""
        click.echo(f"wrote {output}: {rows} rows, {duration_s:.6g} s at {rate_hz:.6g} Hz{said}; {', '.join(channels)}")


__all__ = ["convert"]
