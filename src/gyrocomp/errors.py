"""Typed errors raised by gyrocomp.

Library code raises these with messages that name the file, row, column or option at fault
and say what to do; only :mod:`gyrocomp.cli` turns them into one line on stderr and an exit status.
"""

from __future__ import annotations

import os
import re
import sys
from typing import Literal, get_args


class GyrocompError(Exception):
    """Base class of every error gyrocomp raises on purpose."""


class InputError(GyrocompError, ValueError):
    """Bad data, a bad file or a bad option value (CLI exit status 2)."""


class LayoutError(InputError):
    """A table's (or a file of named arrays') time or gyro is not where gyrocomp looks, and no mapping says where
    (``path``: the file); its layout can be guessed from the names (``gyrocomp init``)."""

    def __init__(self, message: str, path):
        super().__init__(message)
        self.path = path


class TimeOrderError(InputError):
    """A recording's time repeats or goes back (``repeated``: it repeats) at row ``row`` (1-based, of its file)."""

    def __init__(self, message: str, row: int, repeated: bool):
        super().__init__(message)
        self.row, self.repeated = row, repeated


class ModelError(GyrocompError):
    """A model could not be fitted, loaded or applied (CLI exit status 1)."""


class NotFittedError(ModelError, AttributeError):
    """An estimator was used before ``fit`` was called."""


class TemperatureRangeWarning(UserWarning):
    """Data lies outside the temperature range a model was fitted on; the model was clamped to its edge."""


class UnusedOptionWarning(UserWarning):
    """An option was given that the input does not read (a table's column mapping or units for a log whose
    fields and time stamps are its own): it changed nothing."""


class DataQualityWarning(UserWarning):
    """Data was accepted but something about it deserves attention (rows dropped, gaps found)."""


class TimeOrderWarning(DataQualityWarning):
    """A log's samples were out of time order (sorted) or repeated a time stamp (dropped): ``moved`` and
    ``dropped`` samples, and ``largest_back_s``, the furthest the time went back [s] (a clock reset or two logs
    appended go back far; a logger's reordering, a sample period or two)."""

    def __init__(self, message: str = "", moved: int = 0, dropped: int = 0, largest_back_s: float = 0.0):
        super().__init__(message)
        self.moved, self.dropped, self.largest_back_s = moved, dropped, largest_back_s


class PlausibilityWarning(DataQualityWarning):
    """The data is probably not what it claims: a unit mistake (kelvin, ms), values beyond any MEMS sensor, a
    calibration run that turns or whose temperature barely varies (:mod:`gyrocomp.measures.plausibility`). ``check``
    names the check that found it."""

    def __init__(self, message: str = "", check: str | None = None):
        super().__init__(message)
        self.check = check


#: the name of a plausibility check (the checks themselves are in :mod:`gyrocomp.measures.plausibility`)
CheckName = Literal[
    "rate",
    "kelvin",
    "time-unit",
    "time-bursts",
    "offset",
    "rotation",
    "temperature-span",
    "agreement",
    "accel-unit",
    "temperature-range",
]
#: every check's name
CHECKS: tuple[CheckName, ...] = get_args(CheckName)


def silence_pattern(check: str) -> str:
    """The ``message`` regular expression for ``warnings.filterwarnings`` that silences one check."""
    if check not in CHECKS:
        raise InputError(f"check: unknown plausibility check {check!r}; use one of {', '.join(CHECKS)}")
    return rf"(?s).*\(check {re.escape(repr(check))}\)$"


class MissingDependencyError(GyrocompError, ImportError):
    """An optional package is needed for this (the message names the extra to install; CLI exit status 1)."""


def install_hint(extra: str) -> str:
    """How to install an extra, from PyPI and from a clone of the repository (where ``pip install
    'gyrocomp[...]'`` would fetch the released package instead of the clone's)."""
    return f"pip install 'gyrocomp[{extra}]' (from a clone of the repository: pip install -e '.[{extra}]')"


#: the package's folder: a warning is attributed to the first frame outside it (the user's line)
_PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__)) + os.sep


def user_stacklevel() -> int:
    """The ``stacklevel`` for :func:`warnings.warn`, called where the warning is raised, that attributes it to the
    first caller outside gyrocomp (the user's line), however deep inside the package it is raised."""
    frame, level = sys._getframe(1), 1
    while frame is not None and frame.f_code.co_filename.startswith(_PACKAGE_DIR):
        frame, level = frame.f_back, level + 1
    return level


class ModelChoiceWarning(UserWarning):
    """Validation found that a temperature model does not help an axis (none generalizes to held-out data, or
    the chosen one leaves more drift there than the raw output)."""


def printable(text: str, lines: bool = False) -> str:
    """``text`` with control characters escaped (``\\n``, ``\\x1b``), and the other characters that are not
    printable (bidirectional overrides such as ``\\u202e``, zero-width characters): a newline, a terminal's escape
    sequence or a reversal in a message (a file name's, a serial's, a foreign library's) would otherwise break a
    one-line message, take over the terminal or show other text than there is. ``lines``: keep newlines (text of
    several lines, each made printable)."""
    return "".join(c if c.isprintable() or (lines and c == "\n") else repr(c)[1:-1] for c in text)


#: the characters of a foreign library's message kept in one of gyrocomp's
FOREIGN_MESSAGE_CHARS = 160


def foreign_message(exc: BaseException) -> str:
    """What a foreign library's exception says, for one of gyrocomp's one-line messages: its type, then its text
    with control characters escaped (:func:`printable`) and cut to ``FOREIGN_MESSAGE_CHARS`` (a parser's error can
    quote a whole schema, newlines and all)."""
    return f"{type(exc).__name__}: {printable(str(exc))[:FOREIGN_MESSAGE_CHARS]}"
