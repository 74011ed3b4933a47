"""Readers and writers. Every reader returns a :class:`gyrocomp.recording.Recording` in internal units."""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import InputError
from ..recording import Recording
from .atomic import atomic_path, refuse_to_overwrite_inputs, write_text_atomic
from .tables import (
    TableData,
    TableLayout,
    detect_table_format,
    file_sha256,
    parse_column_mapping,
    read_table,
    write_gyro_back,
    write_recording,
)

FORMATS = ("csv", "parquet")


def detect_format(path: str | os.PathLike, fmt: str | None = None) -> str:
    """The format name of ``path``: ``fmt`` if given (checked), else from the file suffix."""
    if fmt is not None:
        if fmt not in FORMATS:
            raise InputError(f"--format: unknown format {fmt!r}; use one of {', '.join(FORMATS)}")
        return fmt
    found = detect_table_format(Path(path))
    if found is None:
        raise InputError(
            f"{path}: cannot tell the format from the suffix {Path(path).suffix!r}; "
            f"name it with --format ({', '.join(FORMATS)})"
        )
    return found


def read(
    path: str | os.PathLike,
    layout: TableLayout | None = None,
    *,
    fmt: str | None = None,
    drop_nonfinite: bool = False,
) -> Recording:
    """Read any supported file into a :class:`Recording` (see :func:`read_table` for options)."""
    return read_table(path, layout, fmt=detect_format(path, fmt), drop_nonfinite=drop_nonfinite).recording


__all__ = [
    "FORMATS",
    "TableData",
    "TableLayout",
    "atomic_path",
    "detect_format",
    "detect_table_format",
    "file_sha256",
    "parse_column_mapping",
    "read",
    "read_table",
    "refuse_to_overwrite_inputs",
    "write_gyro_back",
    "write_recording",
    "write_text_atomic",
]
