"""Numbers with their standard error: rounded to the error's second significant digit."""

import math

import pytest

from gyrocomp.rounding import with_error


@pytest.mark.parametrize(
    "value, error, sign, text",
    [
        (0.0003912, 2.7e-05, False, "0.000391 +- 0.000027"),
        (1.000483, 3e-05, True, "+1.000483 +- 0.000030"),
        (0.0991, 0.0012, True, "+0.0991 +- 0.0012"),
        (-0.0991, 0.0012, True, "-0.0991 +- 0.0012"),
        (12345.6, 67.0, False, "12346 +- 67"),
        (1e-12, 3e-14, False, "(1.000 +- 0.030)e-12"),
        (2.5e6, 1e3, False, "(2.5000 +- 0.0010)e+06"),
        (0.5, None, False, "0.5"),
        (0.5, 0.0, False, "0.5"),
        (0.5, math.nan, True, "+0.5"),
        (None, 0.1, False, "-"),
    ],
)
def test_the_value_keeps_the_digits_its_error_allows(value, error, sign, text):
    assert with_error(value, error, sign=sign) == text


def test_the_rounded_value_is_within_half_a_last_digit():
    for value, error in ((0.123456789, 0.00123), (98.7654, 0.56), (-3.21e-5, 4.4e-7)):
        shown = float(with_error(value, error).split(" +- ")[0])
        digit = 10.0 ** (math.floor(math.log10(error)) - 1)
        assert abs(shown - value) <= digit / 2 + 1e-15
