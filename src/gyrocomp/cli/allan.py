"""``gyrocomp allan``: parse its options, call the library, print the result."""

from __future__ import annotations

import json
from pathlib import Path

import click

from ..allan import KINDS
from ..files.noise_file import analyse_noise_file
from ..io import refuse_to_overwrite_inputs, write_text_atomic
from ..export.kalibr import kalibr_imu, kalibr_imu_yaml
from ..report.figures import allan_figure, check_figure_path
from .common import OUTPUT_FILE, fit_taus_option, pop_read_options, progress_bar, read_options, echo, settings_for
from .render import print_noise


def _parse_taus(text: str):
    if text in ("octave", "decade", "all"):
        return text
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        values = []
    if not values or min(values) <= 0:
        raise click.BadParameter(
            "use octave, decade, all or a comma-separated list of taus [s], e.g. 1,10,100", param_hint="--taus"
        )
    return values


@click.command()
@click.argument("input_path", metavar="FILE", type=click.Path())
@click.option(
    "--axes", "axes", default=None, help="Columns to analyse, e.g. gyro_x,gyro_z,accel_z (default: every gyro axis)."
)
@click.option(
    "--kind", type=click.Choice(KINDS), default="oadev", show_default=True, help="Estimator of the printed curve."
)
@click.option("--taus", default="octave", show_default=True, help="octave, decade, all, or taus [s] such as 1,10,100.")
@click.option("--json", "as_json", is_flag=True, help="Print curves and noise terms as JSON on stdout.")
@click.option("--plot", "plot_path", type=OUTPUT_FILE, help="Write the Allan plot here (.png, .svg, .pdf).")
@click.option("--kalibr", "kalibr", type=OUTPUT_FILE, help="Write Kalibr's imu.yaml here.")
@click.option("--rostopic", default="/imu0", show_default=True, help="rostopic written into the Kalibr file.")
@click.option(
    "--split-gaps/--no-split-gaps",
    default=False,
    help="Pool the contiguous stretches of a log with time gaps instead of refusing it.",
)
@fit_taus_option()
@read_options
@click.pass_context
def allan(ctx, input_path, axes, kind, taus, as_json, plot_path, kalibr, rostopic, split_gaps, fit_taus_s, **kwargs):
    """Allan deviation with 68 % intervals and IEEE 952 noise terms (N, B, K, Q, R) of each axis of FILE."""
    opts = pop_read_options(kwargs)
    tau_spec = _parse_taus(taus)
    for option, path in (("--plot", plot_path), ("--kalibr", kalibr)):
        if path:
            refuse_to_overwrite_inputs(path, [input_path], option=option)
    if plot_path:
        check_figure_path(plot_path)
    named = [a.strip() for a in axes.split(",") if a.strip()] if axes else None
    with progress_bar(f"reading {Path(input_path).name}") as progress:
        analysis = analyse_noise_file(
            input_path,
            named,
            options=settings_for(input_path, opts),
            fmt=opts["fmt"],
            with_accel=bool(kalibr),
            kind=kind,
            taus=tau_spec,
            split_gaps=split_gaps,
            fit_taus_s=fit_taus_s,
            progress=progress,
        )
    if analysis.how and not ctx.obj["quiet"]:
        echo(f"gyrocomp: note: {analysis.how}", err=True)
    if kalibr:
        write_text_atomic(kalibr, kalibr_imu_yaml(kalibr_imu(analysis, rostopic)))
    if plot_path:
        allan_figure(analysis, plot_path)
    if as_json:
        echo(json.dumps(analysis.to_dict(), indent=2), lines=True)
    elif not ctx.obj["quiet"]:
        print_noise(analysis)


__all__ = ["allan"]
