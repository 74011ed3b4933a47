"""``gyrocomp evaluate``: parse its options, call the library, print the result."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import click

from ..calibration import Calibration
from ..errors import InputError
from ..files.evaluate import evaluate_file
from ..io.schedule import apply_schedule, read_rate_schedule
from ..measures.merit import Evaluation
from ..evaluation.comparison import compare_methods
from ..evaluation import evaluate as evaluate_calibration
from ..evaluation import compare_installed, evaluate_stages
from .common import (
    settings_for,
    echo,
    hysteresis_band,
    pop_read_options,
    progress_bar,
    read_options,
    read_run,
    turn_on_window_option,
    window_option,
)
from .render import print_comparison, print_evaluation, print_expected_drift, print_installed, print_stages


def _nan_none(value):
    return None if isinstance(value, float) and math.isnan(value) else value


@click.command()
@click.argument("paths", nargs=-1, required=True, type=click.Path(), metavar="MODEL RUNS... | --compare RUNS...")
@window_option()
@turn_on_window_option()
@click.option(
    "--compare",
    is_flag=True,
    help="The thesis's comparison on RUNS: raw, polynomial, network, each with and without hysteresis "
    "(leave one run out with two runs or more).",
)
@click.option(
    "--hysteresis-band",
    "hysteresis_band_text",
    default=None,
    metavar="LO,HI",
    help="With --compare: limit the hysteresis to this band [degC].",
)
@click.option(
    "--stages",
    is_flag=True,
    help="Report each stage of MODEL (the thesis's Table 4.4): raw, temperature only, + acceleration, + hysteresis.",
)
@click.option(
    "--installed",
    is_flag=True,
    help="RUNS are PX4/ArduPilot logs: judge the thermal calibration installed on the vehicle (TC_G*, "
    "INS_TCAL* parameters in the log) against MODEL on the same data (the still segments of a log "
    "that moves).",
)
@click.option("--json", "as_json", is_flag=True, help="Print the figures as JSON on stdout.")
@click.option(
    "--rate-schedule",
    "rate_schedule",
    type=click.Path(),
    default=None,
    metavar="FILE",
    help="A rate table's schedule for the RUNS it names (as for fit): adds their rate error.",
)
@read_options
@click.pass_context
def evaluate(
    ctx,
    paths,
    window_s,
    turn_on_window_s,
    compare,
    hysteresis_band_text,
    stages,
    installed,
    as_json,
    rate_schedule,
    **kwargs,
):
    """Bias offset, bias instability and integration time of RUNS, raw and compensated with MODEL.

    With --compare, no model is given: the methods of the reference thesis are fitted on the runs and compared.
    """
    opts = pop_read_options(kwargs)
    if window_s is not None and not window_s > 0:
        raise click.BadParameter(f"must be positive, got {window_s:g}", param_hint="--window")
    quiet = ctx.obj["quiet"]
    if compare:
        return _compare(paths, opts, window_s, hysteresis_band(hysteresis_band_text), as_json, quiet)
    if len(paths) < 2:
        raise click.UsageError("give MODEL and at least one run, or --compare RUNS...")
    model, runs = paths[0], paths[1:]
    calibration = Calibration.load(model)
    if stages:
        return _stages(calibration, model, runs, opts, window_s, turn_on_window_s, as_json, quiet)
    if installed:
        return _installed(calibration, runs, opts, window_s, as_json, quiet)
    evaluation = _evaluate_runs(calibration, runs, opts, window_s, turn_on_window_s, rate_schedule)
    expected = calibration.report.expected_drift()
    in_sample, partly = _in_sample(calibration, runs, opts["time_range_s"], quiet)
    if as_json:
        document = {**evaluation.to_dict(), "in_sample_files": in_sample, "partly_in_sample_files": partly}
        document["expected_held_out_drift"] = [e.to_dict() for e in expected.values()]
        echo(json.dumps(document, indent=2), lines=True)
    elif not quiet:
        print_evaluation(evaluation)
        print_expected_drift(expected)
        if turn_on_window_s is not None:
            echo(
                f"gyrocomp: note: --turn-on-window {turn_on_window_s:g}: each run's constant was taken from "
                "its first seconds; bias offset, bias instability and integration time do not depend on a "
                "constant, so only the compensated output (gyrocomp apply) shows it",
                err=True,
            )


def _in_sample(calibration, runs, time_range_s, quiet: bool) -> tuple[list[str], list[str]]:
    """The runs whose judged rows the model was fitted on, all of them or part (:meth:`Calibration.fitted_share`),
    each said in a note unless ``quiet``."""
    shares = {str(path): calibration.fitted_share(path, time_range_s) for path in runs}
    in_sample = [path for path, share in shares.items() if share == "all"]
    partly = [path for path, share in shares.items() if share == "part"]
    for path in in_sample if not quiet else ():
        echo(
            f"gyrocomp: note: {path}: the model was fitted on these rows of the file, so its figures are "
            "in-sample; on new data expect the held-out drift the model file states (gyrocomp show)",
            err=True,
        )
    for path in partly if not quiet else ():
        echo(
            f"gyrocomp: note: {path}: the model was fitted on part of the rows judged (the window its fit read "
            "with --time overlaps this one), so its figures are partly in-sample; judge the rows outside that "
            "window alone for the drift to expect on new data",
            err=True,
        )
    return in_sample, partly


def _installed(calibration: Calibration, runs, opts: dict, window_s, as_json: bool, quiet: bool) -> None:
    """--installed: the thermal calibration installed on the vehicle against the model, on its logs."""
    results = [compare_installed(calibration, read_run(path, opts).recording, window_s=window_s) for path in runs]
    if as_json:
        echo(json.dumps({"runs": [dataclasses.asdict(r) for r in results]}, indent=2, default=_nan_none), lines=True)
    elif not quiet:
        print_installed(results)


def _compare(paths, opts: dict, window_s, band, as_json: bool, quiet: bool) -> None:
    """--compare: the thesis's methods fitted on the runs and compared."""
    recordings = [read_run(path, opts).recording for path in paths]
    result = compare_methods(recordings, window_s=window_s, hysteresis_band_degc=band)
    if as_json:
        echo(json.dumps(result.to_dict(), indent=2), lines=True)
    elif not quiet:
        print_comparison(result)


