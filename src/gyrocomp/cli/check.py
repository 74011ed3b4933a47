"""``gyrocomp check``: parse its options, call the data check, print one verdict line per run."""

from __future__ import annotations

import json

import click

from ..files.check import ask_for, check_files
from ..fitting.thermal import HYSTERESIS_CHOICES
from ..io.inputs import expand_runs
from ..models.options import FitOptions
from .entry_point import in_cli_words
from .common import (
    settings_for,
    echo,
    accept_option,
    parse_temperature_option,
    pop_read_options,
    read_options,
    temperature_help,
)

#: the exit status when a run is refused (0: every run may be fitted; 2 stays bad input)
REFUSED_EXIT = 1


@click.command()
@click.argument("runs", nargs=-1, required=True, type=click.Path())
@click.option(
    "--temperature",
    default="auto",
    show_default=True,
    help="The fit's temperature curve, as fit takes it: " + temperature_help(),
)
@click.option(
    "--hysteresis",
    type=click.Choice(HYSTERESIS_CHOICES),
    default="auto",
    show_default=True,
    help="The fit's hysteresis, as fit takes it (turning-point: the runs must heat and cool).",
)
@accept_option
@click.option("--json", "as_json", is_flag=True, help="Print every finding as JSON.")
@read_options
@click.pass_context
def check(ctx, runs, temperature, hysteresis, accept, as_json, **kwargs):
    """Check RUNS before a fit, as fit and fleet fit do: one verdict line per run (ok, warning with its expected
    cost, or refused with the reason). Exit status 1 when a run is refused."""
    opts = pop_read_options(kwargs)
    ask = ask_for(FitOptions(temperature=parse_temperature_option(temperature), hysteresis=hysteresis))
    _, checks = check_files(expand_runs(runs), lambda path: settings_for(path, opts), opts["fmt"], ask, accept)
    if as_json:
        echo(json.dumps([c.to_dict() for c in checks], indent=2), lines=True)
    elif not ctx.obj["quiet"]:
        for c in checks:
            echo(in_cli_words(c.line()))
    if any(c.verdict == "refused" for c in checks):
        ctx.exit(REFUSED_EXIT)
