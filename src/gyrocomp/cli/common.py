"""What the commands share: reading files with the common options, the console, the progress bar, option parsing."""

from __future__ import annotations

import math

import contextlib
import sys
from pathlib import Path

import click
from rich.console import Console
from rich.progress import BarColumn, Progress, TaskProgressColumn, TextColumn, TimeElapsedColumn

from ..errors import InputError
from ..io import FORMATS, ReadOptions, TableLayout, parse_column_mapping, read_input
from ..curves.network import DEFAULT_HIDDEN
from ..models.options import Network, Polynomial
from ..models.pipelines import check_channels
from ..recording.prepared import CHANNELS
from ..curves.polynomial import MAX_ORDER


def make_console() -> Console:
    return Console(width=None if sys.stdout.isatty() else 160, highlight=False, markup=False)


def read_options(func):
    """Options every command that reads data files shares."""
    options = [
        click.option("--columns", "columns", metavar="CH=COL,...",
                     help="Map channels to the file's columns, e.g. gyro_z=GyrZ,temperature=T."),
        click.option("--gyro-unit", default="deg/s", show_default=True, help="deg/s, rad/s or mdps."),
        click.option("--accel-unit", default="g", show_default=True, help="g, mg or m/s2."),
        click.option("--time-unit", default="s", show_default=True, help="s, ms, us or ns."),
        click.option("--format", "fmt", default=None,
                     help=f"Input format (default: told from the file): {', '.join(FORMATS)}."),
        click.option("--delimiter", default=None,
                     help="CSV field separator (default: told from the header: comma, semicolon or tab; 'tab' for a tab)."),
        click.option("--decimal", default=None, help="CSV decimal point, . or , (default: told from the first row)."),
        click.option("--drop-nan", is_flag=True, help="Drop rows with empty/NaN values (says how many) instead of refusing the file."),
        click.option("--instance", default=None, metavar="N",
                     help="Sensor instance in PX4/ArduPilot logs (uORB multi_id, IMU number from 0; default 0); "
                          "fit: all fits every instance, one model file each."),
        click.option("--device-id", "device_id", type=int, default=None, help="PX4 device id of the gyro to read."),
        click.option("--imu-topic", default=None, help="ROS bag: the sensor_msgs/Imu topic (default: the only one)."),
        click.option("--temperature-topic", default=None,
                     help="ROS bag: the sensor_msgs/Temperature topic (default: the only one)."),
        click.option("--record", default=None, help="ArduPilot log: IMU (default) or TCLR (onboard learning records)."),
        click.option("--time", "time_range", default=None, metavar="A:B",
                     help="Only the samples from A to B seconds after the file's first ([A, B); A: or :B open)."),
    ]
    for option in reversed(options):
        func = option(func)
    return func


def table_layout(columns, gyro_unit, accel_unit, time_unit, delimiter=None, decimal=None) -> TableLayout:
    return TableLayout(parse_column_mapping(columns), gyro_unit, accel_unit, time_unit,
                       "\t" if delimiter == "tab" else delimiter, decimal)


READ_OPTIONS = ("columns", "gyro_unit", "accel_unit", "time_unit", "fmt", "drop_nan", "instance", "device_id",
                 "imu_topic", "temperature_topic", "record", "delimiter", "decimal", "time_range")


def parse_time_range(text: str | None) -> tuple[float | None, float | None] | None:
    """``--time A:B`` -> (A, B) [s from the file's first sample]; an empty side is open."""
    if text is None:
        return None
    parts = text.split(":")
    try:
        if len(parts) != 2:
            raise ValueError
        bounds = tuple(None if p.strip() == "" else float(p) for p in parts)
    except ValueError:
        raise click.BadParameter(f"{text!r}: give A:B in seconds from the file's start (A: or :B for an open end)",
                                 param_hint="--time") from None
    if any(b is not None and not math.isfinite(b) for b in bounds) or bounds == (None, None):
        raise click.BadParameter(f"{text!r}: give finite seconds on at least one side", param_hint="--time")
    return bounds


@contextlib.contextmanager
def progress_bar(description: str, indeterminate: bool = False):
    """A progress callback drawing a bar on stderr when it is a terminal and --quiet is off; else None.
    ``indeterminate``: a pulsing bar for work that does not report its fraction done."""
    ctx = click.get_current_context(silent=True)
    quiet = bool(ctx and ctx.find_root().obj and ctx.find_root().obj.get("quiet"))
    if quiet or not sys.stderr.isatty():
        yield None
        return
    with Progress(TextColumn("{task.description}"), BarColumn(), TaskProgressColumn(), TimeElapsedColumn(),
                  console=Console(stderr=True), transient=True) as bar:
        task = bar.add_task(description, total=None if indeterminate else 1.0)
        yield lambda fraction: bar.update(task, completed=min(max(fraction, 0.0), 1.0))


