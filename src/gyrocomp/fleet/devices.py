"""Which runs belong to which unit: a pattern on the file paths or a manifest, and the content hash that tells a
unit's inputs changed.

A fleet is given as files (a folder, a glob, or names); each file is one run (one power-on) of one unit. The unit
comes from the path, matched against a pattern such as ``'{serial}/run_{n}.csv'`` (each ``{name}`` matches one
path component's text, ``{serial}`` is required; the pattern is matched against the end of the path), or from a
manifest table with a ``path`` and a ``serial`` column (any other column is kept as the unit's metadata).
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import warnings
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from ..errors import DataQualityWarning, InputError, user_stacklevel
from ..io.inputs import expand_inputs
from ..io.tables import detect_table_format, file_sha256

_FIELD = re.compile(r"\{(\w+)\}")


@dataclass(frozen=True)
class UnitRuns:
    """The runs of one unit: its serial, the run files (sorted) and metadata from the manifest or the pattern."""

    serial: str
    paths: tuple[str, ...]
    metadata: Mapping[str, str] = field(default_factory=dict)


def pattern_regex(pattern: str) -> re.Pattern:
    """The regular expression of a path pattern: ``{name}`` matches text without a ``/``, the rest literally;
    anchored at the end of the path. The pattern must name ``{serial}``, each field once."""
    names = _FIELD.findall(pattern)
    if "serial" not in names:
        raise InputError(f"unit_pattern: {pattern!r} names no {{serial}} field, e.g. '{{serial}}/run_{{n}}.csv'")
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise InputError(f"unit_pattern: {pattern!r} names {{{repeated[0]}}} twice")
    parts, last = [], 0
    for m in _FIELD.finditer(pattern):
        parts.append(re.escape(pattern[last : m.start()]))
        parts.append(f"(?P<{m.group(1)}>[^/]+?)")
        last = m.end()
    parts.append(re.escape(pattern[last:]))
    return re.compile(r"(?:^|/)" + "".join(parts) + r"$")


def units_from_pattern(paths: Iterable[str | os.PathLike], pattern: str) -> list[UnitRuns]:
    """Group run files into units by ``pattern`` (see the module). Fields other than ``serial`` become the units'
    metadata, except those that differ between the runs of some unit (a run number). A file that does not match
    is left out with a warning."""
    regex = pattern_regex(pattern)
    groups: dict[str, list[tuple[str, dict[str, str]]]] = {}
    unmatched = []
    for path in paths:
        text = Path(path).as_posix()
        m = regex.search(text)
        if m is None:
            unmatched.append(text)
            continue
        fields = m.groupdict()
        groups.setdefault(fields.pop("serial"), []).append((os.fspath(path), fields))
    if unmatched:
        if not groups:
            raise InputError(
                f"unit_pattern: {pattern!r} matches none of the {len(unmatched)} files (e.g. {unmatched[0]})"
            )
        warnings.warn(
            f"unit_pattern: {len(unmatched)} file(s) do not match {pattern!r} and are left out (e.g. {unmatched[0]})",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
    # a field that differs between the runs of any unit names runs (``{n}``); the others describe units
    per_run = {k for runs in groups.values() for k in runs[0][1] if len({f[k] for _, f in runs}) > 1}
    return [
        UnitRuns(serial, tuple(sorted(p for p, _ in runs)), {k: v for k, v in runs[0][1].items() if k not in per_run})
        for serial, runs in sorted(groups.items())
    ]


def units_from_manifest(path: str | os.PathLike) -> list[UnitRuns]:
    """Units from a manifest (CSV or Parquet): one row per run, columns ``path`` (relative to the manifest's folder
    unless absolute) and ``serial``; any other column is metadata, and must be the same on every row of a unit."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such manifest file")
    fmt = detect_table_format(path)
    if fmt is None:
        raise InputError(f"{path}: a manifest is a CSV or Parquet table (suffix .csv or .parquet)")
    table = pd.read_parquet(path) if fmt == "parquet" else pd.read_csv(path, dtype=str, keep_default_na=False)
    missing = [c for c in ("path", "serial") if c not in table.columns]
    if missing:
        raise InputError(
            f"{path}: the manifest has no {missing[0]!r} column (it needs path and serial; "
            f"found {', '.join(map(str, table.columns))})"
        )
    groups: dict[str, list[tuple[str, dict[str, str]]]] = {}
    for i, row in enumerate(table.astype(str).to_dict("records")):
        where = f"{path}: row {i + 2 if fmt == 'csv' else i + 1}"
        serial, run = row.pop("serial").strip(), row.pop("path").strip()
        if not serial or not run:
            raise InputError(f"{where}: empty {'serial' if not serial else 'path'}")
        run_path = Path(run) if Path(run).is_absolute() else path.parent / run
        if not run_path.exists():
            raise InputError(f"{where}: path {run}: no such file")
        if any(os.path.samefile(run_path, seen) for seen, _ in groups.get(serial, ())):
            raise InputError(f"{where}: path {run} is already a run of unit {serial}; give each run once")
        groups.setdefault(serial, []).append((os.fspath(run_path), row))
    for serial, runs in groups.items():
        for key in runs[0][1]:
            values = {f[key] for _, f in runs}
            if len(values) > 1:
                raise InputError(
                    f"{path}: unit {serial}: column {key!r} differs between its runs "
                    f"({', '.join(sorted(values)[:3])}); metadata is per unit"
                )
    return [
        UnitRuns(serial, tuple(sorted(p for p, _ in runs)), dict(runs[0][1])) for serial, runs in sorted(groups.items())
    ]


def content_hash(path: str | os.PathLike) -> str:
    """SHA-256 of a run's content: its bytes, or for a ROS 2 bag folder its files' names and bytes."""
    return file_sha256(path) if Path(path).is_file() else _folder_sha256(Path(path))


def input_hash(paths: Iterable[str | os.PathLike], settings: Mapping, *, contents: Iterable[str] | None = None) -> str:
    """SHA-256 over the contents of the run files (not their names or times) and the fit's settings: a unit
    whose hash is unchanged would be fitted to the same model again. ``contents``: the files' content hashes
    when already known (:func:`content_hash`; the files are then not read again)."""
    digest = hashlib.sha256()
    for content in sorted(contents if contents is not None else (content_hash(p) for p in paths)):
        digest.update(content.encode())
    digest.update(json.dumps(settings, sort_keys=True, default=str).encode())
    return digest.hexdigest()


def _folder_sha256(folder: Path) -> str:
    """A ROS 2 bag folder: the hash of its files' names (relative) and contents."""
    digest = hashlib.sha256()
    for f in sorted(p for p in folder.rglob("*") if p.is_file()):
        digest.update(f.relative_to(folder).as_posix().encode())
        digest.update(file_sha256(f).encode())
    return digest.hexdigest()


__all__ = [
    "UnitRuns",
    "content_hash",
    "expand_inputs",
    "input_hash",
    "pattern_regex",
    "units_from_manifest",
    "units_from_pattern",
]
