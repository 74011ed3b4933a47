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

import math
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
    one line a file that is not TOML, a section that is not a table or is no command, and nesting deeper than a
    command's section (a ``[read]`` key that is no reading option, and a value of the wrong type, are refused by
    :func:`defaults_for`, against the options of the command that runs)."""
    if given == "":
        raise InputError("--config '': names no file; give --no-config (or GYROCOMP_NO_CONFIG=1) to read none")
    path = Path(given) if given else Path(PROJECT_FILE)
    if not path.is_file():
        if given:
            raise InputError(f"--config {given}: no such file")
        return None
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not a readable TOML file ({exc})") from None
    except RecursionError:  # tables or arrays nested thousands deep
        raise InputError(f"{path}: not a project file: its tables or arrays nest thousands deep") from None
    read = _options(path, "read", data.pop("read", {}))
    if "columns" in read:
        read["columns"] = mapping_text(read["columns"], f"{path}: [read] columns = {_shown(read['columns'])}")
    defaults = _options(path, "defaults", data.pop("defaults", {}))
    sections: dict[str, dict] = {}

    def walk(prefix: str, table: dict) -> None:
        for name, value in table.items():
            full = f"{prefix}.{name}" if prefix else name
            if not isinstance(value, dict):
                raise InputError(
                    f"{path}: {full} = {_shown(value)}: options go in [read], [defaults] or a command's section"
                )
            if prefix == "" and name not in commands:
                raise InputError(
                    f"{path}: [{name}]: no such command; sections are read, defaults and {', '.join(commands)}"
                )
            if full.count(".") > _DEEPEST:
                raise InputError(f"{path}: [{full}]: no such command (a command's section holds its options)")
            options = {_key(k): v for k, v in value.items() if not isinstance(v, dict)}
            sections[full] = options
            walk(full, {k: v for k, v in value.items() if isinstance(v, dict)})

    walk("", data)
    return Project(str(path), read, defaults, sections)


#: the most dots in a command's section (``[fleet.fit]``)
_DEEPEST = 1


def _options(path: Path, section: str, table) -> dict:
    """A section of options (``[read]``, ``[defaults]``): a table whose values are not tables."""
    if not isinstance(table, dict):
        raise InputError(f"{path}: {section} = {_shown(table)}: [{section}] is a table of options (key = value lines)")
    for key, value in table.items():
        if isinstance(value, dict) and not (section == "read" and _key(key) == "columns"):
            raise InputError(f"{path}: [{section}] {key}: a table; each option is one value (key = value)")
    return {_key(k): v for k, v in table.items()}


def _shown(value) -> str:
    """A project file's value in a message: its TOML type, and the value where it is short."""
    text = repr(value)
    return text if len(text) <= 40 else f"a {type(value).__name__} ({text[:30]}...)"


def check_value(project: Project, section: str, key: str, param: click.Parameter) -> None:
    """Refuse in one line, naming the file, the section and the key, a project file's value that the option
    ``param`` does not take: of the wrong type, not finite, or several where it takes one."""
    value = {"read": project.read, "defaults": project.defaults}.get(section, project.commands.get(section, {}))[key]
    where = f"{project.path}: [{section}] {key} = {_shown(value)}"
    several = param.multiple or param.nargs != 1
    if isinstance(value, list) and not several:
        raise InputError(f"{where}: --{key} takes one value, not a list")
    if isinstance(value, bool) and not getattr(param, "is_flag", False):
        raise InputError(f"{where}: --{key} takes a {param.type.name}, not a boolean")
    if isinstance(value, float) and not math.isfinite(value):
        raise InputError(f"{where}: not a finite number")
    for each in value if isinstance(value, list) else [value]:
        if isinstance(each, (dict, list)) or (isinstance(each, float) and not math.isfinite(each)):
            raise InputError(f"{where}: each value is one {param.type.name}")
        if isinstance(param.type, click.Path) and not isinstance(each, str):
            raise InputError(f'{where}: --{key} takes a path, written as a string ("...")')
        try:
            param.type.convert(each, param, None)
        except click.BadParameter as exc:
            raise InputError(f"{where}: {exc.message}") from None
        except (TypeError, ValueError, OverflowError):
            raise InputError(f"{where}: not a {param.type.name}") from None


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
    params = {param.name: param for param in command.params}
    out = {}
    for section, options in (("read", project.read if reading else {}), ("defaults", project.defaults)):
        for key in options:
            if key in flags:
                check_value(project, section, key, params[flags[key]])
                out[flags[key]] = options[key]
    for key, value in project.commands.get(name, {}).items():
        if key not in flags:
            raise InputError(f"{project.path}: [{name}] {key}: gyrocomp {name.replace('.', ' ')} has no option --{key}")
        check_value(project, name, key, params[flags[key]])
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


def unknown_defaults(project: Project, commands: list[click.Command]) -> list[str]:
    """The keys of ``project``'s ``[defaults]`` that no command of ``commands`` (every command, and a group's
    commands) has as an option: a misspelt key, which would otherwise change nothing without a word."""
    known: set[str] = set()
    stack = list(commands)
    while stack:
        command = stack.pop()
        known |= {o[2:] for p in command.params if isinstance(p, click.Option) for o in p.opts if o.startswith("--")}
        stack += list(getattr(command, "commands", {}).values())
    return [key for key in project.defaults if key not in known]


__all__ = [
    "PROJECT_FILE",
    "PROJECT_KEY",
    "Project",
    "ReadingOption",
    "check_value",
    "defaults_for",
    "load_project",
    "unknown_defaults",
]