def read_settings(opts: dict, channels: tuple[str, ...] | None = None) -> ReadOptions:
    """The :class:`ReadOptions` the common reading options (``pop_read_options``) give; ``channels``: a table's
    channels to read (None: all)."""
    layout = table_layout(opts["columns"], opts["gyro_unit"], opts["accel_unit"], opts["time_unit"], opts["delimiter"],
                          opts["decimal"])
    return ReadOptions(layout=layout, drop_nonfinite=opts["drop_nan"], instance=parse_instance(opts["instance"]),
                       device_id=opts["device_id"], imu_topic=opts["imu_topic"],
                       temperature_topic=opts["temperature_topic"], record=opts["record"], channels=channels,
                       time_range_s=parse_time_range(opts["time_range"]))


def parse_instance(text: str | int | None) -> int | None:
    """``--instance``: a whole number >= 0 (``all`` is taken by ``gyrocomp fit`` before reading)."""
    if text is None or isinstance(text, int):
        return text
    if text.strip().lower() == "all":
        raise click.BadParameter("all is for gyrocomp fit (one model per instance); give a number here",
                                 param_hint="--instance")
    try:
        value = int(text)
    except ValueError:
        raise click.BadParameter(f"{text!r}: give a whole number >= 0 (or all, in gyrocomp fit)",
                                 param_hint="--instance") from None
    if value < 0:
        raise click.BadParameter(f"{value}: give a whole number >= 0", param_hint="--instance")
    return value


def read_run(path, opts: dict, channels: tuple[str, ...] | None = None):
    with progress_bar(f"reading {Path(path).name}") as progress:
        return read_input(path, read_settings(opts, channels), fmt=opts["fmt"], progress=progress)


def pop_read_options(kwargs: dict) -> dict:
    return {k: kwargs.pop(k) for k in READ_OPTIONS}


def parse_hidden(text: str) -> tuple[int, ...]:
    """``"mlp"`` -> (3,), ``"mlp:5"`` -> (5,), ``"mlp:5x4"`` -> (5, 4)."""
    text = text.strip().lower()
    if text == "mlp":
        return DEFAULT_HIDDEN
    try:
        hidden = tuple(int(h) for h in text.split(":", 1)[1].split("x"))
    except (IndexError, ValueError):
        hidden = ()
    if not hidden or any(h < 1 or h > 50 for h in hidden) or len(hidden) > 3:
        raise InputError(f"--temperature: {text!r}; use mlp, mlp:H (H hidden tanh neurons, 1..50) or mlp:HxH")
    return hidden


def parse_temperature_option(text: str, seed: int = 0) -> Polynomial | Network | None:
    """``"poly"`` -> ``Polynomial()``, ``"poly:3"`` -> ``Polynomial(3)``, ``"mlp"``/``"mlp:5"`` -> ``Network(hidden,
    seed)``, ``"none"`` -> None."""
    text = text.strip().lower()
    if text == "mlp" or text.startswith("mlp:"):
        return Network(parse_hidden(text), seed)
    if text in ("poly", "auto"):
        return Polynomial()
    if text == "none":
        return None
    if text.startswith("poly:"):
        try:
            order = int(text[5:])
        except ValueError:
            order = -1
        if 0 <= order <= MAX_ORDER:
            return Polynomial(order)
        raise InputError(f"--temperature: {text!r}: the order must be a whole number from 0 to {MAX_ORDER}")
    raise InputError(f"--temperature: {text!r}: use poly (automatic order), poly:N (N = 0..{MAX_ORDER}), "
                     "mlp (the thesis's 1-3-1 network), mlp:H or none")


def parse_channels(text: str) -> tuple[str, ...]:
    """``--channels``: ``"gyro,accel"`` -> ``("gyro", "accel")``, checked by the library."""
    items = tuple(c.strip().lower() for c in text.split(",") if c.strip())
    unknown = [c for c in items if c not in CHANNELS]
    if unknown or not items:
        raise InputError(f"--channels: {','.join(unknown) or repr(text)}: use gyro, accel or gyro,accel")
    return check_channels(items)


class FiniteFloat(click.ParamType):
    """A number option: finite (``inf`` and ``nan`` are refused in one line naming the option), printed short."""

    name = "number"

    def convert(self, value, param, ctx):
        if isinstance(value, float) and math.isfinite(value):
            return value
        try:
            number = float(value)
        except (TypeError, ValueError):
            self.fail(f"{str(value)[:40]!r} is not a number", param, ctx)
        if not math.isfinite(number):
            self.fail(f"{number} is not a finite number", param, ctx)
        return number


#: the type of every number option
FINITE = FiniteFloat()


def float_list(text: str | None, option: str) -> tuple[float, ...] | None:
    if text is None:
        return None
    try:
        values = tuple(float(v) for v in text.split(",") if v.strip())
    except ValueError:
        values = ()
    if not values:
        raise click.BadParameter("give comma-separated numbers, e.g. -20,70", param_hint=option)
    if not all(math.isfinite(v) for v in values):
        raise click.BadParameter(f"{text[:40]!r}: give finite numbers", param_hint=option)
    return values


__all__ = ["FINITE", "FiniteFloat", "READ_OPTIONS", "make_console", "float_list", "parse_channels", "parse_hidden", "parse_temperature_option", "pop_read_options", "parse_instance", "progress_bar", "read_options", "read_run", "read_settings", "table_layout"]
