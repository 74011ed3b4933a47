"""The project file (``gyrocomp.toml``): tell your data once, for every command (``gyrocomp init`` writes one,
``gyrocomp config show`` prints the one in use: :mod:`gyrocomp.cli.project`). Loaded by the command group before
any command runs, so this module imports nothing heavy.

Sections: ``[read]`` the reading options of every command that reads data (``columns``, ``gyro-unit``,
``accel-unit``, ``time-unit``, ``delimiter``, ``decimal``, ``format``, ``drop-nan``, ``instance``, ...;
``columns`` a string ``CH=COL,...`` or a table), ``[defaults]`` any option of any command by its long name (each
command takes those it has: ``window = 60``, ``turn-on-window = 60``), and ``[COMMAND]`` (``[fit]``,
``[fleet.fit]``) the options of one command, checked against it. An option given on the command line wins.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import click

from ..errors import InputError
from ..option_spelling import mapping_text

PROJECT_FILE = "gyrocomp.toml"
#: where the command group keeps the loaded project for the commands (click's shared ``Context.meta``)
PROJECT_KEY = "gyrocomp.project"


class ReadingOption(click.Option):
    """A reading option (made from the fields of :class:`gyrocomp.io.ReadOptions` by :mod:`gyrocomp.cli.common`):
    the options ``[read]`` may hold are those of the command that runs."""


@dataclass(frozen=True)
class Project:
    """A project file's sections: ``read``, ``defaults`` and one per command (``fit``, ``fleet.fit``), each option
    name (as its flag, without dashes) to its value."""

    path: str
    read: dict = field(default_factory=dict)
    defaults: dict = field(default_factory=dict)
    commands: dict = field(default_factory=dict)


def _key(name: str) -> str:
    return name.strip().lstrip("-").replace("_", "-")


def load_project(given: str | None, commands: tuple[str, ...]) -> Project | None:
    """The project file given (``--config``), else ``gyrocomp.toml`` in the working folder, else None; refuses in
    one line a file that is not TOML or a section that is no command (a ``[read]`` key that is no reading option is
    refused by :func:`defaults_for`, against the reading options of the command that runs)."""
    path = Path(given) if given else Path(PROJECT_FILE)
    if not path.is_file():
        if given:
            raise InputError(f"--config {given}: no such file")
        return None
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not a readable TOML file ({exc})") from None
    read = {_key(k): v for k, v in data.pop("read", {}).items()}
    if "columns" in read:
        read["columns"] = mapping_text(read["columns"], f"{path}: [read] columns")
    defaults = {_key(k): v for k, v in data.pop("defaults", {}).items()}
    sections: dict[str, dict] = {}

    def walk(prefix: str, table: dict) -> None:
        for name, value in table.items():
            full = f"{prefix}.{name}" if prefix else name
            if not isinstance(value, dict):
                raise InputError(f"{path}: {name} = ...: options go in [read], [defaults] or a command's section")
            if prefix == "" and name not in commands:
                raise InputError(
                    f"{path}: [{name}]: no such command; sections are read, defaults and {', '.join(commands)}"
                )
            options = {_key(k): v for k, v in value.items() if not isinstance(v, dict)}
            sections[full] = options
            walk(full, {k: v for k, v in value.items() if isinstance(v, dict)})

    walk("", data)
    return Project(str(path), read, defaults, sections)


def defaults_for(project: Project, command: click.Command, name: str) -> dict:
    """Click's ``default_map`` for ``command`` (named ``name``, dotted for a group's command) from ``project``:
    the [read] and [defaults] options it has, then its own section's (refused when it has no such option); a
    group's commands nested."""
    flags = {
        opt.lstrip("-"): param.name
        for param in command.params
        if isinstance(param, click.Option)
        for opt in param.opts
        if opt.startswith("--")
    }
    reading = sorted(
        opt.lstrip("-")
        for param in command.params
        if isinstance(param, ReadingOption)
        for opt in param.opts
        if opt.startswith("--")
    )
    for key in project.read if reading else ():
        if key not in reading:
            raise InputError(f"{project.path}: [read] {key}: not a reading option; use {', '.join(reading)}")
    out = {flags[k]: v for k, v in {**project.read, **project.defaults}.items() if k in flags}
    for key, value in project.commands.get(name, {}).items():
        if key not in flags:
            raise InputError(f"{project.path}: [{name}] {key}: gyrocomp {name.replace('.', ' ')} has no option --{key}")
        out[flags[key]] = value
    switches = {
        param.name: param
        for param in command.params
        if isinstance(param, click.Option) and param.is_flag and not param.secondary_opts
    }
    for key, value in out.items():
        if key in switches and value is True:
            flag = next(o for o in switches[key].opts if o.startswith("--"))
            raise InputError(
                f"{project.path}: {flag[2:]} = true: a switch the command line could not turn off "
                f"again; give {flag} when running gyrocomp {name.replace('.', ' ')}"
            )
    for sub_name, sub in getattr(command, "commands", {}).items():
        out[sub_name] = defaults_for(project, sub, f"{name}.{sub_name}")
    return out


__all__ = ["PROJECT_FILE", "PROJECT_KEY", "Project", "ReadingOption", "defaults_for", "load_project"]
