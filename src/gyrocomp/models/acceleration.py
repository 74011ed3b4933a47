"""g-sensitivity: the gyro bias that linear acceleration causes (thesis section 2.7).

- which accelerometer axes the calibration positions excite, and so which columns of G a fit can see;
- G alone by least squares over the static positions (:func:`fit_g_sensitivity`; with a temperature
  model G is fitted jointly by :class:`gyrocomp.models.thermal.ThermalHysteresisModel`);
- the network with the three accelerations as inputs (:func:`fit_acceleration_network`).

The offset itself, G a (+ the g x g terms), is :func:`gyrocomp.effects.g_sensitivity_offset`.
"""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np

from ..calibration import AxisCalibration, Calibration
from ..effects import G_SQUARED_TERMS
from ..errors import DataQualityWarning, InputError
from ..recording import ACCEL_AXES, Recording
from .base import block_means, provenance
from .mlp import ACCEL_INPUTS, DEFAULT_HIDDEN, NETWORK_BLOCK_S, MLPTemperatureModel

ACCELERATION_CHOICES = ("none", "matrix", "matrix2")
#: an accelerometer axis is excited when its within-run spread over the positions exceeds this [g]
EXCITATION_G = 0.1


def excited_columns(accel_g: list[np.ndarray], weights: list[np.ndarray], *, squares: bool = False,
                    warn: bool = True) -> tuple[tuple[int, ...], tuple[int, ...], tuple[str, ...]]:
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
    spread = np.sqrt(sum(np.sum(w[:, None] * (a - np.average(a, axis=0, weights=w)) ** 2, axis=0)
                         for a, w in zip(accel_g, weights)) / sum(float(np.sum(w)) for w in weights))
    excited = tuple(j for j in range(3) if spread[j] > EXCITATION_G)
    missing = [f"{ACCEL_AXES[j]} ({spread[j]:.2g} g)" for j in range(3) if j not in excited]
    if missing and warn:
        warnings.warn(
            f"the positions do not excite {', '.join(missing)}: within-run spread below {EXCITATION_G} g; "
            "those columns of the g-sensitivity matrix are not fitted (reported as 0 with no standard error). "
            "Record positions that tilt every axis (a tumble: +1, 0 and -1 g on each)",
            DataQualityWarning, stacklevel=4)
    chosen: tuple[int, ...] = ()
    if squares:
        pairs = {"xx": (0, 0), "yy": (1, 1), "zz": (2, 2), "xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}
        chosen = tuple(m for m, term in enumerate(G_SQUARED_TERMS)
                       if set(pairs[term]) <= set(excited) and not (len(excited) == 3 and term == "zz"))
    return excited, chosen, tuple(ACCEL_AXES[j] for j in excited)


def _listed(values: np.ndarray) -> list:
    return [None if not np.isfinite(v) else float(v) for v in values]


def turned_between_positions(recordings: list[Recording], min_duration_s: float) -> bool:
    """Whether some run has an accelerometer triad and more than one orientation among its static segments."""
    from ..static import orientations, static_segments

    for rec in recordings:
        if rec.accel_g is None or not set(ACCEL_AXES) <= set(rec.accel_axes):
            continue
        if len(orientations(static_segments(rec, min_duration_s=min_duration_s))) > 1:
            return True
    return False


def acceleration_report(thermal, mode: str) -> dict:
    """The fit report's acceleration part: G rows and standard errors per gyro axis [deg/s/g]."""
    return {
        "mode": mode, "excited_axes": list(thermal.excited_axes_),
        "static_segments": [len(segs) for segs in thermal.segments_],
        "axes": {a: {"g_sensitivity_dps_per_g": _listed(thermal.g_sensitivity_dps_per_g_[a]),
                     "standard_error_dps_per_g": _listed(thermal.g_sensitivity_se_dps_per_g_[a]),
                     **({"g_squared_dps_per_g2": _listed(thermal.g_squared_dps_per_g2_[a]),
                         "g_squared_standard_error_dps_per_g2": _listed(thermal.g_squared_se_dps_per_g2_[a])}
                        if mode == "matrix2" else {})}
                 for a in thermal.g_sensitivity_dps_per_g_}}


def fit_g_sensitivity(recordings: list[Recording], mode: str, static_min_duration_s: float) -> Calibration:
    """The thesis's 3x3 g-sensitivity matrix G (section 2.7.1) and one constant per run, by least squares over
    the static segments, without a temperature model (no temperature, or --temperature none); ``mode``
    ``matrix2`` adds the g x g terms. With a temperature model, G is fitted jointly instead
    (:class:`gyrocomp.models.thermal.ThermalHysteresisModel`)."""
    from .thermal import ThermalHysteresisModel

    flat = [dataclasses.replace(rec, temperature_degc=np.zeros(rec.n_samples)) for rec in recordings]
    thermal = ThermalHysteresisModel(order=0, hysteresis="none", acceleration=mode,
                                     static_min_duration_s=static_min_duration_s).fit(flat)
    axes = {}
    for axis in recordings[0].gyro_axes:
        g_row = tuple(map(float, thermal.g_sensitivity_dps_per_g_[axis])) if thermal.excited_axes_ else None
        g_sq = tuple(map(float, thermal.g_squared_dps_per_g2_[axis])) if mode == "matrix2" and g_row else None
        axes[axis] = AxisCalibration(None, tuple(float(c) for c in thermal.turn_on_biases_dps_[axis]),
                                     g_sensitivity_dps_per_g=g_row, g_squared_dps_per_g2=g_sq)
    name = "g-sensitivity" + (" (g x g)" if mode == "matrix2" else "") if thermal.excited_axes_ else "none"
    return Calibration(axes=axes, model=name, provenance=provenance(recordings),
                       fit_report={"temperature": None, "acceleration": acceleration_report(thermal, mode)})


def fit_acceleration_network(recordings: list[Recording], options: dict, min_static: float) -> Calibration:
    """The thesis's acceleration network (section 2.7.2): accel_x, accel_y, accel_z in, the gyro bias out (and
    one constant per run), trained on the static segments of the runs."""
    from ..static import static_segments

    hidden = options["temperature"][1] if isinstance(options.get("temperature"), tuple) else DEFAULT_HIDDEN
    network = MLPTemperatureModel(hidden=hidden, seed=options.get("mlp_seed", 0))
    segments = [static_segments(rec, min_duration_s=min_static) for rec in recordings]
    for rec in recordings:
        if rec.accel_g is None:
            raise InputError(f"{rec.source}: --pipeline mlp>mlp-accel needs accel_x, accel_y and accel_z columns")
    axes = {}
    for axis in recordings[0].gyro_axes:
        t_in, y_in, w_in, a_in = [], [], [], []
        for rec, segs in zip(recordings, segments):
            pieces = [slice(g.start, g.stop) for g in segs] or None
            blocks = block_means(rec, axis, NETWORK_BLOCK_S, math.inf, pieces)  # one temperature bin: equal weights
            t_in.append(blocks.temperature_degc)
            y_in.append(blocks.value_dps)
            w_in.append(blocks.weight)
            a_in.append(blocks.accel_g)
        network.fit_blocks(axis, t_in, y_in, w_in, t_ref_degc=0.0, accel_g=a_in, inputs=ACCEL_INPUTS)
        axes[axis] = AxisCalibration(None, tuple(float(c) for c in network.turn_on_biases_dps_[axis]),
                                     acceleration_network=network.curves_[axis])
    report = {"acceleration": {"mode": "network", "hidden": list(hidden),
                               "static_segments": [len(s) for s in segments]}}
    return Calibration(axes=axes, model="mlp-accel:3-" + "-".join(map(str, hidden)) + "-1",
                       provenance=provenance(recordings), fit_report=report)


__all__ = ["ACCELERATION_CHOICES", "EXCITATION_G", "acceleration_report", "excited_columns", "fit_acceleration_network",
           "fit_g_sensitivity", "turned_between_positions"]
