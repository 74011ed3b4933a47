"""``gyrocomp plan``: parse its options, call the library, print the result."""

from __future__ import annotations

import dataclasses
import json

import click

from ..calibration import Calibration
from ..evaluation.drift_forecast import DEFAULT_WINDOW_S, UseProfile
from ..evaluation.log_watch import watch_log
from ..evaluation.run_advice import WORTHWHILE_GAIN, plan_calibration, ramp_rate_degc_per_min
from .common import FINITE, echo, pop_read_options, read_options, read_run
from .render import print_plan


#: the close candidates a note names (the nearest first), the rest counted
SHOWN_CANDIDATES = 3


def _check_options(
    paths, watch, every_s, every_given, target_drift_dps, looks, use_log, use_range, use_ramp, window_s
) -> None:
    """Options that do not go together, or out of their range: a usage error naming them."""
    if not window_s > 0:
        raise click.BadParameter(f"must be positive, got {window_s:g}", param_hint="--window")
    if use_log is not None and use_range is not None:
        raise click.UsageError("give --use LOG or --use-range LO:HI, not both")
    if use_ramp is not None and not use_ramp > 0:
        raise click.BadParameter(f"must be positive, got {use_ramp:g}", param_hint="--use-ramp")
    if use_ramp is not None and use_range is None:
        raise click.UsageError("--use-ramp goes with --use-range (a log's own ramps are its own)")
    if watch is None and (every_given or target_drift_dps is not None or looks is not None):
        raise click.UsageError("--every, --target-drift and --looks go with --watch LOG")
    if target_drift_dps is not None and not target_drift_dps > 0:
        raise click.BadParameter(f"must be positive, got {target_drift_dps:g}", param_hint="--target-drift")
    if not every_s >= 0:
        raise click.BadParameter(f"must be zero or more, got {every_s:g}", param_hint="--every")
    if watch is None and len(paths) < 2:
        raise click.UsageError("give MODEL and the runs it was fitted on, or --watch LOG")


def _notes(result, calibration: Calibration) -> None:
    """What the forecast does not count, the axes it leaves out, and the next run (or that more buys little)."""
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
                + " (held-out drift within one standard error)"
                + (
                    f"; fitted, {' and '.join(forecast.alternatives)} part from it by {forecast.model_choice_dps:.2g} "
                    "deg/s on this profile, added to the interval's upper end"
                    if forecast.alternatives
                    else "; the forecast counts the chosen curve's uncertainty alone"
                ),
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


def _use_profile(use_log, bounds, use_ramp, recordings, opts) -> UseProfile | None:
    """The use profile the options describe (None: the calibration's own range)."""
    if use_log is not None:
        return UseProfile.of(read_run(use_log, opts).recording)
    if bounds is not None:
        return UseProfile.cycle(*bounds, use_ramp or ramp_rate_degc_per_min(recordings))
    return None


def _watch(log, earlier_paths, opts, use_log, bounds, use_ramp, window_s, every_s, target, looks, as_json) -> None:
    """Look at the growing ``log`` until the target is reached or the looks are done, a line (or a JSON line) each."""
    earlier = [read_run(path, opts).recording for path in earlier_paths]
    use = _use_profile(use_log, bounds, use_ramp, earlier or [read_run(log, opts).recording], opts)
    first = None
    for seen in watch_log(lambda: read_run(log, opts).recording, every_s, earlier, use, window_s, target, looks):
        if as_json:
            echo(json.dumps(dataclasses.asdict(seen)))
            continue
        lo, hi = seen.range_degc
        head = f"{log}: {seen.duration_s / 3600:.2f} h, {seen.rows} rows, {lo:.1f}..{hi:.1f} degC"
        if seen.worst is None:
            echo(f"{head}: no forecast yet ({seen.waiting})")
            continue
        w = seen.worst
        first = w.drift_dps if first is None else first
        line = (
            f"{head}: {w.axis} {w.drift_dps:.3g} deg/s ({w.low_dps:.2g}..{w.high_dps:.2g}); one more hour of this "
            f"leg: -{max(seen.leg_gain_dps_per_h, 0.0):.2g} deg/s"
        )
        if target is not None:
            line += f"; {_progress(first, w.drift_dps, target)}"
        echo(line)
        if seen.reached:
            echo(f"gyrocomp: target reached: {w.axis} {w.drift_dps:.3g} <= {target:g} deg/s", err=True)
            return
    if target is not None:
        echo(f"gyrocomp: note: --target-drift {target:g} deg/s not reached in {looks} look(s)", err=True)


