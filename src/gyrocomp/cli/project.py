"""``gyrocomp init`` (write a project file from a log) and ``gyrocomp config show`` (print the one in use); the
file itself: :mod:`gyrocomp.cli.projectfile`."""

from __future__ import annotations

import datetime as _dt
import json
import shlex
import sys
from pathlib import Path

import click

from ..errors import InputError, printable
from ..io import format_spelling, refuse_to_overwrite_inputs, write_text_atomic
from ..io.project import FORMAT_KEY
from ..io.guess import HeaderlessTable, guess_layout
from ..io.serial import parse_names, parse_rate
from .common import OUTPUT_FILE, make_console, echo
from .projectfile import PROJECT_FILE, PROJECT_KEY


#: TOML's short escapes in a basic string
_TOML_ESCAPES = {'"': '\\"', "\\": "\\\\", "\b": "\\b", "\t": "\\t", "\n": "\\n", "\f": "\\f", "\r": "\\r"}


def _toml_text(value) -> str:
    """A value as TOML: a string quoted (a basic string: quotes, backslashes and control characters escaped, so a
    name cannot end the value or add a line), a number or a boolean as it is."""
    if not isinstance(value, str):
        return json.dumps(value)
    return '"' + "".join(_TOML_ESCAPES.get(c) or _toml_char(c) for c in value) + '"'


def _toml_char(c: str) -> str:
    if ord(c) < 0x20 or ord(c) == 0x7F:
        return f"\\u{ord(c):04X}"
    if 0xD800 <= ord(c) < 0xE000:  # a byte of a name that is not UTF-8 (a surrogate escape): TOML has no spelling
        raise InputError(f"{c!r}: a name that is not UTF-8 cannot be written into the project file; rename it")
    return c


@click.command()
@click.argument("log", type=click.Path())
@click.option(
    "-o", "--output", default=PROJECT_FILE, show_default=True, type=OUTPUT_FILE, help="The project file to write."
)
@click.option("--force", is_flag=True, help="Replace an existing project file.")
@click.option(
    "--names",
    default=None,
    metavar="NAME,...",
    help="A table without a header line (a serial terminal's log): its columns' names in order, e.g. "
    "gyro_x,gyro_y,gyro_z,temperature (asked for in a terminal).",
)
@click.option(
    "--rate",
    "rate_hz",
    default=None,
    metavar="HZ",
    help="The rows' sample rate [Hz], for a table without a time column.",
)
@click.option("--format", "fmt", default=None, help=format_spelling().help)
@click.pass_context
def init(ctx, log, output, force, names, rate_hz, fmt):
    """Write a project file for LOG's kind of table: its columns and units guessed from their names and
    magnitudes, said one by one, read by every command run in this folder (a file of named arrays, HDF5, MAT or
    .npz: the same from its arrays). A table without a header line (a serial terminal's log) needs its columns'
    names, in order, once: --names, or asked for in a terminal."""
    refuse_to_overwrite_inputs(output, [log], option="-o")
    if Path(output).exists() and not force:
        raise InputError(f"{output}: exists; give --force to replace it, or -o another file")
    rate_hz = None if rate_hz is None else parse_rate(rate_hz)
    try:
        guess = guess_layout(log, None if names is None else parse_names(names), rate_hz, fmt)
    except HeaderlessTable as exc:
        if not sys.stdin.isatty():
            raise InputError(
                f"{log}: a table without a header line, rows of {exc.count} numbers (e.g. "
                f"{exc.example!r}); give their names in order with --names (e.g. --names "
                "gyro_x,gyro_y,gyro_z,temperature), and --rate HZ if it has no time column"
            ) from None
        echo(f"{log} has no header line; its rows hold {exc.count} numbers, e.g. {exc.example}")
        names = click.prompt(
            f"their {exc.count} names in order (time, gyro_x..z, accel_x..z, temperature; "
            "any other name leaves a column unused)"
        )
        if rate_hz is None and "time" not in parse_names(names):
            rate_hz = parse_rate(click.prompt("no time column: the rows' sample rate [Hz]"))
        guess = guess_layout(log, parse_names(names), rate_hz, fmt)
    layout = guess.layout
    write_text_atomic(output, _project_text(log, guess, fmt))
    if not ctx.obj["quiet"]:
        echo(f"wrote {output} from {log}:")
        for reason in guess.reasons:
            echo(f"  {reason}")
        if guess.unused:
            echo(f"  columns not used: {', '.join(n if n.strip() else repr(n) + ' (unnamed)' for n in guess.unused)}")
        name = shlex.quote(Path(log).name)
        if any(channel.startswith("temperature") for channel in layout.columns):
            echo(f"check the units above; then e.g. gyrocomp fit {name} -o model.json")
        else:  # a fit needs a temperature; a log without one still gives its noise
            echo(
                f"check the units above; the file has no temperature, so no temperature model can be fitted "
                f"from it: its noise is measured by gyrocomp noise {name} (or gyrocomp allan {name})"
            )


