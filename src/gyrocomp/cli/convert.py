"""``gyrocomp convert``: parse its options, call the library, print the result."""

from __future__ import annotations

import click

from ..io import output_format, refuse_to_overwrite_inputs, write_recording
from .common import pop_read_options, read_run, read_options


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
    recording = read_run(input_path, opts).recording
    write_recording(recording, output, fmt=out_fmt)
    if not ctx.obj["quiet"]:
        channels = [*recording.gyro_axes, *recording.accel_axes, *recording.temperature_columns]
        gaps = f", {len(recording.gaps)} time gap(s)" if recording.gaps else ""
        click.echo(f"wrote {output}: {recording.n_samples} rows, {recording.duration_s:.6g} s at "
                   f"{recording.rate_hz:.6g} Hz{gaps}; {', '.join(channels)}")


__all__ = ["convert"]
