"""Options defined once: a typed field that says how it is spelled on the command line.

A dataclass field made with :func:`spelled` carries a :class:`Spelling` in its metadata: the flag, the help line,
the metavar, whether it is a switch, and how the option's text becomes the field's value. From that one field
come the three things an option is:

- the library parameter: the field itself (``ReadOptions(drop_nonfinite=True)``);
- the command-line option: made from the field (:func:`spelled_fields`) by the command line, whose value builds
  the options object (:func:`from_values`);
- the words of a message: the library names the field (``drop_nonfinite: ...``) and the command line shows the
  flag the field is spelled with (``--drop-nan``).

Nothing here imports more than the standard library (and the package's errors), so that the command line can read the spellings cheaply.
"""

from __future__ import annotations

import json

import dataclasses
from collections.abc import Callable, Mapping
from dataclasses import MISSING, dataclass
from typing import Any, TypeVar

from .errors import InputError

T = TypeVar("T")

#: the key of a field's metadata that holds its spelling
SPELLING_KEY = "gyrocomp.option_spelling"


@dataclass(frozen=True)
class Spelling:
    """How one typed option is spelled on the command line.

    Parameters
    ----------
    flag : str
        The long flag, ``"--drop-nan"``.
    help : str
        One line of help.
    metavar : str, optional
        What the value looks like in the help (``"A:B"``); default: click's.
    switch : bool
        A flag without a value (the field is a bool, False unless given).
    parse : callable, optional
        The field's value from the option's text; raises :class:`gyrocomp.errors.InputError` naming the field
        (``time_range_s: ...``). Default: the text itself.
    """

    flag: str
    help: str
    metavar: str | None = None
    switch: bool = False
    parse: Callable[[str], Any] | None = None


def spelled(spelling: Spelling, *, default: Any = MISSING, default_factory: Any = MISSING) -> Any:
    """A dataclass field (as :func:`dataclasses.field`) with its command-line spelling."""
    return dataclasses.field(default=default, default_factory=default_factory, metadata={SPELLING_KEY: spelling})


def _nested(field: dataclasses.Field) -> type | None:
    """The dataclass a field holds whose own fields are spelled (``ReadOptions.layout``: a ``TableLayout``)."""
    factory = field.default_factory
    return factory if isinstance(factory, type) and dataclasses.is_dataclass(factory) else None


def spelled_fields(cls: type) -> tuple[tuple[dataclasses.Field, Spelling], ...]:
    """Every spelled field of dataclass ``cls`` with its spelling, in order; the spelled fields of a field that
    holds a dataclass (made by its ``default_factory``) in its place."""
    found = []
    for field in dataclasses.fields(cls):
        if SPELLING_KEY in field.metadata:
            found.append((field, field.metadata[SPELLING_KEY]))
        elif _nested(field) is not None:
            found.extend(spelled_fields(_nested(field)))
    return tuple(found)


def from_values(cls: type[T], values: Mapping[str, Any]) -> T:
    """An instance of ``cls`` from its spelled fields' values keyed by field name (a field absent or None takes
    its default; a field holding a dataclass is built from the same values)."""
    kwargs = {}
    for field in dataclasses.fields(cls):
        if SPELLING_KEY in field.metadata and values.get(field.name) is not None:
            kwargs[field.name] = values[field.name]
        elif SPELLING_KEY not in field.metadata and _nested(field) is not None:
            kwargs[field.name] = from_values(_nested(field), values)
    return cls(**kwargs)


def _column_text(column: str) -> str:
    """A column's name in a mapping's text: as it is, or in double quotes (a JSON string) where a comma, an equals
    sign, a bracket, a quote or an outer space would otherwise change how the text splits."""
    plain = column == column.strip() and not any(c in column for c in ',="[]') and not column.startswith('"')
    return column if plain or not column else json.dumps(column, ensure_ascii=False)


def mapping_text(value: Any, where: str) -> str:
    """A mapping option as its command-line text ``KEY=VALUE,...``, from that text or a table of key = value
    (a project file's ``columns``); ``where`` names it in the message of a value that is neither."""
    if isinstance(value, dict):
        if not all(isinstance(v, str) for v in value.values()):
            raise InputError(f"{where}: each channel names a column (a string)")
        return ",".join(f"{k}={_column_text(v)}" for k, v in value.items())
    if not isinstance(value, str):
        raise InputError(f"{where}: a string CH=COL,... or a table of channel = column")
    return value


__all__ = ["SPELLING_KEY", "Spelling", "from_values", "mapping_text", "spelled", "spelled_fields"]