def _project_text(log, guess, fmt: str | None) -> str:
    """The project file's text for the layout ``guess`` made of ``log``: the reasons as comments (escaped), then
    [read] (the units, the format, the delimiter, the names, the rate) and [read.columns]."""
    layout = guess.layout
    lines = [
        f"# gyrocomp project file: written by `gyrocomp init {printable(Path(log).name)}` on "
        f"{_dt.date.today().isoformat()}; every gyrocomp command run in this folder reads it",
        "# (an option on the command line wins; `gyrocomp config show` prints what is in use)",
        *(f"# {printable(reason)}" for reason in guess.reasons),
        "",
        "[read]",
        "# channel = the file's column",
        "[read.columns]",
    ]
    lines += [f"{channel} = {_toml_text(column)}" for channel, column in layout.columns.items()]
    read = {"gyro-unit": layout.gyro_unit, "accel-unit": layout.accel_unit, "time-unit": layout.time_unit}
    if fmt is not None:  # a format the file's name does not tell (a text matrix named .mat): every command reads so
        read[FORMAT_KEY] = fmt
    if layout.delimiter is not None:
        read["delimiter"] = "tab" if layout.delimiter == "\t" else layout.delimiter
    if layout.names is not None:
        read["names"] = ",".join(layout.names)
    if layout.rate_hz is not None:
        read["rate"] = layout.rate_hz
        if "time" not in layout.columns:  # rows read at the rate: a time column the file may have is left unread
            lines.append('time = ""')
    # TOML: a table's keys come before its sub-tables, so the units go in a [read] written before [read.columns]
    head = lines.index("[read]")
    lines[head + 1 : head + 1] = [f"{k} = {_toml_text(v)}" for k, v in read.items()]
    return "\n".join(lines) + "\n"


@click.group()
def config():
    """The project file in use (gyrocomp.toml in this folder, or --config)."""


@config.command("show")
@click.option("--json", "as_json", is_flag=True, help="Print it as JSON.")
@click.pass_context
def show(ctx, as_json):
    """Print the project file in use and the options it gives each command."""
    project = ctx.meta.get(PROJECT_KEY)  # loaded by the command group, before any command runs
    if project is None:
        echo(f"no project file: no {PROJECT_FILE} in {Path.cwd()} and no --config")
        return
    data = {"path": project.path, "read": project.read, "defaults": project.defaults, "commands": project.commands}
    if as_json:
        echo(json.dumps(data, indent=2), lines=True)
        return
    console = make_console()
    console.print(f"project file: {project.path}")
    for section, options in (("read", project.read), ("defaults", project.defaults), *project.commands.items()):
        if options:
            console.print(f"[{section}]")
            for key, value in options.items():
                console.print(f"  {key} = {value!r}")


__all__ = ["config", "init"]
