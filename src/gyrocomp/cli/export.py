"""``gyrocomp export``: parse its options, call the library, print the result."""

from __future__ import annotations

import click

from ..calibration import Calibration
from ..io import refuse_to_overwrite_inputs
from ..export import EXPORTERS, ExportOptions, export_to, format_of
from ..fitting.online import LearnerSettings, OnlineCalibrator
from .common import FINITE, echo


#: the formats gyrocomp export offers (the model file itself is already a file: fleet export offers json too)
EXPORT_FORMATS = tuple(name for name in EXPORTERS if name != "json")


@click.command()
@click.argument("model", type=click.Path())
@click.option(
    "--format",
    "fmt",
    type=click.Choice(EXPORT_FORMATS),
    default=None,
    help="; ".join(EXPORTERS[name].help() for name in EXPORT_FORMATS) + "; default: the one -o's name says.",
)
@click.option("-o", "--output", required=True, type=click.Path(), help="Parameter file to write (c: a folder).")
@click.option(
    "--rate",
    "rate_hz",
    type=FINITE,
    default=None,
    help="c: the sample rate the code will run at [Hz] (needed when the model has thermal lag).",
)
@click.option(
    "--instance",
    type=int,
    default=None,
    help="Sensor instance: PX4 gyro 0..3 (default 0), ArduPilot IMU 1..3 (default 1).",
)
@click.option(
    "--device-id",
    type=int,
    default=None,
    help="PX4: the gyro's device id (TC_G*_ID; default: the one the model's ULog runs recorded).",
)
@click.option(
    "--accel-device-id",
    type=int,
    default=None,
    help="PX4: the accelerometer's device id (TC_A*_ID, CAL_ACC*_ID; default: the model's).",
)
@click.option(
    "--learner",
    "learner_state",
    type=click.Path(dir_okay=False),
    default=None,
    help="c: bake the online learner's settings from this learner state (gyrocomp learn --save-state) "
    "instead of the defaults.",
)
@click.pass_context
def export(ctx, model, fmt, output, rate_hz, instance, device_id, accel_device_id, learner_state):
    """Write MODEL as autopilot parameters (temperature cubic, accelerometer offsets and scales) or as C code."""

    refuse_to_overwrite_inputs(output, [model] + ([learner_state] if learner_state else []))
    fmt = fmt or format_of(output, EXPORT_FORMATS)
    if learner_state is not None and fmt != "c":
        raise click.BadParameter("the learner is exported with --format c only", param_hint="--learner")
    settings = OnlineCalibrator.load(learner_state).settings if learner_state else None
    write_export(
        Calibration.load(model),
        fmt,
        output,
        rate_hz=rate_hz,
        instance=instance,
        device_id=device_id,
        accel_device_id=accel_device_id,
        quiet=ctx.obj["quiet"],
        learner=settings,
    )


def write_export(
    calibration: Calibration,
    fmt: str,
    output,
    *,
    rate_hz=None,
    instance=None,
    device_id: int | None = None,
    accel_device_id: int | None = None,
    quiet: bool = False,
    learner: LearnerSettings | None = None,
) -> None:
    """Write ``calibration`` as ``fmt`` (:func:`gyrocomp.export.exporters.export_to`) and say what was written."""
    done = export_to(
        calibration,
        fmt,
        output,
        ExportOptions(
            rate_hz=rate_hz,
            instance=instance,
            device_id=device_id,
            accel_device_id=accel_device_id,
            learner=learner,
            judge_firmware=not quiet,
        ),
    )
    if quiet:
        return
    echo("wrote " + " and ".join(str(p) for p in done.written))
    for line in done.notes:
        echo(line)
    if done.firmware is not None:
        for line in done.firmware.lines():
            echo(line)


__all__ = ["EXPORT_FORMATS", "export", "write_export"]
