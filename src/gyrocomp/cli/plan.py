"""``gyrocomp plan``: parse its options, call the library, print the result."""

from __future__ import annotations

import dataclasses
import json
import re
from pathlib import Path

import click

from ..calibration import Calibration
from ..evaluation.drift_forecast import DEFAULT_WINDOW_S, UseProfile
from ..measures.ramp_rate import ramp_rate_degc_per_min
from ..evaluation.log_watch import watch_log
from ..evaluation.run_advice import WORTHWHILE_GAIN, plan as plan_runs
from .common import FINITE, echo, pop_read_options, read_options, read_run
from .render import print_plan


#: the close candidates a note names (the nearest first), the rest counted
SHOWN_CANDIDATES = 3


def _check_options(
    paths, watch, every_given, looks, budget_h, target_drift_dps, use_ramp, use_profile, window_s, every_s
) -> None:
    """Options that do not go together, or out of their range: a usage error naming them."""
    if not window_s > 0:
        raise click.BadParameter(f"must be positive, got {window_s:g}", param_hint="--window")
    if use_ramp is not None and not use_ramp > 0:
        raise click.BadParameter(f"must be positive, got {use_ramp:g}", param_hint="--use-ramp")
    if use_ramp is not None and _range_text(use_profile) is None:
        raise click.UsageError("--use-ramp goes with --use-profile LO:HI (a log's own ramps are its own)")
    if watch is None and (every_given or looks is not None):
        raise click.UsageError("--every and --looks go with --watch LOG")
    if watch is not None and budget_h is not None:
        raise click.UsageError("--budget-h plans the runs to record next; --watch follows the run under way")
    if budget_h is not None and not budget_h > 0:
        raise click.BadParameter(f"must be positive, got {budget_h:g}", param_hint="--budget-h")
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
    if result.sequence or result.budget_h is not None or result.target_drift_dps is not None:
        echo(_sequence_line(result), err=True)
        return
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


def _sequence_line(result) -> str:
    """The runs to record in turn, within the budget or to the target, in one line."""
    within = f"within {result.budget_h:g} h" if result.budget_h is not None else "to reach the target"
    if not result.sequence:
        return f"gyrocomp: next: {within}, no candidate run lowers the worst axis's expected drift"
    runs = ", then ".join(f"{a.run.name} ({a.run.description}, {a.run.hours:.1f} h)" for a in result.sequence)
    hours = sum(a.run.hours for a in result.sequence)
    end = result.sequence[-1].after.worst.drift_dps
    line = f"gyrocomp: next: {within}: record {runs}; {hours:.1f} h in all, the worst axis {result.now.worst.drift_dps:.2g} -> {end:.2g} deg/s"
    if result.target_drift_dps is not None:
        line += f"; {'reaches' if result.reaches_target else 'does not reach'} {result.target_drift_dps:g} deg/s"
    return line


#: a use profile given as a range: LO:HI in degC
_RANGE = re.compile(r"^\s*([-+]?[0-9.]+(?:e[-+]?[0-9]+)?)\s*:\s*([-+]?[0-9.]+(?:e[-+]?[0-9]+)?)\s*$", re.I)


def _range_text(text: str | None) -> re.Match | None:
    """The range a --use-profile names (None: a file, or nothing given); a file of that name wins."""
    if text is None or Path(text).exists():
        return None
    return _RANGE.match(text)


def _use_profile(text, use_ramp, recordings, opts) -> UseProfile | None:
    """The use profile --use-profile names: a log's temperatures, or one cycle over LO:HI degC (None: the
    calibration's own range)."""
    if text is None:
        return None
    found = _range_text(text)
    if found is None:
        if not Path(text).exists() and ":" in text:
            raise click.BadParameter(
                f"{text!r}: no such file, and not a range LO:HI in degC (e.g. -10:60)", param_hint="--use-profile"
            )
        return UseProfile.of(read_run(text, opts).recording)
    lo, hi = float(found.group(1)), float(found.group(2))
    if not lo < hi:
        raise click.BadParameter(f"{text!r}: the lower end first", param_hint="--use-profile")
    return UseProfile.cycle(lo, hi, use_ramp or ramp_rate_degc_per_min(recordings))


