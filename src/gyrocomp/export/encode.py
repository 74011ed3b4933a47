"""Text from files (a model's name, a serial, a run's source) put into generated files: one function per target.

A model file is something people email each other: any text it carries may be hostile. Generated code never takes
an identifier from data (the exporters generate them), and text that is only there for a reader goes through the
function of its target here, which keeps a safe alphabet:

- :func:`c_comment`: inside a C block comment. Printable ASCII without ``*`` (so neither ``/*`` nor ``*/`` can
  form), ``\\`` (no line splicing) and ``?`` (no trigraphs); anything else becomes ``_``; one line, limited length.
- :func:`line_comment`: after the comment character of a parameter file (``#`` in PX4's and ArduPilot's files):
  printable ASCII, one line, limited length (a newline would start a line the autopilot reads as a parameter).

HTML is escaped once, at the boundary, by :func:`html.escape` in the report; JSON and CSV by their writers.
"""

from __future__ import annotations

#: the longest text kept [characters]; longer text ends in "..."
MAX_COMMENT_CHARS = 160
_C_UNSAFE = frozenset("*\\?")


def _printable(text: str, unsafe: frozenset[str], limit: int) -> str:
    out = "".join(c if " " <= c <= "~" and c not in unsafe else "_" for c in str(text))
    return out if len(out) <= limit else out[: limit - 3] + "..."


def c_comment(text: str, limit: int = MAX_COMMENT_CHARS) -> str:
    """``text`` made safe to stand inside a C block comment (see the module doc)."""
    return _printable(text, _C_UNSAFE, limit)


def line_comment(text: str, limit: int = MAX_COMMENT_CHARS) -> str:
    """``text`` made safe to stand after a line-comment character in a parameter file (see the module doc)."""
    return _printable(text, frozenset(), limit)


__all__ = ["MAX_COMMENT_CHARS", "c_comment", "line_comment"]
