"""``gyrocomp validate``: parse its options, call the library, print the result."""

from __future__ import annotations

import json

import click

from ..models.options import FitOptions
from ..fitting.folds import FOLD_KINDS
from ..evaluation.validation import validate as validate_runs
from .common import FINITE, pop_read_options, read_run, parse_temperature_option, progress_bar, read_options, echo
from .render import print_validation


@click.command()
@click.argument("runs", nargs=-1, required=True, type=click.Path())
@click.option(
    "--folds",
    type=click.Choice(FOLD_KINDS),
    default="auto",
    show_default=True,
    help="Hold out each run, each heating or cooling leg, or time blocks; auto: runs with three runs "
    "or more, else legs.",
)
@click.option(
    "--window",
    "window_s",
    type=FINITE,
    default=None,
    help="Moving-average window of the drift [s] (default: as fit's model choice: a tenth of the median fold, 60..600 s, at most a quarter of the shortest).",
)
@click.option(
    "--candidate",
    "candidates",
    multiple=True,
    metavar="SPEC",
    help="Also validate gyrocomp fitted with --temperature SPEC (poly:N, poly, mlp); repeatable.",
)
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON on stdout.")
@read_options
@click.pass_context
def validate(ctx, runs, folds, window_s, candidates, as_json, **kwargs):
    """Held-out drift on RUNS of raw, PX4's cubic, ArduPilot's cubic, a plain cubic, gyrocomp's default and the best
    model a firmware carries.

    Each method is fitted without the fold it is scored on (leave one run out, or one heating or cooling leg
    with fewer than three runs); the score is the RMS of the moving-averaged compensated output about its mean.
    """
    opts = pop_read_options(kwargs)
    if window_s is not None and not window_s > 0:
        raise click.BadParameter(f"must be positive, got {window_s:g}", param_hint="--window")
    named = {}
    for spec in candidates:
        model = parse_temperature_option(spec)
        if model is None:
            raise click.BadParameter(
                "a candidate needs a temperature model (poly, poly:N or mlp)", param_hint="--candidate"
            )
        named[f"gyrocomp {spec}"] = FitOptions(temperature=model)
    recordings = [read_run(path, opts).recording for path in runs]
    with progress_bar("validating", indeterminate=True):
        result = validate_runs(recordings, folds=folds, window_s=window_s, candidates=named)
    if as_json:
        echo(json.dumps(result.to_dict(), indent=2), lines=True)
    elif not ctx.obj["quiet"]:
        print_validation(result)


__all__ = ["validate"]
