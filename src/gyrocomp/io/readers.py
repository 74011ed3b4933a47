"""The readers' registry: what a format is (:class:`Reader`), :func:`register_reader`, and everything asked of
formats: the names ``--format`` takes and its help, telling a file's format from its first bytes or its name,
which files a folder holds as runs, the sensor instances of a log.

A reader lives in a module of its own that calls :func:`register_reader` once; :mod:`gyrocomp.io.read_formats`
names every such module, so importing :mod:`gyrocomp.io` registers them all. Nothing else in gyrocomp names a
format.
"""

from __future__ import annotations

import dataclasses
import os
import stat
import warnings
from collections.abc import Callable
from typing import Any
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError, UnusedOptionWarning, user_stacklevel
from ..recording import Recording
from .read_options import ProgressCallback, ReadOptions
from .layout import TableLayout
from .tables import TableData, table_data


@dataclass(frozen=True)
class Reader:
    """A registered input format.

    Parameters
    ----------
    name : str
        What ``--format`` and ``fmt=`` call it.
    description : str
        What it is, one line (``--format``'s help shows it).
    read : callable
        ``read(path, options, progress) -> Recording or TableData`` in internal units [s, deg/s, g, degC]; a
        reader that returns :class:`TableData` keeps the file's own columns for writing results back.
    suffixes : tuple of str
        Endings of file names in this format, lower case (``.ulg``, ``.csv.gz``): a file whose first bytes say
        nothing is told by these, and a folder is searched for them.
    magic : tuple of bytes
        First bytes that announce the format.
    aliases : tuple of str
        Other names ``--format`` takes for it.
    folder_marker : str, optional
        A file that makes a folder one input of this format (a ROS 2 bag's ``metadata.yaml``).
    instances : callable, optional
        ``instances(path) -> tuple of int``: the sensor instances a file holds (default: one, ``(0,)``).
    table : bool
        A table of columns (CSV, Parquet): its layout options apply, and it can be read and written in chunks.
    layout : bool
        Not a table, but read by the layout options too (a file of named arrays: their mapping, units, rate).
    stream : callable, optional
        ``stream(path, options, chunk_rows, progress)``: the file read in chunks of about ``chunk_rows`` samples,
        an object with the interface of :class:`gyrocomp.io.stream.TableStream` that the file commands use
        (``chunks()``, the axes, ``layout``, ``columns``, ``gaps``, ``warn_summary()``); a format without one
        is read whole by every command.
    """

    name: str
    description: str
    read: Callable[[Path, ReadOptions, ProgressCallback | None], Recording | TableData]
    suffixes: tuple[str, ...] = ()
    magic: tuple[bytes, ...] = ()
    aliases: tuple[str, ...] = ()
    folder_marker: str | None = None
    instances: Callable[[Path], tuple[int, ...]] | None = None
    table: bool = False
    stream: Callable[[Path, ReadOptions, int, ProgressCallback | None], Any] | None = None
    layout: bool = False

    def warn_unused_layout(self, path: Path, options: ReadOptions) -> None:
        """Warn (:class:`UnusedOptionWarning`) when ``options`` set layout options (a column mapping, units, a
        rate, a text table's syntax) for a format that does not read them: a log's fields, units and time stamps
        are its own, so they change nothing (a project file written for the folder's tables sets them too).

        Parameters
        ----------
        path : Path
            The file named in the warning.
        options : ReadOptions
            What was asked of the reading (command line, project file or call).
        """
        if self.table or self.layout:
            return
        default = TableLayout()
        given = [
            f.name
            for f in dataclasses.fields(TableLayout)
            if getattr(options.layout, f.name) != getattr(default, f.name)
        ]
        if given:
            warnings.warn(
                f"{path}: {', '.join(f'{name}=' for name in given)} not used: they are for tables and files of "
                f"named arrays, and a {self.name} file's fields, units and time stamps are its own",
                UnusedOptionWarning,
                stacklevel=user_stacklevel(),
            )

    def read_table_data(self, path: Path, options: ReadOptions, progress: ProgressCallback | None) -> TableData:
        """What :attr:`read` returns, as :class:`TableData` (a recording becomes a table in the default layout).

        Parameters
        ----------
        path : Path
            The input.
        options : ReadOptions
            The reading options.
        progress : callable, optional
            Called with the fraction done.
        """
        self.warn_unused_layout(path, options)
        data = self.read(path, options, progress)
        return data if isinstance(data, TableData) else table_data(data)


#: every input format, by name, in the order registered
READERS: dict[str, Reader] = {}


def register_reader(reader: Reader) -> Reader:
    """Add ``reader`` to :data:`READERS`; a name, alias or suffix another reader has is refused.

    Parameters
    ----------
    reader : Reader
        The format: its name, description, reading function, suffixes, first bytes, aliases.

    Returns
    -------
    Reader
        ``reader``, registered.
    """
    taken = {n for r in READERS.values() for n in (r.name, *r.aliases)}
    clash = sorted(taken & {reader.name, *reader.aliases})
    if clash:
        raise InputError(f"reader {reader.name!r}: the name {clash[0]!r} is registered already")
    suffixes = {s for r in READERS.values() for s in r.suffixes} & set(reader.suffixes)
    if suffixes:
        raise InputError(f"reader {reader.name!r}: the suffix {sorted(suffixes)[0]!r} is registered already")
    READERS[reader.name] = reader
    return reader


