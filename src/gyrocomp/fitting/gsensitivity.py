"""Which columns of the g-sensitivity matrix G the calibration positions let a fit see: the design helpers
every g-sensitivity fit shares (:mod:`gyrocomp.fitting.thermal`'s joint fit, :mod:`gyrocomp.fitting.acceleration`).
"""

from __future__ import annotations

import warnings

import numpy as np

from ..effects import G_SQUARED_TERMS
from ..errors import DataQualityWarning, user_stacklevel
from ..recording import ACCEL_AXES, Recording
from ..runs.prepared import PreparedRun

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
            stacklevel=user_stacklevel(),
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
    """Whether the runs turn the unit between positions far enough for a g-sensitivity fit to see: some
    accelerometer axis whose static segments' mean specific force spreads within the runs (weighted by their
    durations) beyond ``EXCITATION_G``, as :func:`excited_columns` asks of the fit's own points. Segments at one
    orientation whose specific force moves with the accelerometer's own bias over a chamber's temperatures (0.05 g on
    a real one-cycle log) are no turn.

    Parameters
    ----------
    recordings : list of Recording
        The runs; those without a whole accelerometer triad, or with one static segment, say nothing.
    min_duration_s : float
        The shortest static segment [s].
    """
    gravity_g, weights = [], []
    for rec in recordings:
        if rec.accel_g is None or not set(ACCEL_AXES) <= set(rec.accel_axes):
            continue
        segments = [
            s for s in PreparedRun.of(rec).static_segments(min_duration_s=min_duration_s) if s.gravity_g is not None
        ]
        if len(segments) > 1:
            gravity_g.append(np.array([s.gravity_g for s in segments]))
            weights.append(np.array([s.duration_s for s in segments]))
    return bool(gravity_g) and bool(excited_columns(gravity_g, weights, warn=False)[0])


__all__ = ["ACCELERATION_CHOICES", "EXCITATION_G", "excited_columns", "turned_between_positions"]
