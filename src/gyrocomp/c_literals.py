"""Numbers written into generated C: full precision, never a non-finite value (C has no literal for it)."""

from __future__ import annotations

import math

from .errors import InputError


def c_number(x: float) -> str:
    """``x`` as a C double literal that reads back to the same double."""
    if not math.isfinite(x):
        raise InputError("export: the model holds a non-finite number; fit it again")
    return repr(float(x))


def c_array(values) -> str:
    """A C initializer list of doubles: ``{1.0, 2.5}``."""
    return "{" + ", ".join(c_number(v) for v in values) + "}"


__all__ = ["c_array", "c_number"]
