"""``gyrocomp plan``: parse its options, call the library, print the result."""

from __future__ import annotations

import json

import click

from ..calibration import Calibration
from ..evaluation.drift_forecast import DEFAULT_WINDOW_S, UseProfile
from ..evaluation.run_advice import WORTHWHILE_GAIN, plan_calibration, ramp_rate_degc_per_min
from .common import FINITE, echo, pop_read_options, read_options, read_run
from .render import print_plan


#: the close candidates a note names (the nearest first), the rest counted
SHOWN_CANDIDATES = 3


def _use_range(text: str | None) -> tuple[float, float] | None:
    if text is None:
        return None
    parts = text.split(":")
    try:
        lo, hi = (float(p) for p in parts)
    except ValueError:
        raise click.BadParameter(f"{text!r}: give LO:HI in degC, e.g. -10:60", param_hint="--use-range") from None
    if not lo < hi:
        raise click.BadParameter(f"{text!r}: the lower end first", param_hint="--use-range")
    return lo, hi


@click.command()
@click.argument("model", type=click.Path())
@click.argument("runs", nargs=-1, required=True, type=click.Path())
@click.option(
    "--use",
    "use_log",
    type=click.Path(),
    default=None,
    metavar="LOG",
    help="The temperatures the gyro will see: a log of the vehicle's own (its temperature column).",
)
@click.option(
    "--use-range",
    "use_range",
    default=None,
    metavar="LO:HI",
    help="The temperatures the gyro will see, as one heat-cool cycle over LO..HI degC (default: the calibrated range).",
)
@click.option(
    "--use-ramp",
    "use_ramp",
    type=FINITE,
    default=None,
    metavar="DEGC_PER_MIN",
    help="With --use-range: the cycle's ramp rate [degC/min] (default: the calibration runs').",
)
@click.option(
    "--window",
    "window_s",
    type=FINITE,
    default=DEFAULT_WINDOW_S,
    show_default=True,
    help="Moving-average window of the drift [s].",
)
@click.option("--json", "as_json", is_flag=True, help="Print the plan as JSON on stdout.")
@read_options
@click.pass_context
def plan(ctx, model, runs, use_log, use_range, use_ramp, window_s, as_json, **kwargs):
    """How much chamber time is enough, and which run to record next: the drift MODEL should leave on a use
    profile, and candidate runs scored per hour of chamber time.

    The drift MODEL should leave on the use profile (60 s moving average, as the accuracy page scores it), with a
    95 % interval from its coefficients' uncertainty under the RUNS' own residual noise, the part's own drift and
    the extrapolation past the calibrated range; then candidate runs (the cycle again, a wider range, a slower or
    faster ramp, dwells, one leg) scored by the drift after each, per hour of chamber time. RUNS are the static
    chamber runs MODEL was fitted on.
    """
    opts = pop_read_options(kwargs)
    if not window_s > 0:
        raise click.BadParameter(f"must be positive, got {window_s:g}", param_hint="--window")
    if use_log is not None and use_range is not None:
        raise click.UsageError("give --use LOG or --use-range LO:HI, not both")
    if use_ramp is not None and not use_ramp > 0:
        raise click.BadParameter(f"must be positive, got {use_ramp:g}", param_hint="--use-ramp")
    if use_ramp is not None and use_range is None:
        raise click.UsageError("--use-ramp goes with --use-range (a log's own ramps are its own)")
    bounds = _use_range(use_range)
    calibration = Calibration.load(model)
    recordings = [read_run(path, opts).recording for path in runs]
    use = None
    if use_log is not None:
        use = UseProfile.of(read_run(use_log, opts).recording)
    elif bounds is not None:
        use = UseProfile.cycle(*bounds, use_ramp or ramp_rate_degc_per_min(recordings))
    result = plan_calibration(calibration, recordings, use, window_s)
    if as_json:
        echo(json.dumps(result.to_dict(), indent=2), lines=True)
        return
    if ctx.obj["quiet"]:
        return
    print_plan(result)
    for forecast in result.now.axes.values():
        if forecast.not_covered:
            echo(
                f"gyrocomp: note: {forecast.axis}: the model applies a {', '.join(forecast.not_covered)} whose "
                "uncertainty the forecast does not count",
                err=True,
            )
        if forecast.close_candidates:
            named = ", ".join(forecast.close_candidates[:SHOWN_CANDIDATES])
            more = len(forecast.close_candidates) - SHOWN_CANDIDATES
            echo(
                f"gyrocomp: note: {forecast.axis}: the model choice could not tell its curve from {named}"
                + (f" and {more} more" if more > 0 else "")
                + " (held-out drift within one standard error); the forecast counts the chosen curve's uncertainty alone",
                err=True,
            )
    for axis in calibration.axes:
        if axis not in result.now.axes:
            echo(f"gyrocomp: note: {axis}: constants only (no temperature curve), not forecast", err=True)
    best = result.advice[0] if result.advice else None
    if result.enough or best is None:
        echo(
            f"gyrocomp: note: no candidate run lowers the worst axis's expected drift by {WORTHWHILE_GAIN:.0%} or "
            "more: more chamber time buys little on this use profile",
            err=True,
        )
    else:
        echo(
            f"gyrocomp: next: record {best.run.description} ({best.run.hours:.1f} h): the worst axis "
            f"{result.now.worst.drift_dps:.2g} -> {best.after.worst.drift_dps:.2g} deg/s; it resolves {best.resolves}",
            err=True,
        )
