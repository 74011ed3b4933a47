"""What the commands share: reading files with the common options, the console, the progress bar, option parsing."""

from __future__ import annotations

import math

import contextlib
import sys
from pathlib import Path

import click
from rich.console import Console
from rich.progress import BarColumn, Progress, TaskProgressColumn, TextColumn, TimeElapsedColumn

from ..errors import InputError, printable
from ..option_spelling import Spelling, from_values, spelled_fields
from .projectfile import ReadingOption
from ..io import ReadOptions, format_spelling, read_input
from ..io.tables import layout_fits, table_header
from ..io.atomic import check_output_file
from ..files.chunks import read_whole
from ..curves.network import DEFAULT_HIDDEN
from ..curves.kinds import BASES
from ..models.options import Curve, Network, Polynomial, curve_size_range, family_help
from ..models.fit import check_channels
from ..runs.prepared import CHANNELS
from ..measures.data_check import DATA_CHECKS
from ..curves.polynomial import POLY_FAMILY


class OutputFile(click.Path):
    """A file option or argument an output is written to, checked as it is parsed, before any work
    (:func:`gyrocomp.io.atomic.check_output_file`: not ``-`` or standard output, not a name ending in ``/``, not a
    symbolic link, a folder or a FIFO)."""

    def __init__(self):
        super().__init__(dir_okay=False)

    def convert(self, value, param, ctx):
        value = super().convert(value, param, ctx)
        check_output_file(value)
        return value


#: the type of every option or argument naming an output file
OUTPUT_FILE = OutputFile()


class _InertConsole(Console):
    """A console that shows text as it is: no markup, and control and bidirectional characters escaped
    (:func:`gyrocomp.errors.printable`) in every text it renders, a table's cells and titles too (a serial, a
    station's or a file's name holding a terminal's escape sequence cannot reach the terminal)."""

    def render_str(self, text: str, **kwargs):
        return super().render_str(printable(text, lines=True), **kwargs)


def make_console() -> Console:
    return _InertConsole(width=None if sys.stdout.isatty() else 160, highlight=False, markup=False)


def echo(message: str, err: bool = False, lines: bool = False) -> None:
    """``click.echo`` of a one-line message with control and bidirectional characters escaped, a newline too (a
    file's name cannot break the line); ``lines``: a text of several lines (JSON), its newlines kept."""
    click.echo(printable(str(message), lines=lines), err=err)


def _parsed(parse):
    """A click callback giving the option's value as its spelling parses it (errors name the field, which the
    command line shows as the flag)."""
    return lambda ctx, param, value: parse(value) if isinstance(value, str) else value


def click_option(name: str, spelling: Spelling, default=None):
    """The click option of a typed field (:mod:`gyrocomp.option_spelling`): its flag, help and metavar, the field's name
    as the parameter's, its value parsed as the spelling says; a field's text default (a unit) is the option's
    and shown in the help, any other default (None, an empty mapping) applies when the option is not given."""
    if spelling.switch:
        # with its off form: a project file that switches it on is undone on the command line
        return click.option(
            f"{spelling.flag}/--no-{spelling.flag[2:]}", name, default=False, help=spelling.help, cls=ReadingOption
        )
    shown = isinstance(default, str)
    return click.option(
        spelling.flag,
        name,
        default=default if shown else None,
        show_default=shown,
        metavar=spelling.metavar,
        help=spelling.help,
        callback=_parsed(spelling.parse) if spelling.parse else None,
        cls=ReadingOption,
    )


#: the reading options of every command that reads data: the input's format, then the fields of ReadOptions
#: (and of its TableLayout), each defined once, where the library defines it, with its default
READ_FIELDS = (
    ("fmt", format_spelling(), None),
    *((field.name, spelling, field.default) for field, spelling in spelled_fields(ReadOptions)),
)
READ_OPTIONS = tuple(name for name, _, _ in READ_FIELDS)


def _fit_taus(ctx, param, text: str | None) -> tuple[float, float] | None:
    if text is None:
        return None
    try:
        low, high = (float(v) for v in text.split(","))
    except ValueError:
        low = high = -1.0
    if not 0 < low < high:
        raise click.BadParameter("use MIN,MAX in seconds with 0 < MIN < MAX, e.g. 3,1000", param_hint="--fit-taus")
    return low, high