def _watch(log, earlier_paths, opts, use_profile, use_ramp, window_s, every_s, target, looks, as_json) -> None:
    """Look at the growing ``log`` until the target is reached or the looks are done, a line (or a JSON line) each."""
    earlier = [read_run(path, opts).recording for path in earlier_paths]
    use = _use_profile(use_profile, use_ramp, earlier or [read_run(log, opts).recording], opts)
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
    help="The worst axis's expected drift to reach [deg/s]: the runs to record until it is reached; with --watch, "
    "stop (exit 0) at the look that reaches it.",
)
@click.option(
    "--budget-h",
    "budget_h",
    type=FINITE,
    default=None,
    metavar="HOURS",
    help="Chamber time to spend [h]: the runs to record one after another within it, each the best gain per hour "
    "after those before it.",
)
@click.option(
    "--looks",
    type=click.IntRange(min=1),
    default=None,
    help="With --watch: stop after this many looks (default: until --target-drift is reached, or Ctrl-C).",
)
@click.option(
    "--use-profile",
    "use_profile",
    default=None,
    metavar="FILE|LO:HI",
    help="The temperatures the gyro will see: a log of the vehicle's own (its temperature column), or one heat-cool "
    "cycle over LO..HI degC (default: the calibrated range at the runs' ramp rate).",
)
@click.option(
    "--use-ramp",
    "use_ramp",
    type=FINITE,
    default=None,
    metavar="DEGC_PER_MIN",
    help="With --use-profile LO:HI: the cycle's ramp rate [degC/min] (default: the calibration runs').",
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
    ctx, paths, watch, every_s, target_drift_dps, budget_h, looks, use_profile, use_ramp, window_s, as_json, **kwargs
):
    """How much chamber time is enough, and which run to record next: the drift MODEL should leave on a use
    profile, and candidate runs scored per hour of chamber time.

    The drift MODEL should leave on the use profile (60 s moving average, as the accuracy page scores it), with a
    95 % interval from its coefficients' uncertainty under the RUNS' own residual noise, the part's own drift, the
    extrapolation past the calibrated range and how far the forms the model choice could not tell apart part on
    it; then candidate runs (the cycle again, a wider range, a slower or faster ramp, dwells, one leg) scored by
    the drift after each, per hour of chamber time; with --budget-h or --target-drift, the runs to record in turn.
    RUNS are the static chamber runs MODEL was fitted on.

    With --watch LOG, a run under way: LOG is read again every --every seconds and fitted (with RUNS recorded
    before it); each look prints a line with the worst axis's forecast so far and what one more hour of the leg
    under way would lower it by, until --target-drift is reached or --looks are done.
    """
    opts = pop_read_options(kwargs)
    # on the command line (a project file's [plan] every = ... is a default, for the watches that read it)
    every_given = ctx.get_parameter_source("every_s") is click.core.ParameterSource.COMMANDLINE
    _check_options(
        paths, watch, every_given, looks, budget_h, target_drift_dps, use_ramp, use_profile, window_s, every_s
    )
    if watch is not None:
        return _watch(watch, paths, opts, use_profile, use_ramp, window_s, every_s, target_drift_dps, looks, as_json)
    calibration = Calibration.load(paths[0])
    recordings = [read_run(path, opts).recording for path in paths[1:]]
    use = _use_profile(use_profile, use_ramp, recordings, opts)
    result = plan_runs(calibration, recordings, use, window_s, budget_h=budget_h, target_drift_dps=target_drift_dps)
    if as_json:
        echo(json.dumps(result.to_dict(), indent=2), lines=True)
        return
    if ctx.obj["quiet"]:
        return
    print_plan(result)
    _notes(result, calibration)
