"""The readers' optional libraries: importing them with one line that names the extra, and what they print while they
read."""

from __future__ import annotations


import contextlib
import importlib
import io
import os
import sys
import tempfile
import warnings
from collections.abc import Iterator
from types import ModuleType


from ..errors import DataQualityWarning, MissingDependencyError, install_hint, printable, user_stacklevel


def require(module: str, extra: str, what: str) -> ModuleType:
    """Import an optional dependency, or raise one line that names the extra to install."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingDependencyError(
            f"{what} needs the optional package {module.split('.')[0]}; install it with: {install_hint(extra)}"
        ) from None


@contextlib.contextmanager
def _descriptor_into(fd: int, sink) -> Iterator[None]:
    """Point file descriptor ``fd`` at ``sink`` for the block (what C extensions write goes there too); a
    descriptor that is not open is left alone."""
    try:
        saved = os.dup(fd)
    except OSError:
        yield
        return
    try:
        os.dup2(sink.fileno(), fd)
        yield
    finally:
        os.dup2(saved, fd)
        os.close(saved)


@contextlib.contextmanager
def foreign_output(source: str, library: str) -> Iterator[None]:
    """Capture what a foreign reader (pyulog, pymavlink and its C indexer) prints to stdout or stderr while it
    reads, and say it in one :class:`DataQualityWarning`: how many lines, the first with control characters
    escaped. The descriptors are process-wide, so this is meant around a reader's own call only."""
    captured = io.StringIO()
    with tempfile.TemporaryFile() as sink:
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                stream.flush()
        with (
            _descriptor_into(1, sink),
            _descriptor_into(2, sink),
            contextlib.redirect_stdout(captured),
            contextlib.redirect_stderr(captured),
        ):
            yield
        sink.seek(0)
        text = captured.getvalue() + sink.read().decode("utf-8", "replace")
    lines = [line for line in text.splitlines() if line.strip()]
    if lines:
        first = printable(lines[0].strip())[:120]
        warnings.warn(
            f"{source}: {library} reported {len(lines)} line(s) while reading, the first: {first!r}; "
            "the log is probably damaged in places",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
