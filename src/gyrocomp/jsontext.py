"""JSON text from files (model files, learner states), read with bounds: a file is an input like any other.

Python's :func:`json.loads` turns a 4,000-digit integer into an int that no float can hold (an internal error
later) and refuses one of 5,000 digits with an error about interpreter limits. gyrocomp's files hold no integer
beyond :data:`MAX_INTEGER_DIGITS` digits, so a longer one is refused here, in one line naming the file.
"""

from __future__ import annotations

import json
from typing import Any

from .errors import InputError

#: the most digits an integer in a gyrocomp JSON file may have (counts, ids and seeds stay far below)
MAX_INTEGER_DIGITS = 30


def loads(text: str, source: str, what: str = "file", remedy: str = "") -> Any:
    """``text`` parsed as JSON; malformed text, nesting too deep for Python or an integer of more than
    :data:`MAX_INTEGER_DIGITS` digits is an :class:`InputError` naming ``source`` (a gyrocomp ``what``: ``model
    file``, ``learner state``), and ``remedy`` (a hint) for malformed text."""

    def integer(digits: str) -> int:
        if len(digits.lstrip("-")) > MAX_INTEGER_DIGITS:
            raise InputError(f"{source}: an integer of {len(digits.lstrip('-'))} digits; gyrocomp's files hold none "
                             f"of more than {MAX_INTEGER_DIGITS}")
        return int(digits)

    hint = f"; {remedy}" if remedy else ""
    try:
        return json.loads(text, parse_int=integer)
    except json.JSONDecodeError as exc:
        raise InputError(f"{source}: not valid JSON (line {exc.lineno}, column {exc.colno}: {exc.msg}){hint}") from None
    except RecursionError:
        raise InputError(f"{source}: not a gyrocomp {what} (nested too deeply)") from None


__all__ = ["MAX_INTEGER_DIGITS", "loads"]
