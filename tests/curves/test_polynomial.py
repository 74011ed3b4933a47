"""The polynomial basis's columns (gyrocomp.curves.polynomial)."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp.curves.polynomial import polynomial_columns, power_columns


@settings(max_examples=60, deadline=None)
@given(first=st.integers(0, 3), count=st.integers(0, 6), seed=st.integers(0, 2**16), n=st.integers(0, 50))
def test_power_columns_are_the_integer_powers(first, count, seed, n):
    u = np.random.default_rng(seed).uniform(-1.5, 1.5, n)
    got = power_columns(u, first, first + count - 1)
    want = u[:, None] ** np.arange(first, first + count)
    assert got.shape == want.shape == (n, count)
    np.testing.assert_allclose(got, want, rtol=8 * np.finfo(float).eps, atol=8 * np.finfo(float).eps)


def test_columns_past_the_range_follow_the_tangent():
    clipped = np.array([-1.0, 0.5, 1.0])
    beyond = np.array([-0.5, 0.0, 0.25])
    cols = polynomial_columns(clipped, 3, beyond)
    k = np.arange(1, 4)
    np.testing.assert_allclose(cols, clipped[:, None] ** k + k * clipped[:, None] ** (k - 1) * beyond[:, None])
    np.testing.assert_array_equal(polynomial_columns(clipped, 0, beyond).shape, (3, 0))
