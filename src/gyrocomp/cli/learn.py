"""``gyrocomp learn``: replay logs through the online learner; parse its options, call the library, print the result."""

from __future__ import annotations

import contextlib
import itertools

import click

from ..errors import InputError, NotFittedError
from ..io import refuse_to_overwrite_inputs
from ..io.atomic import folder_lock, write_texts_atomic
from ..io.inputs import expand_runs
from ..fitting.online import GYRO_AXES, LearnerSettings, OnlineCalibrator, replay
from .common import FINITE, OUTPUT_FILE, pop_read_options, read_options, read_run
from .render import print_learner


@click.command()
@click.argument("logs", nargs=-1, required=True, type=click.Path())  # files, folders of logs, or quoted globs
@click.option(
    "-o",
    "--output",
    required=True,
    type=OUTPUT_FILE,
    help="Model file to write (JSON; gyrocomp apply and export take it).",
)
@click.option(
    "--resume",
    "resume",
    type=click.Path(dir_okay=False),
    default=None,
    help="A learner state saved by --save-state: go on from it (the logs are later power-ons).",
)
@click.option(
    "--save-state",
    "save_state",
    type=OUTPUT_FILE,
    default=None,
    help="Write the learner's whole state here (JSON), to go on later with --resume.",
)
@click.option(
    "--degree",
    type=click.Choice(["1", "2", "3"]),
    default="3",
    show_default=True,
    help="Highest degree of the temperature curve (used once the still data span enough).",
)
@click.option(
    "--bin-width",
    "bin_width_degc",
    type=FINITE,
    default=1.0,
    show_default=True,
    help="Temperature bin of the learner's points [degC].",
)
@read_options
@click.pass_context
def learn(ctx, logs, output, resume, save_state, degree, bin_width_degc, **kwargs):
    """Learn a temperature model from the still moments of LOGS, as the online learner would on the vehicle:
    each log one power-on, replayed in the order given.

    LOGS are files, folders (every log file in them, in name order) or quoted glob patterns ('logs/**/*.ulg')."""
    opts = pop_read_options(kwargs)
    paths = expand_runs(logs)
    outputs = [p for p in (output, save_state) if p is not None]
    for out in outputs:
        refuse_to_overwrite_inputs(out, paths + ([resume] if resume else []), "-o" if out == output else "--save-state")
    if save_state is not None and save_state == output:
        raise click.BadParameter("give the state a file of its own, not the model's", param_hint="--save-state")
    recordings = (read_run(path, opts).recording for path in paths)
    if resume is not None:
        learner = OnlineCalibrator.load(resume)
        rate_hz = opts["rate_hz"]
        if rate_hz is not None and rate_hz != learner.settings.rate_hz:
            raise InputError(f"--rate {rate_hz:g}: the resumed learner runs at {learner.settings.rate_hz:g} Hz")
    else:
        first = next(recordings)
        settings = LearnerSettings(rate_hz=first.rate_hz, degree=int(degree), bin_width_degc=bin_width_degc)
        learner = OnlineCalibrator(settings)
        recordings = itertools.chain([first], recordings)
    if save_state is not None:
        learner.check_state_target(save_state)  # before the logs are replayed; again under the lock below
    contributions = replay(learner, recordings)
    try:
        model = learner.to_calibration(
            axes=[a for a in GYRO_AXES if any(a in c.gyro_axes for c in contributions)], contributions=contributions
        )
    except NotFittedError as exc:  # no still piece in any log: bad input, not a failure
        raise InputError(str(exc)) from None
    texts = {output: model.to_json()}
    with contextlib.ExitStack() as held:
        if save_state is not None:  # no other learner saves between this check and the write
            held.enter_context(folder_lock(save_state))
            learner.check_state_target(save_state)
            learner.mark_saved()
            learner.new_revision()
            texts[save_state] = learner.to_json()
        write_texts_atomic(".", texts)
    if not ctx.obj["quiet"]:
        print_learner(learner, contributions, output)


__all__ = ["learn"]
