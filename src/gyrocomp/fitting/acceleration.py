"""g-sensitivity: the gyro bias that linear acceleration causes (thesis section 2.7).

- which accelerometer axes the calibration positions excite (:mod:`gyrocomp.fitting.gsensitivity`);
- G alone by least squares over the static positions (:func:`fit_g_sensitivity`; with a temperature
  model G is fitted jointly by :class:`gyrocomp.fitting.thermal.ThermalHysteresisModel`);
- the network with the three accelerations as inputs (:func:`fit_acceleration_network`).

The offset itself, G a (+ the g x g terms), is :func:`gyrocomp.effects.g_sensitivity_offset`.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..calibration import AxisCalibration, Calibration
from ..errors import InputError
from ..calibration.fit_report import GSensitivityReport, GSensitivityRow
from ..recording import Recording
from ..runs.prepared import PreparedRun
from .provenance import provenance
from .gsensitivity import ACCELERATION_CHOICES, EXCITATION_G, excited_columns, turned_between_positions
from ..curves.network import ACCEL_INPUTS, DEFAULT_HIDDEN, NETWORK_BLOCK_S
from .network_model import NetworkTemperatureModel
from .thermal import ThermalHysteresisModel


def _listed(values: np.ndarray) -> tuple:
    return tuple(None if not np.isfinite(v) else float(v) for v in values)


def acceleration_report(thermal, mode: str) -> dict:
    """The fit report's acceleration part: G rows and standard errors per gyro axis [deg/s/g] (and the g x g
    terms [deg/s/g^2] with ``matrix2``), written from its typed record."""
    squared = mode == "matrix2"
    rows = {
        a: GSensitivityRow(
            _listed(thermal.g_sensitivity_dps_per_g_[a]),
            _listed(thermal.g_sensitivity_se_dps_per_g_[a]),
            _listed(thermal.g_squared_dps_per_g2_[a]) if squared else None,
            _listed(thermal.g_squared_se_dps_per_g2_[a]) if squared else None,
        )
        for a in thermal.g_sensitivity_dps_per_g_
    }
    return GSensitivityReport(
        mode, None, tuple(len(segs) for segs in thermal.segments_), tuple(thermal.excited_axes_), rows
    ).to_dict()


def fit_g_sensitivity(recordings: list[Recording], mode: str, static_min_duration_s: float) -> Calibration:
    """The thesis's 3x3 g-sensitivity matrix G (section 2.7.1) and one constant per run, by least squares over
    the static segments, without a temperature model (no temperature, or temperature=None); ``mode``
    ``matrix2`` adds the g x g terms. With a temperature model, G is fitted jointly instead
    (:class:`gyrocomp.fitting.thermal.ThermalHysteresisModel`)."""
    flat = [dataclasses.replace(rec, temperature_degc=np.zeros(rec.n_samples)) for rec in recordings]
    thermal = ThermalHysteresisModel(
        order=0, hysteresis="none", acceleration=mode, static_min_duration_s=static_min_duration_s
    ).fit(flat)
    axes = {}
    for axis in recordings[0].gyro_axes:
        g_row = tuple(map(float, thermal.g_sensitivity_dps_per_g_[axis])) if thermal.excited_axes_ else None
        g_sq = tuple(map(float, thermal.g_squared_dps_per_g2_[axis])) if mode == "matrix2" and g_row else None
        axes[axis] = AxisCalibration(
            None,
            tuple(float(c) for c in thermal.turn_on_biases_[axis]),
            g_sensitivity_dps_per_g=g_row,
            g_squared_dps_per_g2=g_sq,
        )
    name = "g-sensitivity" + (" (g x g)" if mode == "matrix2" else "") if thermal.excited_axes_ else "none"
    return Calibration(
        axes=axes,
        model=name,
        provenance=provenance(recordings),
        fit_report={"temperature": None, "acceleration": acceleration_report(thermal, mode)},
    )


def fit_acceleration_network(
    recordings: list[Recording], *, hidden: tuple[int, ...] = DEFAULT_HIDDEN, seed: int = 0, min_static: float = 10.0
) -> Calibration:
    """The thesis's acceleration network (section 2.7.2): accel_x, accel_y, accel_z in, the gyro bias out (and
    one constant per run), trained on the static segments of at least ``min_static`` [s] of the runs; ``hidden``
    neurons per layer, restarts drawn from ``seed``."""
    network = NetworkTemperatureModel(hidden=hidden, seed=seed)
    segments = [PreparedRun.of(rec).static_segments(min_duration_s=min_static) for rec in recordings]
    for rec in recordings:
        if rec.accel_g is None:
            raise InputError(f"{rec.source}: pipeline=mlp>mlp-accel needs accel_x, accel_y and accel_z columns")
    axes = {}
    for axis in recordings[0].gyro_axes:
        t_in, y_in, w_in, a_in = [], [], [], []
        for rec, segs in zip(recordings, segments):
            pieces = [slice(g.start, g.stop) for g in segs] or None
            # one temperature bin: equal weights
            blocks = PreparedRun.of(rec).block_means(axis, NETWORK_BLOCK_S, math.inf, pieces)
            t_in.append(blocks.temperature_degc)
            y_in.append(blocks.value)
            w_in.append(blocks.weight)
            a_in.append(blocks.accel_g)
        network.fit_blocks(axis, t_in, y_in, w_in, t_ref_degc=0.0, accel_g=a_in, inputs=ACCEL_INPUTS)
        axes[axis] = AxisCalibration(
            None, tuple(float(c) for c in network.turn_on_biases_[axis]), acceleration_network=network.curves_[axis]
        )
    report = {
        "acceleration": GSensitivityReport(
            "network", None, tuple(len(s) for s in segments), (), {}, tuple(hidden)
        ).to_dict()
    }
    return Calibration(
        axes=axes,
        model="mlp-accel:3-" + "-".join(map(str, hidden)) + "-1",
        provenance=provenance(recordings),
        fit_report=report,
    )


__all__ = [
    "ACCELERATION_CHOICES",
    "EXCITATION_G",
    "acceleration_report",
    "excited_columns",
    "fit_acceleration_network",
    "fit_g_sensitivity",
    "turned_between_positions",
]
