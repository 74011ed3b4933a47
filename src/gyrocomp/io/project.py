"""The project file's reading options (``gyrocomp.toml``'s ``[read]`` section, which ``gyrocomp init`` writes) for
the library: :func:`project_read_options` gives the :class:`~gyrocomp.io.read_options.ReadOptions` and the format every
command reads the project's files with, so that ``gyrocomp.read(path, config="gyrocomp.toml")`` reads a file as
``gyrocomp fit`` run in that folder does.

The keys are the reading options' long flags without dashes (``columns``, ``gyro-unit``, ``time-unit``,
``delimiter``, ``decimal``, ``format``, ``drop-nan``, ``instance``, ...), their values as on the command line
(``columns`` also as a table of channel = column); the other sections (``[defaults]``, a command's own) are the
command line's, and are not read here.
"""

from __future__ import annotations

import dataclasses
import os
import tomllib
from pathlib import Path

from ..errors import InputError
from ..option_spelling import mapping_text, spelled_fields
from .read_options import ReadOptions
from .layout import TableLayout

#: the key of the format in ``[read]`` (the reading functions' ``fmt``)
FORMAT_KEY = "format"


def read_section(path: str | os.PathLike) -> dict:
    """The ``[read]`` section of a project file, its keys as flags without dashes; refuses in one line a file that
    is missing or not TOML."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"config: {path}: no such project file (gyrocomp init writes one: gyrocomp.toml)")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not a readable TOML file ({exc})") from None
    section = data.get("read", {})
    if not isinstance(section, dict):
        raise InputError(f"{path}: [read] must be a section of options")
    out = {k.strip().lstrip("-").replace("_", "-"): v for k, v in section.items()}
    if "columns" in out:
        out["columns"] = mapping_text(out["columns"], f"{path}: [read] columns")
    return out


def project_read_options(path: str | os.PathLike) -> tuple[ReadOptions, str | None]:
    """(reading options, format or None) of a project file's ``[read]`` section, as every command run beside it
    reads files; a key that is no reading option is refused in one line naming it and the ones there are.

    Parameters
    ----------
    path : path
        The project file (``gyrocomp.toml``).

    Returns
    -------
    (ReadOptions, str or None)
        Its reading options, and the input format it names (None: told from each file).
    """
    section = read_section(path)
    fmt = section.pop(FORMAT_KEY, None)
    if fmt is not None and not isinstance(fmt, str):
        raise InputError(f"{path}: [read] format: a format name (e.g. csv), got {fmt!r}")
    fields = {spelling.flag.lstrip("-"): (field, spelling) for field, spelling in spelled_fields(ReadOptions)}
    layout_fields = {f.name for f in dataclasses.fields(TableLayout)}
    values: dict[str, dict] = {"layout": {}, "options": {}}
    for key, value in section.items():
        if key not in fields:
            raise InputError(
                f"{path}: [read] {key}: not a reading option; use {', '.join(sorted([*fields, FORMAT_KEY]))}"
            )
        field, spelling = fields[key]
        if spelling.switch:
            if not isinstance(value, bool):
                raise InputError(f"{path}: [read] {key}: true or false, got {value!r}")
        elif isinstance(value, str) and spelling.parse is not None:
            value = spelling.parse(value)
        values["layout" if field.name in layout_fields else "options"][field.name] = value
    return ReadOptions(layout=TableLayout(**values["layout"]), **values["options"]), fmt


__all__ = ["FORMAT_KEY", "project_read_options", "read_section"]
