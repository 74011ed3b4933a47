"""``gyrocomp report``: parse its options, call the library, print the result."""

from __future__ import annotations

import click

from ..calibration import Calibration
from ..io import refuse_to_overwrite_inputs, write_text_atomic
from ..report.figures import require_matplotlib
from ..report.html import build_report
from ..evaluation.run_advice import plan as plan_runs
from ..evaluation.validation import validate as validate_runs
from .common import (
    echo,
    FINITE,
    OUTPUT_FILE,
    pop_read_options,
    progress_bar,
    read_options,
    read_run,
    turn_on_window_option,
    window_option,
)


@click.command()
@click.argument("model", type=click.Path())
@click.argument("runs", nargs=-1, required=True, type=click.Path())
@click.option("-o", "--output", required=True, type=OUTPUT_FILE, help="The HTML file to write.")
@window_option()
@turn_on_window_option()
@click.option(
    "--min-static",
    "static_min_duration_s",
    type=FINITE,
    default=10.0,
    show_default=True,
    help="Shortest still stretch drawn as a static position [s].",
)
@click.option(
    "--validate-on",
    "validate_on",
    multiple=True,
    type=click.Path(),
    help="A calibration run to validate on (repeat it for each run): adds the table of gyrocomp validate.",
)
@click.option(
    "--plan-on",
    "plan_on",
    multiple=True,
    type=click.Path(),
    help="A calibration run MODEL was fitted on (repeat it for each run): adds gyrocomp plan's section, the drift "
    "to expect on the calibrated range and the next run to record.",
)
@read_options
@click.pass_context
def report(ctx, model, runs, output, window_s, turn_on_window_s, static_min_duration_s, validate_on, plan_on, **kwargs):
    """One self-contained HTML report of MODEL judged on RUNS: the model, the figures of merit, bias against
    temperature, raw and compensated series, Allan deviations, g-sensitivity; with --validate-on, the held-out
    drift of each method on those calibration runs."""

    opts = pop_read_options(kwargs)
    refuse_to_overwrite_inputs(output, [model, *runs, *validate_on, *plan_on])
    if not str(output).lower().endswith((".html", ".htm")):
        raise click.BadParameter(f"{output}: name the report .html", param_hint="-o")
    if window_s is not None and not window_s > 0:
        raise click.BadParameter(f"must be positive, got {window_s:g}", param_hint="--window")
    require_matplotlib()
    calibration = Calibration.load(model)
    recordings = [read_run(path, opts).recording for path in runs]
    validation = None
    if validate_on:
        with progress_bar("validating", indeterminate=True):
            validation = validate_runs([read_run(path, opts).recording for path in validate_on])
    planned = None
    if plan_on:
        with progress_bar("planning", indeterminate=True):
            planned = plan_runs(calibration, [read_run(path, opts).recording for path in plan_on])
    with progress_bar("report") as progress:
        result = build_report(
            calibration,
            recordings,
            window_s=window_s,
            turn_on_window_s=turn_on_window_s,
            min_static_s=static_min_duration_s,
            progress=progress,
            validation=validation,
            plan=planned,
        )
    write_text_atomic(output, result.html)
    if not ctx.obj["quiet"]:
        echo(f"wrote {output}: {len(result.html) / 1e6:.2f} MB, sections {', '.join(result.sections)}")


__all__ = ["report"]
