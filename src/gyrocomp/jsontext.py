"""JSON text from files (model files, learner states), read with bounds: a file is an input like any other.

Python's :func:`json.loads` turns a 4,000-digit integer into an int that no float can hold (an internal error
later) and refuses one of 5,000 digits with an error about interpreter limits. gyrocomp's files hold no integer
beyond :data:`MAX_INTEGER_DIGITS` digits, so a longer one is refused here, in one line naming the file. It also
reads ``NaN`` and ``Infinity``, which are not JSON, and keeps the last of two equal keys of an object without a
word: both are refused here (gyrocomp writes neither).
"""

from __future__ import annotations

import json
from typing import Any

from .errors import InputError

#: the most digits an integer in a gyrocomp JSON file may have (counts, ids and seeds stay far below)
MAX_INTEGER_DIGITS = 30


def loads(text: str, source: str, what: str = "file", remedy: str = "", non_finite: bool = False) -> Any:
    """``text`` parsed as JSON; malformed text, nesting too deep for Python, an integer of more than
    :data:`MAX_INTEGER_DIGITS` digits or a key twice in one object is an :class:`InputError` naming ``source`` (a
    gyrocomp ``what``: ``model file``, ``learner state``), and ``remedy`` (a hint) for malformed text. ``NaN`` and
    ``Infinity`` are refused too, unless ``non_finite`` (they are then read as floats, for a reader that names the
    field it finds them in)."""

    def integer(digits: str) -> int:
        if len(digits.lstrip("-")) > MAX_INTEGER_DIGITS:
            raise InputError(
                f"{source}: an integer of {len(digits.lstrip('-'))} digits; gyrocomp's files hold none "
                f"of more than {MAX_INTEGER_DIGITS}"
            )
        return int(digits)

    def constant(name: str):
        if non_finite:
            return float(name)
        raise InputError(f"{source}: {name} is not a number JSON allows (gyrocomp writes none); the {what} is damaged")

    def unique(pairs: list[tuple[str, Any]]) -> dict:
        out: dict = {}
        for key, value in pairs:
            if key in out:
                raise InputError(
                    f"{source}: the key {key!r} appears twice in one object; which one is meant is not "
                    f"said (a {what} names each once)"
                )
            out[key] = value
        return out

    hint = f"; {remedy}" if remedy else ""
    try:
        return json.loads(text, parse_int=integer, parse_constant=constant, object_pairs_hook=unique)
    except json.JSONDecodeError as exc:
        raise InputError(f"{source}: not valid JSON (line {exc.lineno}, column {exc.colno}: {exc.msg}){hint}") from None
    except RecursionError:
        raise InputError(f"{source}: not a gyrocomp {what} (nested too deeply)") from None


__all__ = ["MAX_INTEGER_DIGITS", "loads"]