def format_names() -> tuple[str, ...]:
    """The registered formats' names."""
    return tuple(READERS)


def table_formats() -> tuple[str, ...]:
    """The formats that are tables of columns (read and written in chunks)."""
    return tuple(name for name, reader in READERS.items() if reader.table)


def format_help() -> str:
    """``--format``'s help: every registered format with what it is."""
    listed = "; ".join(f"{r.name} ({r.description})" for r in READERS.values())
    return f"Input format (default: told from the file's first bytes or its name): {listed}."


def reader_named(fmt: str) -> Reader:
    """The reader called ``fmt`` (a name or an alias, any case); an unknown name is refused naming the known."""
    text = fmt.lower()
    for reader in READERS.values():
        if text == reader.name or text in reader.aliases:
            return reader
    raise InputError(f"fmt: unknown format {fmt!r}; use one of {', '.join(READERS)}")


def sniff_format(head: bytes) -> str | None:
    """The format a file's first bytes announce, or None (a text table has no signature)."""
    for reader in READERS.values():
        if any(head.startswith(magic) for magic in reader.magic):
            return reader.name
    return None


def format_of_name(path: str | os.PathLike) -> str | None:
    """The format a file's name says by its ending (the longest registered suffix it ends with), or None."""
    name = Path(path).name.lower()
    found = [(len(s), r.name) for r in READERS.values() for s in r.suffixes if name.endswith(s)]
    return max(found)[1] if found else None


def folder_format(folder: str | os.PathLike) -> str | None:
    """The format a folder is one input of (its marker file is in it), or None."""
    for reader in READERS.values():
        if reader.folder_marker and (Path(folder) / reader.folder_marker).exists():
            return reader.name
    return None


def folder_markers() -> tuple[str, ...]:
    """The files that make a folder one input (a ROS 2 bag's ``metadata.yaml``)."""
    return tuple(r.folder_marker for r in READERS.values() if r.folder_marker)


def run_suffixes() -> tuple[str, ...]:
    """Every registered suffix: what a folder is searched for."""
    return tuple(s for r in READERS.values() for s in r.suffixes)


def detect_format(path: str | os.PathLike, fmt: str | None = None) -> str:
    """The format name of ``path``: ``fmt`` if given (checked), else from its first bytes or its name. A pipe or
    a device (``/dev/stdin``, ``<(...)``) is refused: inputs are read more than once (their first bytes, then in
    chunks, some twice)."""
    _require_a_file(path)
    if fmt is not None:
        return reader_named(fmt).name
    path = Path(path)
    if path.is_dir():
        found = folder_format(path)
        if found is not None:
            return found
        markers = ", ".join(folder_markers()) or "no format is read from a folder"
        raise InputError(f"{path}: is a folder (not one input: no {markers} in it); name a file")
    if path.is_file():
        with open(path, "rb") as fh:
            found = sniff_format(fh.read(16))
        if found is not None:
            return found
    found = format_of_name(path)
    if found is None:
        raise InputError(
            f"{path}: cannot tell the format from the file or its suffix {path.suffix!r}; "
            f"name it with fmt= ({', '.join(READERS)})"
        )
    return found


def _require_a_file(path: str | os.PathLike) -> None:
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return  # a missing file is said where it is opened, with the same words everywhere
    if stat.S_ISFIFO(mode) or stat.S_ISCHR(mode) or stat.S_ISBLK(mode) or stat.S_ISSOCK(mode):
        kind = "a pipe" if stat.S_ISFIFO(mode) else "a socket" if stat.S_ISSOCK(mode) else "a device"
        raise InputError(
            f"{path}: is {kind}, not a file; gyrocomp reads an input more than once (its first bytes "
            "tell the format, then its rows): save it to a file first"
        )


def instances(path: str | os.PathLike, fmt: str | None = None) -> tuple[int, ...]:
    """The sensor instances a file holds (PX4 uORB ``multi_id``, ArduPilot IMU number from 0), sorted; ``(0,)``
    for a format with one sensor per file."""
    reader = READERS[detect_format(path, fmt)]
    if not Path(path).exists():
        raise InputError(f"{path}: no such file")
    return (0,) if reader.instances is None else reader.instances(Path(path))


def check_magic(path, expected: bytes, what: str, hint: str) -> None:
    """Refuse a file whose first bytes are not ``expected``, in one line that says what it is instead."""
    with open(path, "rb") as fh:
        head = fh.read(max(len(expected), 16))
    if not head.startswith(expected):
        raise InputError(f"{path}: not a {what} file ({_describe_head(head)}); {hint}")


def _describe_head(head: bytes) -> str:
    fmt = sniff_format(head)
    if fmt is not None:
        return f"it looks like {fmt}"
    if not head:
        return "it is empty"
    return f"it starts with {head[:8]!r}"


__all__ = [
    "READERS",
    "Reader",
    "check_magic",
    "detect_format",
    "folder_format",
    "folder_markers",
    "format_help",
    "format_names",
    "format_of_name",
    "instances",
    "reader_named",
    "register_reader",
    "run_suffixes",
    "sniff_format",
    "table_formats",
]