def fit_taus_option():
    """``--fit-taus MIN,MAX`` [s]: the taus the descriptive IEEE 952 noise fit uses (allan, noise)."""
    return click.option(
        "--fit-taus",
        "fit_taus_s",
        default=None,
        metavar="MIN,MAX",
        callback=_fit_taus,
        help="Fit the noise model on taus in [MIN, MAX] s only, e.g. 3,1000 past an anti-alias filter.",
    )


def window_option():
    """``--window`` [s]: the moving average of the figures of merit (evaluate, report, plot)."""
    return click.option(
        "--window",
        "window_s",
        type=FINITE,
        default=None,
        help="Moving-average window [s] (default: tau at the raw Allan minimum, at least 1 s).",
    )


def turn_on_window_option(whose: str = "each run's"):
    """``--turn-on-window`` [s]: a run's turn-on bias from its first seconds (``whose``: the help's words)."""
    return click.option(
        "--turn-on-window",
        "turn_on_window_s",
        type=FINITE,
        default=None,
        help=f"Estimate {whose} turn-on bias from its first S seconds [s].",
    )


def read_options(func):
    """Options every command that reads data files shares."""
    for name, spelling, default in reversed(READ_FIELDS):
        func = click_option(name, spelling, default)(func)
    return func


@contextlib.contextmanager
def progress_bar(description: str, indeterminate: bool = False):
    """A progress callback drawing a bar on stderr when it is a terminal and --quiet is off; else None.
    ``indeterminate``: a pulsing bar for work that does not report its fraction done."""
    ctx = click.get_current_context(silent=True)
    quiet = bool(ctx and ctx.find_root().obj and ctx.find_root().obj.get("quiet"))
    if quiet or not sys.stderr.isatty():
        yield None
        return
    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        TaskProgressColumn(),
        TimeElapsedColumn(),
        console=Console(stderr=True),
        transient=True,
    ) as bar:
        task = bar.add_task(description, total=None if indeterminate else 1.0)
        yield lambda fraction: bar.update(task, completed=min(max(fraction, 0.0), 1.0))


def read_settings(opts: dict, channels: tuple[str, ...] | None = None) -> ReadOptions:
    """The :class:`ReadOptions` the common reading options (``pop_read_options``) give; ``channels``: a table's
    channels to read (None: all). For one file, :func:`settings_for`."""
    return from_values(ReadOptions, {**opts, "channels": channels})


#: the key of a command's reading options (``pop_read_options``) that names those its project file set
FROM_PROJECT = "set by the project file"


def settings_for(path, opts: dict, channels: tuple[str, ...] | None = None) -> ReadOptions:
    """The reading options for the file ``path``: those of ``opts``; but a table that the project file's reading
    options do not describe (none of the columns they map, or a mapping a table cannot take) while gyrocomp's own
    names do (a table gyrocomp wrote: ``split``'s, ``convert``'s) is read without what the project file set, and a
    note says so. A table that neither describes is read with ``opts``, whose error names what is missing."""
    settings = read_settings(opts, channels)
    set_there = opts.get(FROM_PROJECT, ())
    header = table_header(path) if set_there else None
    if header is None or layout_fits(header, settings.layout, path):
        return settings
    own = read_settings({**opts, **dict.fromkeys(set_there)}, channels)  # None: the field's default
    if not layout_fits(header, own.layout, path):
        return settings
    ctx = click.get_current_context(silent=True)
    if not (ctx and ctx.find_root().obj and ctx.find_root().obj.get("quiet")):
        flags = ", ".join(f"--{k.replace('_', '-')}" for k in set_there)
        echo(
            f"gyrocomp: note: {path}: read in gyrocomp's own layout (time, gyro_x ... in s, deg/s): the project "
            f"file's {flags} describe other files (this one has none of the columns they name)",
            err=True,
        )
    return own


def read_run(path, opts: dict, channels: tuple[str, ...] | None = None):
    with progress_bar(f"reading {Path(path).name}") as progress:
        return read_input(path, settings_for(path, opts, channels), fmt=opts["fmt"], progress=progress)


