"""Which files a list of inputs names: files as given, folders searched for runs, glob patterns expanded."""

from __future__ import annotations

import glob
import os
import warnings
from collections.abc import Iterable
from pathlib import Path

from ..errors import DataQualityWarning, InputError, user_stacklevel
from .readers import folder_format, folder_markers, format_of_name, run_suffixes


def expand_inputs(data: Iterable[str | os.PathLike]) -> list[Path]:
    """The run files that ``data`` names: files as given, folders searched recursively for every readable format
    (a ROS 2 bag folder, with its ``metadata.yaml``, counts as one run), glob patterns expanded; sorted, each once:
    names that are one file (reached through symbolic links, a link loop included) count once, by the shortest
    name, and a warning says how many were dropped."""
    found = _each_once(_named_files(data))
    if not found:
        raise InputError(
            f"{', '.join(map(os.fspath, data))}: no run file found (looked for {', '.join(run_suffixes())})"
        )
    return sorted(found)


def _each_once(paths: set[Path]) -> set[Path]:
    """One name per file (its shortest, then first in order), with a warning when names were dropped."""
    by_file: dict[str, Path] = {}
    for path in sorted(paths, key=lambda p: (len(p.parts), os.fspath(p))):
        by_file.setdefault(os.path.realpath(path), path)
    dropped = len(paths) - len(by_file)
    if dropped:
        warnings.warn(
            f"{dropped} name(s) matched are files already named by another path (through symbolic "
            "links, or a link loop); each file is read once",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
    return set(by_file.values())


def _named_files(data: Iterable[str | os.PathLike]) -> set[Path]:
    found: set[Path] = set()
    for item in data:
        text = os.fspath(item)
        path = Path(text)
        if path.is_dir():
            found.update(_runs_in_folder(path))
        elif path.exists():
            found.add(path)
        elif glob.has_magic(text):
            matches = [Path(m) for m in glob.glob(text, recursive=True)]
            if not matches:
                raise InputError(f"{text}: the pattern matches no file")
            for match in matches:
                found.update(_runs_in_folder(match) if match.is_dir() else [match])
        else:
            raise InputError(f"{text}: no such file or folder")
    return found


def _runs_in_folder(folder: Path) -> list[Path]:
    runs, bags = [], []
    markers = set(folder_markers())
    for root, dirs, files in os.walk(folder):
        if markers & set(files) and root != os.fspath(folder):
            bags.append(Path(root))
            dirs.clear()
            continue
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))
        runs += [Path(root) / f for f in sorted(files) if not f.startswith(".") and format_of_name(f) is not None]
    return runs + bags


def expand_runs(items: Iterable[str | os.PathLike]) -> list[str]:
    """Run names for a command: a folder (not a ROS 2 bag's) becomes the runs in it and a glob pattern no file
    is named after becomes its matches (both sorted, see :func:`expand_inputs`); any other name stays as given, in
    order (a missing file is then reported by the reader)."""
    out: list[str] = []
    for item in items:
        text = os.fspath(item)
        path = Path(text)
        folder = path.is_dir() and folder_format(path) is None
        if folder or (not path.exists() and glob.has_magic(text)):
            out += [os.fspath(p) for p in expand_inputs([text])]
        else:
            out.append(text)
    return out


__all__ = ["expand_inputs", "expand_runs"]
