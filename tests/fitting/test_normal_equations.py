"""The small normal equations of the model choice (gyrocomp.fitting.normal_equations) against numpy's SVD."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp.fitting.normal_equations import RCOND, solve_normal


@settings(max_examples=200, deadline=None)
@given(
    p=st.integers(1, 12),
    seed=st.integers(0, 2**32 - 1),
    collinear=st.sampled_from([0.0, 1e-9, 1e-4, 1.0]),
    absent=st.booleans(),
)
def test_the_minimum_norm_solution_of_any_gram_matrix(p, seed, collinear, absent):
    """Well-conditioned, nearly collinear, exactly collinear and all-zero columns (a branch with no training
    data): the same solution as ``numpy.linalg.lstsq`` to rounding, relative to the solution's size."""
    rng = np.random.default_rng(seed)
    x = rng.standard_normal((60, p)) * rng.lognormal(0.0, 2.0, p)
    if p > 1:
        x[:, -1] = x[:, 0] * (1 + collinear * rng.standard_normal(60)) if collinear else x[:, -1]
    if absent:
        x[:, p // 2] = 0.0
    gram = x.T @ x
    scale = np.sqrt(np.maximum(np.diag(gram), 1e-300))
    a = gram / np.outer(scale, scale)
    b = (x.T @ rng.standard_normal(60)) / scale
    expected = np.linalg.lstsq(a, b, rcond=RCOND)[0]
    got = solve_normal(a, b)
    assert got.shape == (p,)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-7 * max(np.max(np.abs(expected)), 1e-12))
