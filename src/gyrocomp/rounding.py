"""Numbers shown with their standard error: the value rounded to the error's second significant digit, so a
table says no more than the data know (``0.000391 +- 0.000027``, not ``0.0003912 +- 2.7e-05``)."""

from __future__ import annotations

import math


def with_error(value: float | None, standard_error: float | None, *, sign: bool = False) -> str:
    """``value +- standard_error``, both to the decimal of the error's second significant digit (fixed point;
    scientific with a shared exponent when that would need more than 8 decimals or the value is 1e6 or more).
    Without a finite, positive error: the value to 4 significant digits; without a value (none was
    measured): ``-``.

    Parameters
    ----------
    value : float or None
        The estimate [any unit].
    standard_error : float or None
        Its standard error [the same unit].
    sign : bool
        Write a + before a positive value.
    """
    plus = "+" if sign else ""
    if value is None:
        return "-"
    if not math.isfinite(value):
        return f"{value}"
    if standard_error is None or not math.isfinite(standard_error) or standard_error <= 0:
        return f"{value:{plus}.4g}"
    decimals = 1 - math.floor(math.log10(standard_error))
    if decimals > 8 or abs(value) >= 1e6:
        exponent = math.floor(math.log10(max(abs(value), standard_error)))
        scale = 10.0**exponent
        digits = max(0, exponent - math.floor(math.log10(standard_error)) + 1)
        return f"({value / scale:{plus}.{digits}f} +- {standard_error / scale:.{digits}f})e{exponent:+03d}"
    decimals = max(decimals, 0)
    return f"{value:{plus}.{decimals}f} +- {standard_error:.{decimals}f}"


__all__ = ["with_error"]
