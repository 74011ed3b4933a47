"""Noise models for estimators, from the noise analyses of static logs: per axis, the IEEE Std 952 fit (what the
curve is) beside two bounds (what a filter may be told, :mod:`gyrocomp.allan.bound`): white noise and random walk
alone, the form Kalibr, VINS and the autopilots' EKFs carry, and with Gauss-Markov terms standing in for flicker.

Several logs of one part (static logs at several temperatures, say) are bounded together: the model is at or
above every log's upper confidence bound, and each log's own bound is kept for the per-log table. Values are in
the data's unit u: deg/s for a gyro axis, g for an accelerometer axis.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..allan import AllanResult, NoiseTerms
from ..allan.bound import NoiseBound, bound_noise, markov_grid
from ..allan.intervals import confidence_interval
from ..errors import InputError
from ..recording import Recording
from .noise import NoiseAnalysis, analyse_noise

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
    """One log's part of an axis's model: its source, mean temperature [degC] (None without one), the two-term
    bound of its own curve, the white noise read at one sample with its 95 % interval [u/sqrt(Hz)] (the
    deviation at the shortest tau times sqrt(tau), where white noise rules), and the bound of its own curve with
    Gauss-Markov terms on the axis's grid of correlation times (the same for every log, so that a filter
    scheduling its noise by temperature interpolates term by term)."""

    source: str
    temperature_degc: float | None
    bound: NoiseBound
    white_noise_interval: tuple[float, float, float]
    markov: NoiseBound


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
        Each log's own bounds.
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
        return {
            "format": NOISE_MODEL_FORMAT,
            "rate_hz": self.rate_hz,
            "axes": {
                name: {
                    "sensor": a.sensor,
                    "unit": a.unit,
                    "bound": a.bound.to_dict(),
                    "bound_with_markov": a.markov.to_dict(),
                    "ieee_952": {
                        "white_noise_density": a.ieee.white_noise_density,
                        "bias_instability": a.ieee.bias_instability,
                        "random_walk": a.ieee.random_walk,
                    },
                    "logs": [
                        {
                            "source": log.source,
                            "temperature_degc": log.temperature_degc,
                            "white_noise_density": log.bound.white_noise_density,
                            "random_walk": log.bound.random_walk,
                            "white_noise_at_one_sample_95": list(log.white_noise_interval),
                            "bound_with_markov": log.markov.to_dict(),
                        }
                        for log in a.logs
                    ],
                }
                for name, a in self.axes.items()
            },
        }


def _white_at_one_sample(curve: AllanResult) -> tuple[float, float, float]:
    """(low, value, high): the deviation at the shortest tau times sqrt(tau), with its 95 % interval."""
    low, high = confidence_interval(curve.deviation[:1], curve.edf[:1], 0.95)
    root = float(np.sqrt(curve.tau[0]))
    return float(low[0]) * root, float(curve.deviation[0]) * root, float(high[0]) * root


def noise_model(
    analyses: NoiseAnalysis | list[NoiseAnalysis], temperatures_degc: list[float | None] | None = None
) -> NoiseModel:
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
        raise InputError(
            f"noise: the logs have different sample rates ({', '.join(f'{r:g}' for r in sorted(rates))} "
            "Hz); a model is for one rate: analyse each rate on its own"
        )
    temperatures = list(temperatures_degc) if temperatures_degc is not None else [None] * len(analyses)
    shared = [name for name in analyses[0].axes if all(name in a.axes for a in analyses)]
    if not shared:
        raise InputError("noise: the logs share no axis")
    rate = analyses[0].rate_hz
    axes = {}
    for name in shared:
        curves = [a.axes[name].allan for a in analyses]
        max_tau = MAX_TAU_FRACTION * min(record_length_s(c, rate) for c in curves)
        markov = bound_noise(curves, markov=True, max_tau_s=max_tau)
        grid = markov_grid(markov.taus_s[0], markov.taus_s[-1])
        logs = tuple(
            LogNoise(
                a.source,
                t,
                bound_noise(c, markov=False, max_tau_s=max_tau),
                _white_at_one_sample(c),
                bound_noise(c, markov=True, max_tau_s=max_tau, time_constants_s=grid),
            )
            for a, c, t in zip(analyses, curves, temperatures)
        )
        first = analyses[0].axes[name]
        axes[name] = AxisNoiseModel(
            name,
            first.sensor,
            first.unit,
            first.terms,
            bound_noise(curves, markov=False, max_tau_s=max_tau),
            markov,
            logs,
            max_tau,
        )
    return NoiseModel(rate, axes)


def scheduled_bound(axis: AxisNoiseModel, *, markov: bool = False) -> Callable[[float], NoiseBound]:
    """The noise an axis needs at a temperature: each log's own bound at its temperature, its variances (N^2, K^2,
    sigma^2 of each Gauss-Markov term) interpolated linearly between them and held past the coldest and the
    hottest (what a filter scheduling its noise by temperature is told).

    Parameters
    ----------
    axis : AxisNoiseModel
        An axis modelled from logs at known temperatures (:func:`noise_over_temperature`).
    markov : bool
        The logs' bounds with Gauss-Markov terms (every term any log uses at every temperature, zero where a log
        needs none); False: white noise and random walk only.

    Returns
    -------
    callable
        ``at(temperature_degc [degC]) -> NoiseBound`` [u].
    """
    logs = sorted((log for log in axis.logs if log.temperature_degc is not None), key=lambda log: log.temperature_degc)
    if not logs:
        raise InputError(f"{axis.axis}: no log with a temperature to schedule by")
    bounds = [log.markov if markov else log.bound for log in logs]
    t = np.array([log.temperature_degc for log in logs])
    times = sorted({time_constant for b in bounds for _, time_constant in b.markov})
    # each log's variance coefficients [N^2, K^2, sigma_j^2...], interpolated as variances: between two logs the
    # model is then the mix of their two models, never below both (as interpolated sigmas would be where the two
    # logs' programmes chose neighbouring correlation times)
    variances = np.array(
        [
            [
                b.white_noise_density**2,
                b.random_walk**2,
                *(dict((tc, s) for s, tc in b.markov).get(tc, 0.0) ** 2 for tc in times),
            ]
            for b in bounds
        ]
    )

    def at(temperature_degc: float) -> NoiseBound:
        v = [float(np.interp(temperature_degc, t, variances[:, j])) for j in range(variances.shape[1])]
        return NoiseBound(
            math.sqrt(v[0]),
            math.sqrt(v[1]),
            tuple((math.sqrt(s2), tc) for s2, tc in zip(v[2:], times)),
            axis.bound.taus_s,
            math.nan,
            math.nan,
        )

    return at


#: the ``format`` of a noise model's JSON (``gyrocomp noise --export json``)
NOISE_MODEL_FORMAT = "gyrocomp-noise-model"


def per_sample_covariance(density: float, rate_hz: float) -> list[float]:
    """The row-major 3x3 covariance of one sample of white noise of ``density`` [u/sqrt(Hz)] at ``rate_hz`` [Hz]:
    N^2 rate on the diagonal [u^2] (``sensor_msgs/Imu``'s covariance fields)."""
    if not (isinstance(rate_hz, (int, float)) and rate_hz > 0 and math.isfinite(rate_hz)):
        raise InputError(f"rate_hz: a positive number of Hz, got {rate_hz!r}")
    v = density**2 * rate_hz
    return [v, 0.0, 0.0, 0.0, v, 0.0, 0.0, 0.0, v]


def noise_file_densities(path) -> tuple[float | None, float | None]:
    """The largest white-noise density of the gyro axes [deg/s/sqrt(Hz)] and of the accelerometer axes
    [g/sqrt(Hz)] of a noise model's JSON file (``gyrocomp noise --export json``; None for a sensor it lacks).

    Parameters
    ----------
    path : path
        The file.
    """
    try:
        d = json.loads(Path(path).read_text())
    except (OSError, ValueError) as exc:
        raise InputError(
            f"{path}: not a readable noise model ({type(exc).__name__}); gyrocomp's json noise export writes one"
        ) from None
    if not isinstance(d, dict) or d.get("format") != NOISE_MODEL_FORMAT or not isinstance(d.get("axes"), dict):
        raise InputError(
            f'{path}: not a gyrocomp noise model (no "format": "{NOISE_MODEL_FORMAT}"); gyrocomp\'s '
            "json noise export writes one"
        )
    found: dict[str, list[float]] = {"gyro": [], "accel": []}
    for name, axis in d["axes"].items():
        try:
            value = float(axis["bound"]["white_noise_density_u_per_sqrt_hz"])
        except (KeyError, TypeError, ValueError):
            raise InputError(
                f"{path}: axes.{name}.bound.white_noise_density_u_per_sqrt_hz: missing or not a number"
            ) from None
        if not (math.isfinite(value) and value >= 0):
            raise InputError(f"{path}: axes.{name}.bound.white_noise_density_u_per_sqrt_hz: {value!r} is not a density")
        found["accel" if str(name).startswith("accel") else "gyro"].append(value)
    return (max(found["gyro"]) if found["gyro"] else None, max(found["accel"]) if found["accel"] else None)


def mean_temperature_degc(recording) -> float | None:
    """A recording's mean temperature [degC], or None without a temperature column."""
    t = recording.temperature_degc
    return None if t is None else float(np.mean(t))


#: a dwell holds the temperature within this rate [degC/min], over a minute's moving average
DWELL_RATE_DEGC_PER_MIN = 0.05


def temperature_dwells(
    recording: Recording,
    *,
    settle_s: float = 300.0,
    min_duration_s: float = 600.0,
    max_rate_degc_per_min: float = DWELL_RATE_DEGC_PER_MIN,
) -> list[slice]:
    """The stretches of a chamber run where the temperature holds, each without its first ``settle_s``.

    Parameters
    ----------
    recording : Recording
        A run with a temperature column [degC].
    settle_s : float
        Left out at the start of each dwell, while the part settles [s].
    min_duration_s : float
        The shortest stretch kept, after settling [s].
    max_rate_degc_per_min : float
        The largest rate of change of the temperature (a minute's moving average) in a dwell [degC/min].

    Returns
    -------
    list of slice
        The rows of each dwell, in time order.
    """
    if recording.temperature_degc is None:
        raise InputError(f"{recording.source}: no temperature column; dwells are told by the temperature")
    t = np.asarray(recording.temperature_degc, dtype=float)
    t = t.mean(axis=1) if t.ndim == 2 else t
    window = max(int(round(60.0 * recording.rate_hz)), 1)
    smooth = np.convolve(t, np.ones(window) / window, mode="same")
    # the change of the minute's mean over a minute (a sample-to-sample slope of a quantized, noisy sensor is noise)
    ahead = np.minimum(np.arange(t.size) + window, t.size - 1)
    rate = (smooth[ahead] - smooth) / np.maximum(recording.time_s[ahead] - recording.time_s, 1e-9) * 60.0
    holds = np.abs(rate) <= max_rate_degc_per_min
    edges = np.flatnonzero(np.diff(np.r_[0, holds.astype(np.int8), 0]))
    out = []
    for start, stop in zip(edges[::2], edges[1::2]):
        first = int(np.searchsorted(recording.time_s, recording.time_s[start] + settle_s))
        if stop > first and recording.time_s[stop - 1] - recording.time_s[first] >= min_duration_s:
            out.append(slice(first, stop))
    return out


def noise_over_temperature(
    recordings: Recording | list[Recording],
    axes: list[str] | None = None,
    *,
    with_accel: bool = False,
    settle_s: float = 300.0,
    min_duration_s: float = 600.0,
    fit_taus_s: tuple[float, float] | None = None,
) -> NoiseModel:
    """The noise model of chamber runs' dwells (:func:`temperature_dwells`), each dwell a log at its mean
    temperature: the bound covers every dwell, and each dwell's own bound makes the per-temperature table.

    Parameters
    ----------
    recordings : Recording or list of Recording
        Chamber runs held at several temperatures [s, deg/s, g, degC].
    axes : list of str, optional
        The axes (default every gyro axis, and every accelerometer axis with ``with_accel``).
    with_accel : bool
        Also model the accelerometer axes.
    settle_s, min_duration_s : float
        As :func:`temperature_dwells` [s].
    fit_taus_s : (float, float), optional
        The taus the descriptive IEEE 952 fit of each dwell uses [s] (:func:`gyrocomp.measures.noise.analyse_noise`).
    """
    pieces = []
    for recording in [recordings] if isinstance(recordings, Recording) else recordings:
        dwells = temperature_dwells(recording, settle_s=settle_s, min_duration_s=min_duration_s)
        if not dwells:
            raise InputError(
                f"{recording.source}: no dwell of {min_duration_s:g} s after {settle_s:g} s of settling "
                f"(the temperature held within {DWELL_RATE_DEGC_PER_MIN:g} degC/min); give static logs, "
                "or a chamber run with longer dwells"
            )
        pieces += [recording.take(d) for d in dwells]
    analyses = [
        analyse_noise(
            p, axes, with_accel=with_accel, motion_check=False, plausibility_check=False, fit_taus_s=fit_taus_s
        )
        for p in pieces
    ]
    named = [
        dataclasses.replace(a, source=f"{p.source} at {mean_temperature_degc(p):.1f} degC")
        for a, p in zip(analyses, pieces)
    ]
    return noise_model(named, [mean_temperature_degc(p) for p in pieces])


__all__ = [
    "AxisNoiseModel",
    "DWELL_RATE_DEGC_PER_MIN",
    "LogNoise",
    "MAX_TAU_FRACTION",
    "NOISE_MODEL_FORMAT",
    "NoiseModel",
    "noise_file_densities",
    "per_sample_covariance",
    "scheduled_bound",
    "mean_temperature_degc",
    "noise_model",
    "noise_over_temperature",
    "record_length_s",
    "temperature_dwells",
]