def read_whole_run(path, opts: dict):
    """A run for a command that needs its whole recording (``.recording``; a fit): a large file gathered from its
    chunks into temporary files (:func:`gyrocomp.files.chunks.read_whole`), so its size is not the memory's."""
    with progress_bar(f"reading {Path(path).name}") as progress:
        return read_whole(path, settings_for(path, opts), fmt=opts["fmt"], progress=progress)


def pop_read_options(kwargs: dict) -> dict:
    """The reading options of a command's parameters, and (under :data:`FROM_PROJECT`) the names of those the
    project file set."""
    opts = {k: kwargs.pop(k) for k in READ_OPTIONS}
    ctx = click.get_current_context(silent=True)
    opts[FROM_PROJECT] = tuple(
        k
        for k in READ_OPTIONS
        if ctx is not None and ctx.get_parameter_source(k) is click.core.ParameterSource.DEFAULT_MAP
    )
    return opts


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


def parse_temperature_option(text: str, seed: int = 0) -> Polynomial | Curve | Network | None:
    """``--temperature``: ``auto`` -> ``Polynomial()`` (the automatic choice), ``poly:3`` -> ``Polynomial(3)``,
    ``NAME`` or ``NAME:N`` of any registered curve family -> ``Curve(NAME)`` / ``Curve(NAME, N)`` (``table:16``),
    ``mlp``/``mlp:5`` -> ``Network(hidden, seed)``, ``none`` -> None."""
    text = text.strip().lower()
    if text == "mlp" or text.startswith("mlp:"):
        return Network(parse_hidden(text), seed)
    if text == "auto":
        return Polynomial()
    if text == "none":
        return None
    family, _, size = text.partition(":")
    if family in BASES:
        if not size:
            return Curve(family)
        try:
            return Polynomial(int(size)) if family == POLY_FAMILY else Curve(family, int(size))
        except (ValueError, InputError):
            low, top = curve_size_range(family)
            raise InputError(
                f"--temperature: {text!r}: the size of {family} must be a whole number from {low} to {top}"
            ) from None
    raise InputError(
        f"--temperature: {text!r}: use auto, {', '.join(f'{n}, {n}:N' for n in BASES)}, mlp, mlp:H or none"
    )


def temperature_help() -> str:
    """``--temperature``'s help, its curve families read from the registry."""
    return (
        "auto (the default: every polynomial order and each other curve family at its sizes, chosen by held-out "
        f"drift); {family_help()}; mlp (the thesis's 1-3-1 network, Levenberg-Marquardt), mlp:H (H hidden "
        "neurons); none."
    )


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


def hysteresis_band(text: str | None) -> tuple[float, float] | None:
    """--hysteresis-band: LO,HI [degC], LO < HI (None when not given)."""
    band = float_list(text, "--hysteresis-band")
    if band is not None and (len(band) != 2 or not band[0] < band[1]):
        raise click.BadParameter("give LO,HI in degC with LO < HI, e.g. 55,80", param_hint="--hysteresis-band")
    return None if band is None else (band[0], band[1])


__all__ = [
    "FINITE",
    "FiniteFloat",
    "READ_OPTIONS",
    "make_console",
    "float_list",
    "parse_channels",
    "parse_hidden",
    "parse_temperature_option",
    "temperature_help",
    "pop_read_options",
    "progress_bar",
    "read_options",
    "read_run",
    "read_settings",
]


def accept_option(function):
    """``--accept CHECK`` (repeatable): a data check's finding accepted knowingly (check, fit, fleet fit)."""
    return click.option(
        "--accept",
        "accept",
        multiple=True,
        type=click.Choice(DATA_CHECKS),
        metavar="CHECK",
        help=f"Accept this data check's finding knowingly (repeatable): {', '.join(DATA_CHECKS)}.",
    )(function)


def instance_model_path(model, instance: int) -> Path:
    """The model file of one sensor instance beside ``model`` (``fit -o m.json --instance all`` writes
    ``m_imu0.json``, ``m_imu1.json``, ...; ``apply m.json --instance all`` reads them)."""
    model = Path(model)
    return model.parent / f"{model.stem}_imu{instance}{model.suffix}"