def _stages(calibration: Calibration, model, runs, opts: dict, window_s, turn_on_window_s, as_json, quiet) -> None:
    """--stages: the figures after each stage of the model."""
    if not calibration.axes:
        raise InputError(
            f"--stages: {model} has no gyro axes (an accelerometer-only model has one stage); "
            "evaluate it without --stages"
        )
    staged = [
        evaluate_stages(
            calibration, read_run(path, opts).recording, window_s=window_s, turn_on_window_s=turn_on_window_s
        )
        for path in runs
    ]
    if as_json:
        echo(json.dumps({"runs": [s.to_dict() for s in staged]}, indent=2), lines=True)
    elif not quiet:
        print_stages(staged)


def _evaluate_runs(calibration, runs, opts: dict, window_s, turn_on_window_s, rate_schedule) -> Evaluation:
    """The model on each run (gyrocomp.files: tables in chunks, memory bounded whatever the files' lengths, other
    files whole); with a rate schedule, the runs read whole and the schedule applied to them first."""
    if rate_schedule is None:
        parts = []
        for path in runs:
            with progress_bar(f"reading {Path(path).name}") as progress:
                parts.append(
                    evaluate_file(
                        calibration,
                        path,
                        options=settings_for(path, opts),
                        fmt=opts["fmt"],
                        window_s=window_s,
                        turn_on_window_s=turn_on_window_s,
                        progress=progress,
                    )
                )
        return Evaluation([r for p in parts for r in p.runs], [t for p in parts for t in p.triads])
    recordings = [read_run(path, opts).recording for path in runs]
    if rate_schedule is not None:
        recordings = apply_schedule(read_rate_schedule(rate_schedule), recordings, list(runs))
    return evaluate_calibration(calibration, recordings, window_s=window_s, turn_on_window_s=turn_on_window_s)


__all__ = ["evaluate"]
