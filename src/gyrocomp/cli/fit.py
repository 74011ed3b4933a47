"""``gyrocomp fit``: parse its options, call the library, print the result."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from ..errors import InputError
from ..io import instances, refuse_to_overwrite_inputs
from ..io.atomic import write_texts_atomic
from ..io.inputs import expand_runs
from ..io.schedule import apply_schedule, read_rate_schedule
from ..fitting.acceleration import ACCELERATION_CHOICES
from ..models.field import field_recordings
from ..models.options import FitOptions
from ..models.fit import fit as fit_runs
from ..models.triads import SCALE_FACTOR_CHOICES
from ..fitting.folds import FOLD_KINDS
from ..fitting.thermal import HYSTERESIS_CHOICES
from ..files.check import ask_for, enforce, read_noting, refuse
from ..measures.data_check import check_runs
from .common import (
    accept_option,
    FINITE,
    OUTPUT_FILE,
    hysteresis_band,
    instance_model_path,
    parse_channels,
    parse_temperature_option,
    pop_read_options,
    progress_bar,
    read_options,
    read_whole_run,
    temperature_help,
)
from .render import print_contributions, print_fit


@click.command()
@click.argument("runs", nargs=-1, required=True, type=click.Path())  # files, folders of runs, or quoted globs
@click.option("-o", "--output", required=True, type=OUTPUT_FILE, help="Model file to write (JSON).")
@click.option("--temperature", default="auto", show_default=True, help=temperature_help())
@click.option(
    "--seed",
    "mlp_seed",
    type=int,
    default=0,
    show_default=True,
    help="Seed of the network's initializations (mlp); the same seed gives the same model.",
)
@click.option(
    "--bin-width", "bin_width_degc", type=FINITE, default=None, help="Temperature bin width [degC] (default: span/100)."
)
@click.option(
    "--hysteresis",
    type=click.Choice(HYSTERESIS_CHOICES),
    default="auto",
    show_default=True,
    help="The thermal memory: lag, turning-point hysteresis, a turning-point table (turning-table: a memory of any "
    "shape in the distance from the last turn, one after a maximum and one after a minimum), heating/cooling "
    "branches, a bank of plays (play-bank: backlash operators of several widths, a loop of any shape) or a "
    "temperature-rate term (rate: a bias in the smoothed dT/dt, a thermal gradient); auto compares them by "
    "held-out drift when the runs both heat and cool (all but the turning-point table and the bank of plays).",
)
@click.option(
    "--hysteresis-order",
    default="auto",
    show_default=True,
    help="Order of the turning-point polynomial in |T - T_turn|: auto (validated) or 1..3.",
)
@click.option(
    "--hysteresis-band",
    "hysteresis_band_degc",
    default=None,
    metavar="LO,HI",
    help="Limit the hysteresis to this temperature band [degC], e.g. 55,80.",
)
@click.option(
    "--acceleration",
    type=click.Choice(["auto", *ACCELERATION_CHOICES]),
    default="auto",
    show_default=True,
    help="g-sensitivity fitted jointly on the static segments: matrix (3x3), matrix2 (+ g x g terms), "
    "none; auto: matrix when the runs turn the unit between positions.",
)
@click.option(
    "--pipeline",
    default="joint",
    show_default=True,
    help="joint (temperature, lag/hysteresis, G and run constants in one fit), or a cascade fitted stage by "
    "stage: 'poly>matrix', 'matrix>poly', 'mlp>matrix', or 'joint-mlp' (one network reading the "
    "temperature and the three accelerations). Quote the > in a shell.",
)
@click.option(
    "--min-static",
    "static_min_duration_s",
    type=FINITE,
    default=10.0,
    show_default=True,
    help="Shortest still stretch used as a static position [s].",
)
@click.option(
    "--channels",
    default="gyro",
    show_default=True,
    help="What to model: gyro, accel (the accelerometer's bias against temperature, in g) or gyro,accel "
    "(then G reads the temperature-compensated accelerations).",
)
@click.option(
    "--folds",
    type=click.Choice(FOLD_KINDS),
    default="auto",
    show_default=True,
    help="What the model choice holds out: each run, each heating or cooling leg, or time blocks; "
    "auto: runs with three runs or more, else legs.",
)
@click.option(
    "--target",
    type=click.Choice(["model", "px4", "ardupilot"]),
    default="model",
    show_default=True,
    help="px4 or ardupilot: the best model that firmware carries (a cubic at most, chosen by the same "
    "held-out validation, held at the range's edges as the firmware clamps, no lag or hysteresis), so "
    "that apply computes what the exported file will.",
)
@click.option(
    "--scale-factor",
    "scale_factor",
    type=click.Choice(SCALE_FACTOR_CHOICES),
    default="auto",
    show_default=True,
    help="Gyro scale factor and misalignment from the runs with ref_rate_x/y/z columns (rate table) or, "
    "without them, from the turns between the still poses of multi-position runs: matrix (constant), "
    "matrix-temperature (linear in temperature), none; auto: when such runs are given, the order by "
    "leave-one-run-out.",
)
@click.option(
    "--rate-schedule",
    "rate_schedule",
    type=click.Path(),
    default=None,
    metavar="FILE",
    help="A rate table's schedule (CSV: file,start_s,end_s,ref_rate_x,ref_rate_y,ref_rate_z [deg/s]) "
    "giving the reference rates of the runs it names, instead of ref_rate_x/y/z columns.",
)
@click.option(
    "--still-only",
    "still_only",
    type=click.Choice(["auto", "yes", "no"]),
    default="auto",
    show_default=True,
    help="Fit on the still segments of field logs (flights, drives: each one power-on) found from their "
    "own noise: yes for every run, auto for the runs still less than half the time, no for none.",
)
@accept_option
@read_options
@click.pass_context
def fit(
    ctx,
    runs,
    output,
    temperature,
    mlp_seed,
    bin_width_degc,
    hysteresis,
    hysteresis_order,
    hysteresis_band_degc,
    acceleration,
    pipeline,
    static_min_duration_s,
    channels,
    folds,
    target,
    scale_factor,
    rate_schedule,
    still_only,
    accept,
    **kwargs,
):
    """Fit a compensation model on calibration RUNS (each one power-on, the gyro at rest), or on the still
    moments of field logs. The runs are checked first (as gyrocomp check does): a run that cannot give a valid
    fit is refused in one line, one that only degrades it is said with its expected cost.

    RUNS are files, folders (every run file in them) or quoted glob patterns ('logs/**/*.ulg')."""
    opts = pop_read_options(kwargs)
    channels = parse_channels(channels)
    options = FitOptions(
        temperature=parse_temperature_option(temperature, mlp_seed),
        bin_width_degc=bin_width_degc,
        hysteresis=hysteresis,
        hysteresis_order=_hysteresis_order(hysteresis_order),
        hysteresis_band_degc=hysteresis_band(hysteresis_band_degc),
        acceleration=acceleration,
        static_min_duration_s=static_min_duration_s,
        folds=folds,
        target=target,
    )
    runs = expand_runs(runs)
    refuse_to_overwrite_inputs(output, runs)
    every = str(opts["instance"]).strip().lower() == "all"
    chosen = _common_instances(runs, opts["fmt"]) if every else [None]
    fits = {}
    for instance in chosen:
        read_opts = {**opts, "instance": instance if every else opts["instance"]}
        recordings = _checked_runs(runs, read_opts, rate_schedule, still_only, options, accept, ctx.obj["quiet"])
        with progress_bar("fitting" + (f" instance {instance}" if every else ""), indeterminate=True):
            fits[instance] = fit_runs(
                recordings, options, channels=channels, pipeline=pipeline, scale_factor=scale_factor
            )
    _print_and_write(fits, output, every, ctx.obj["quiet"])


def _checked_runs(runs, read_opts: dict, rate_schedule, still_only, options: FitOptions, accept, quiet: bool):
    """The runs read (through the rate schedule, field logs reduced to their still moments) and checked as
    gyrocomp check does (a run that cannot give a valid fit refused)."""
    read = [read_noting(lambda p, o=read_opts: read_whole_run(p, o), path) for path in runs]
    recordings = [r.recording for r in read]
    if rate_schedule is not None:
        recordings = apply_schedule(read_rate_schedule(rate_schedule), recordings, list(runs))
    try:
        recordings, contributions = field_recordings(recordings, still_only)
    except InputError as exc:  # no still data: a run refused by the data check, or read in the wrong unit, says why
        moving = [r.recording.source for r in read if r.recording is not None]  # motion is not the question here
        checks = check_runs(read, ask_for(options), accept, still_only=moving)
        refuse(checks)
        reading = ("counts", "unit")  # raw counts first: they explain a unit out of range
        why = sorted(
            (f for c in checks for f in c.findings if f.check in reading), key=lambda f: reading.index(f.check)
        )
        if why:
            raise InputError(f"{exc}; it may be read wrongly: {why[0].message}") from None
        raise
    enforce(check_runs(read, ask_for(options), accept, still_only=[c.source for c in contributions if c.still_only]))
    if not quiet and any(c.still_only for c in contributions):
        print_contributions(contributions)
    return recordings


def _hysteresis_order(value: str) -> int | str:
    """--hysteresis-order: auto, or 1, 2 or 3."""
    if value == "auto":
        return value
    if value not in ("1", "2", "3"):
        raise click.BadParameter("use auto, 1, 2 or 3", param_hint="--hysteresis-order")
    return int(value)


def _print_and_write(fits: dict, output: str, every: bool, quiet: bool) -> None:
    """Say what each fit found, then write its model file (with every instance, one file each, all or none)."""
    out = Path(output)
    names = {instance: instance_model_path(out, instance).name for instance in fits} if every else {None: out.name}
    written = {i: out.parent / names[i] for i in fits}
    # what the fit found is printed before the files are written: a standard output that fails (a full disk
    # behind > file) fails the command before it leaves a model file, not after
    if not quiet:
        for instance, calibration in fits.items():
            print_fit(calibration, written[instance])
        sys.stdout.flush()
    if every:  # one model file per instance, all written or none
        write_texts_atomic(out.parent, {names[i]: c.to_json() for i, c in fits.items()})
    else:
        fits[None].save(output)


def _common_instances(runs: list[str], fmt: str | None) -> list[int]:
    """The sensor instances of every run (``--instance all``); a run missing one another run has is refused."""
    found = {path: instances(path, fmt) for path in runs}
    every = sorted(set().union(*found.values()))
    for path, have in found.items():
        lacking = [i for i in every if i not in have]
        if lacking:
            raise InputError(
                f"{path}: no instance {lacking[0]} (it has {', '.join(map(str, have))}); --instance all "
                "fits each instance on every run, so every run must hold the same instances"
            )
    return every


__all__ = ["fit"]
