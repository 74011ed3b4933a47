"""Which columns of the g-sensitivity matrix G the calibration positions let a fit see: the design helpers
every g-sensitivity fit shares (:mod:`gyrocomp.fitting.thermal`'s joint fit, :mod:`gyrocomp.fitting.acceleration`).
"""

from __future__ import annotations

import warnings

import numpy as np

from ..effects import G_SQUARED_TERMS
from ..errors import DataQualityWarning
from ..recording import ACCEL_AXES, Recording
from ..runs.prepared import PreparedRun
from ..motion.positions import orientations

ACCELERATION_CHOICES = ("none", "matrix", "matrix2")
#: an accelerometer axis is excited when its within-run spread over the positions exceeds this [g]
EXCITATION_G = 0.1


def excited_columns(
    accel_g: list[np.ndarray], weights: list[np.ndarray], *, squares: bool = False, warn: bool = True
) -> tuple[tuple[int, ...], tuple[int, ...], tuple[str, ...]]:
    """The accelerometer axes the positions excite, the g x g terms a fit can tell apart, and the names.

    Parameters
    ----------
    accel_g : list of array (n_r, 3)
        Per run, the (block-mean) accelerations of the fit's points [g].
    weights : list of array (n_r,)
        The points' weights.
    squares : bool
        Also choose the g x g terms (``gyrocomp.effects.G_SQUARED_TERMS`` indices) among the excited axes;
        with all three excited, zz is left out (xx + yy + zz = 1 g^2 at rest makes it the constant).
    warn : bool
        Warn (``DataQualityWarning``) about axes below ``EXCITATION_G`` of within-run spread.
    """
    spread = np.sqrt(
        sum(np.sum(w[:, None] * (a - np.average(a, axis=0, weights=w)) ** 2, axis=0) for a, w in zip(accel_g, weights))
        / sum(float(np.sum(w)) for w in weights)
    )
    excited = tuple(j for j in range(3) if spread[j] > EXCITATION_G)
    missing = [f"{ACCEL_AXES[j]} ({spread[j]:.2g} g)" for j in range(3) if j not in excited]
    if missing and warn:
        warnings.warn(
            f"the positions do not excite {', '.join(missing)}: within-run spread below {EXCITATION_G} g; "
            "those columns of the g-sensitivity matrix are not fitted (reported as 0 with no standard error). "
            "Record positions that tilt every axis (a tumble: +1, 0 and -1 g on each)",
            DataQualityWarning,
            stacklevel=4,
        )
    chosen: tuple[int, ...] = ()
    if squares:
        pairs = {"xx": (0, 0), "yy": (1, 1), "zz": (2, 2), "xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}
        chosen = tuple(
            m
            for m, term in enumerate(G_SQUARED_TERMS)
            if set(pairs[term]) <= set(excited) and not (len(excited) == 3 and term == "zz")
        )
    return excited, chosen, tuple(ACCEL_AXES[j] for j in excited)


def turned_between_positions(recordings: list[Recording], min_duration_s: float) -> bool:
    """Whether some run has an accelerometer triad and more than one orientation among its static segments."""
    for rec in recordings:
        if rec.accel_g is None or not set(ACCEL_AXES) <= set(rec.accel_axes):
            continue
        if len(orientations(PreparedRun.of(rec).static_segments(min_duration_s=min_duration_s))) > 1:
            return True
    return False


__all__ = ["ACCELERATION_CHOICES", "EXCITATION_G", "excited_columns", "turned_between_positions"]
