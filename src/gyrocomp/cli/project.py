"""``gyrocomp init`` (write a project file from a log) and ``gyrocomp config show`` (print the one in use); the
file itself: :mod:`gyrocomp.cli.projectfile`."""

from __future__ import annotations

import datetime as _dt
import json
from pathlib import Path

import click

from ..errors import InputError
from ..io import refuse_to_overwrite_inputs, write_text_atomic
from ..io.guess import guess_layout
from .common import OUTPUT_FILE, make_console
from .projectfile import PROJECT_FILE, PROJECT_KEY


def _toml_text(value) -> str:
    return json.dumps(value, ensure_ascii=True) if isinstance(value, str) else json.dumps(value)


@click.command()
@click.argument("log", type=click.Path())
@click.option("-o", "--output", default=PROJECT_FILE, show_default=True, type=OUTPUT_FILE,
              help="The project file to write.")
@click.option("--force", is_flag=True, help="Replace an existing project file.")
@click.pass_context
def init(ctx, log, output, force):
    """Write a project file for LOG's kind of table: its columns and units guessed from their names and
    magnitudes, said one by one, read by every command run in this folder."""
    refuse_to_overwrite_inputs(output, [log], option="-o")
    if Path(output).exists() and not force:
        raise InputError(f"{output}: exists; give --force to replace it, or -o another file")
    guess = guess_layout(log)
    layout = guess.layout
    lines = [f"# gyrocomp project file: written by `gyrocomp init {Path(log).name}` on "
             f"{_dt.date.today().isoformat()}; every gyrocomp command run in this folder reads it",
             "# (an option on the command line wins; `gyrocomp config show` prints what is in use)",
             *(f"# {reason}" for reason in guess.reasons), "", "[read]", "# channel = the file's column",
             "[read.columns]"]
    lines += [f"{channel} = {_toml_text(column)}" for channel, column in layout.columns.items()]
    read = {"gyro-unit": layout.gyro_unit, "accel-unit": layout.accel_unit, "time-unit": layout.time_unit}
    if layout.delimiter is not None:
        read["delimiter"] = "tab" if layout.delimiter == "\t" else layout.delimiter
    # TOML: a table's keys come before its sub-tables, so the units go in a [read] written before [read.columns]
    head = lines.index("[read]")
    lines[head + 1:head + 1] = [f"{k} = {_toml_text(v)}" for k, v in read.items()]
    write_text_atomic(output, "\n".join(lines) + "\n")
    if not ctx.obj["quiet"]:
        click.echo(f"wrote {output} from {log}:")
        for reason in guess.reasons:
            click.echo(f"  {reason}")
        if guess.unused:
            click.echo(f"  columns not used: {', '.join(guess.unused)}")
        click.echo("check the units above; then e.g. gyrocomp fit " + Path(log).name + " -o model.json")


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
        click.echo(f"no project file: no {PROJECT_FILE} in {Path.cwd()} and no --config")
        return
    data = {"path": project.path, "read": project.read, "defaults": project.defaults, "commands": project.commands}
    if as_json:
        click.echo(json.dumps(data, indent=2))
        return
    console = make_console()
    console.print(f"project file: {project.path}")
    for section, options in (("read", project.read), ("defaults", project.defaults), *project.commands.items()):
        if options:
            console.print(f"[{section}]")
            for key, value in options.items():
                console.print(f"  {key} = {value!r}")


__all__ = ["config", "init"]