def _progress(first: float, now: float, target: float, width: int = 20) -> str:
    """A bar of the way from the first look's drift to the target."""
    share = 1.0 if now <= target else (0.0 if first <= target else max(0.0, min(1.0, (first - now) / (first - target))))
    filled = int(round(share * width))
    return f"[{'#' * filled}{'.' * (width - filled)}] {share:.0%} of the way to {target:g} deg/s"


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
@click.argument("paths", nargs=-1, type=click.Path(), metavar="MODEL RUNS... | --watch LOG [RUNS...]")
@click.option(
    "--watch",
    "watch",
    type=click.Path(),
    default=None,
    metavar="LOG",
    help="A run under way: read LOG again every --every seconds, fit it (with RUNS recorded before it), and print "
    "the drift forecast so far and what one more hour of the leg under way would buy.",
)
@click.option(
    "--every", "every_s", type=FINITE, default=600.0, show_default=True, help="With --watch: seconds between looks [s]."
)
@click.option(
    "--target-drift",
    "target_drift_dps",
    type=FINITE,
    default=None,
    metavar="DEG_PER_S",
    help="With --watch: stop (exit 0) once the worst axis's expected drift is at or under this [deg/s].",
)
@click.option(
    "--looks",
    type=click.IntRange(min=1),
    default=None,
    help="With --watch: stop after this many looks (default: until --target-drift is reached, or Ctrl-C).",
)
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
def plan(
    ctx, paths, watch, every_s, target_drift_dps, looks, use_log, use_range, use_ramp, window_s, as_json, **kwargs
):
    """How much chamber time is enough, and which run to record next: the drift MODEL should leave on a use
    profile, and candidate runs scored per hour of chamber time.

    The drift MODEL should leave on the use profile (60 s moving average, as the accuracy page scores it), with a
    95 % interval from its coefficients' uncertainty under the RUNS' own residual noise, the part's own drift and
    the extrapolation past the calibrated range; then candidate runs (the cycle again, a wider range, a slower or
    faster ramp, dwells, one leg) scored by the drift after each, per hour of chamber time. RUNS are the static
    chamber runs MODEL was fitted on.

    With --watch LOG, a run under way: LOG is read again every --every seconds and fitted (with RUNS recorded
    before it); each look prints a line with the worst axis's forecast so far and what one more hour of the leg
    under way would lower it by, until --target-drift is reached or --looks are done.
    """
    opts = pop_read_options(kwargs)
    # on the command line (a project file's [plan] every = ... is a default, for the watches that read it)
    every_given = ctx.get_parameter_source("every_s") is click.core.ParameterSource.COMMANDLINE
    _check_options(paths, watch, every_s, every_given, target_drift_dps, looks, use_log, use_range, use_ramp, window_s)
    bounds = _use_range(use_range)
    if watch is not None:
        return _watch(
            watch, paths, opts, use_log, bounds, use_ramp, window_s, every_s, target_drift_dps, looks, as_json
        )
    calibration = Calibration.load(paths[0])
    recordings = [read_run(path, opts).recording for path in paths[1:]]
    use = _use_profile(use_log, bounds, use_ramp, recordings, opts)
    result = plan_calibration(calibration, recordings, use, window_s)
    if as_json:
        echo(json.dumps(result.to_dict(), indent=2), lines=True)
        return
    if ctx.obj["quiet"]:
        return
    print_plan(result)
    _notes(result, calibration)
