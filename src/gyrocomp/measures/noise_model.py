"""Noise models for estimators, from the noise analyses of static logs: per axis, the IEEE Std 952 fit (what the
curve is) beside two bounds (what a filter may be told, :mod:`gyrocomp.allan.bound`): white noise and random walk
alone, the form Kalibr, VINS and the autopilots' EKFs carry, and with Gauss-Markov terms standing in for flicker.

Several logs of one part (static logs at several temperatures, say) are bounded together: the model is at or
above every log's upper confidence bound, and each log's own bound is kept for the per-log table. Values are in
the data's unit u: deg/s for a gyro axis, g for an accelerometer axis.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..allan import AllanResult, NoiseTerms
from ..allan.bound import NoiseBound, bound_noise
from ..errors import InputError
from .noise import NoiseAnalysis

#: the longest averaging time bounded, as a fraction of the shortest record: beyond it too few averages
MAX_TAU_FRACTION = 0.1


def record_length_s(curve: AllanResult, rate_hz: float) -> float:
    """The record an overlapping Allan curve was computed on [s]: N = n + 2m - 1 samples at its first tau (m
    samples averaged, n terms in the sum).

    Parameters
    ----------
    curve : AllanResult
        An overlapping Allan deviation of rate data.
    rate_hz : float
        Its sample rate [Hz].
    """
    m = max(int(round(curve.tau[0] * rate_hz)), 1)
    return (int(curve.n[0]) + 2 * m - 1) / rate_hz


@dataclass(frozen=True)
class LogNoise:
    """One log's part of an axis's model: its source, mean temperature [degC] (None without one) and the
    two-term bound of its own curve."""

    source: str
    temperature_degc: float | None
    bound: NoiseBound


@dataclass(frozen=True)
class AxisNoiseModel:
    """One axis: what the curve is and what a filter may be told.

    Attributes
    ----------
    axis, sensor, unit : str
        ``gyro_x``..., ``gyro`` or ``accel``, ``deg/s`` or ``g``.
    ieee : NoiseTerms
        The IEEE Std 952 fit of the first log's curve [u]: descriptive, lies below the curve somewhere.
    bound : NoiseBound
        White noise and random walk at or above every log's upper confidence bound [u].
    markov : NoiseBound
        The same with Gauss-Markov terms: tighter, for a filter that carries them [u].
    logs : tuple of LogNoise
        Each log's own two-term bound.
    max_tau_s : float
        The longest averaging time bounded [s].
    """

    axis: str
    sensor: str
    unit: str
    ieee: NoiseTerms
    bound: NoiseBound
    markov: NoiseBound
    logs: tuple[LogNoise, ...]
    max_tau_s: float


@dataclass(frozen=True)
class NoiseModel:
    """The noise model of every axis analysed, at the logs' sample rate ``rate_hz`` [Hz]."""

    rate_hz: float
    axes: dict[str, AxisNoiseModel]

    def to_dict(self) -> dict:
        """The model as JSON (``gyrocomp noise --export json``): each axis's bounds and IEEE terms, in its unit."""
        return {"format": "gyrocomp-noise-model", "rate_hz": self.rate_hz, "axes": {
            name: {"sensor": a.sensor, "unit": a.unit, "bound": a.bound.to_dict(), "bound_with_markov":
                   a.markov.to_dict(), "ieee_952": {"white_noise_density": a.ieee.white_noise_density,
                                                   "bias_instability": a.ieee.bias_instability,
                                                   "random_walk": a.ieee.random_walk},
                   "logs": [{"source": log.source, "temperature_degc": log.temperature_degc,
                             "white_noise_density": log.bound.white_noise_density,
                             "random_walk": log.bound.random_walk} for log in a.logs]}
            for name, a in self.axes.items()}}


def noise_model(analyses: NoiseAnalysis | list[NoiseAnalysis],
                temperatures_degc: list[float | None] | None = None) -> NoiseModel:
    """The noise model of the axes the analyses share, bounding every analysis's overlapping Allan curve.

    Parameters
    ----------
    analyses : NoiseAnalysis or list of NoiseAnalysis
        Static logs of one part (:func:`gyrocomp.measures.noise.analyse_noise`), at one sample rate.
    temperatures_degc : list of float or None, optional
        Each log's mean temperature [degC], for the per-log table.

    Returns
    -------
    NoiseModel
    """
    analyses = [analyses] if isinstance(analyses, NoiseAnalysis) else list(analyses)
    if not analyses:
        raise InputError("noise: give at least one static log")
    rates = {round(a.rate_hz, 9) for a in analyses}
    if len(rates) > 1:
        raise InputError(f"noise: the logs have different sample rates ({', '.join(f'{r:g}' for r in sorted(rates))} "
                         "Hz); a model is for one rate: analyse each rate on its own")
    temperatures = list(temperatures_degc) if temperatures_degc is not None else [None] * len(analyses)
    shared = [name for name in analyses[0].axes if all(name in a.axes for a in analyses)]
    if not shared:
        raise InputError("noise: the logs share no axis")
    rate = analyses[0].rate_hz
    axes = {}
    for name in shared:
        curves = [a.axes[name].allan for a in analyses]
        max_tau = MAX_TAU_FRACTION * min(record_length_s(c, rate) for c in curves)
        logs = tuple(LogNoise(a.source, t, bound_noise(c, markov=False, max_tau_s=max_tau))
                     for a, c, t in zip(analyses, curves, temperatures))
        first = analyses[0].axes[name]
        axes[name] = AxisNoiseModel(name, first.sensor, first.unit, first.terms,
                                    bound_noise(curves, markov=False, max_tau_s=max_tau),
                                    bound_noise(curves, markov=True, max_tau_s=max_tau), logs, max_tau)
    return NoiseModel(rate, axes)


def mean_temperature_degc(recording) -> float | None:
    """A recording's mean temperature [degC], or None without a temperature column."""
    t = recording.temperature_degc
    return None if t is None else float(np.mean(t))


__all__ = ["AxisNoiseModel", "LogNoise", "MAX_TAU_FRACTION", "NoiseModel", "mean_temperature_degc", "noise_model",
           "record_length_s"]
