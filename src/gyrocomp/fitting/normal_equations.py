"""Solving the small normal equations of a least-squares fit, ``A x = b`` with ``A`` symmetric positive
semi-definite (a Gram matrix), as the model choice does hundreds of thousands of times per fit."""

from __future__ import annotations

import numpy as np

#: singular values under this fraction of the largest are treated as zero (the minimum-norm solution)
RCOND = 1e-10
#: a Cholesky factor whose diagonal spans more than this ratio is left to the SVD (its square, the condition
#: number's lower bound, 1e8: there a Cholesky solution and the minimum-norm one part by more than rounding)
CHOLESKY_MAX_RATIO = 1e4


def solve_normal(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The minimum-norm solution of ``a x = b`` (``a`` (p, p) symmetric positive semi-definite, scaled to a unit
    diagonal; ``b`` (p,)), singular values under :data:`RCOND` of the largest treated as zero, as
    ``numpy.linalg.lstsq(a, b, rcond=RCOND)`` gives it.

    A well-conditioned ``a`` is solved through its Cholesky factor (LAPACK's dposv: several times faster than the SVD at these
    sizes, and equal to it to rounding); a singular or nearly singular one (a column absent from the training
    data) through the SVD."""
    from scipy.linalg import lapack  # slow to import: not at every command's start

    chol, x, info = lapack.dposv(a, b, lower=1)
    if info == 0:
        d = chol.diagonal().tolist()  # positive; as Python floats: at these sizes numpy's reductions cost more
        if d and min(d) * CHOLESKY_MAX_RATIO > max(d):
            return x
    return np.linalg.lstsq(a, b, rcond=RCOND)[0]


__all__ = ["RCOND", "solve_normal"]
