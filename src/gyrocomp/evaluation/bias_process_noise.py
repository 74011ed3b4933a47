"""What a calibration buys an estimator, in the estimator's own terms: the bias process noise a filter needs with
the raw gyro against the compensated one over the same temperature profile.

A static run through a temperature profile: its raw rate is the bias (the temperature drift, the run's constant)
plus noise; compensated, the drift the model leaves. Each, about its mean, is bounded as a noise model a filter
can carry (:func:`gyrocomp.allan.bound.bound_noise`: white noise N and bias random walk K at or above the upper
end of the curve's 95 % interval at every octave tau) up to a quarter of the run, far enough for the slow
thermal drift to show: the K the raw gyro needs is its drift seen as a random walk, the compensated one's what
the model leaves of it. Their ratio is what the calibration buys a filter's bias process noise on that
profile.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..allan import allan_deviation
from ..allan.bound import NoiseBound, bound_noise
from ..calibration import Calibration
from ..calibration.compensate import apply
from ..errors import InputError
from ..measures.noise import analyse_noise
from ..measures.noise_model import NoiseModel, noise_model
from ..recording import Recording

#: the longest averaging time bounded, as a fraction of the shortest run: the thermal drift is slow
MAX_TAU_FRACTION = 0.25


@dataclass(frozen=True)
class BiasProcessNoise:
    """One gyro axis on the runs given: the noise model the raw and the compensated gyro need.

    Attributes
    ----------
    axis : str
        The gyro axis.
    raw, compensated : NoiseBound
        White noise [deg/s/sqrt(Hz)] and bias random walk [deg/s/sqrt(s)] at or above the raw and the
        compensated gyro's Allan curves (every run's) up to a quarter of the shortest run.
    """

    axis: str
    raw: NoiseBound
    compensated: NoiseBound

    @property
    def random_walk_ratio(self) -> float:
        """The raw gyro's bias random walk over the compensated one's (what the calibration buys)."""
        c = self.compensated.random_walk
        return self.raw.random_walk / c if c > 0 else np.inf


def bias_process_noise(
    calibration: Calibration, recordings: Recording | list[Recording], axes: list[str] | None = None
) -> dict[str, BiasProcessNoise]:
    """The bias process noise a filter needs, raw and compensated, on static runs through a temperature profile.

    Parameters
    ----------
    calibration : Calibration
        The model.
    recordings : Recording or list of Recording
        Static runs held out from the fit, through the temperature profile of interest [s, deg/s, degC].
    axes : list of str, optional
        The gyro axes (default every one the model and the runs share).

    Returns
    -------
    dict of str to BiasProcessNoise
    """
    runs = [recordings] if isinstance(recordings, Recording) else list(recordings)
    names = _gyro_axes(calibration, runs, axes)
    return _bias_bounds(runs, _compensated(calibration, runs), names)


def _gyro_axes(calibration: Calibration, runs: list[Recording], axes: list[str] | None) -> list[str]:
    """The gyro axes asked for (default every one the model and the runs share), checked."""
    if not runs:
        raise InputError("bias_process_noise: give at least one static run")
    shared = [a for a in calibration.axes if all(a in r.gyro_axes for r in runs)]
    names = shared if axes is None else list(axes)
    unknown = [a for a in names if a not in shared]
    if unknown or not names:
        raise InputError(
            f"axes: {', '.join(unknown) or 'none'}: the model and the runs share {', '.join(shared) or 'no gyro axis'}"
        )
    return names


def _compensated(calibration: Calibration, runs: list[Recording]) -> list[Recording]:
    """The runs compensated; a run past the model's temperature range is warned about, as apply does (its drift
    there is the model's extrapolation)."""
    return [apply(calibration, r) for r in runs]


def _bias_bounds(runs: list[Recording], compensated: list[Recording], names: list[str]) -> dict[str, BiasProcessNoise]:
    """Each axis's two-term bound of the raw and of the compensated runs about their means."""
    max_tau = MAX_TAU_FRACTION * min(float(r.time_s[-1] - r.time_s[0]) for r in runs)
    out = {}
    for name in names:
        bounds = []
        for series in (runs, compensated):
            curves = []
            for rec in series:
                values = rec.gyro_dps[:, rec.gyro_axes.index(name)]
                curves.append(allan_deviation(values - values.mean(), rec.rate_hz))
            bounds.append(bound_noise(curves, markov=False, max_tau_s=max_tau))
        out[name] = BiasProcessNoise(name, *bounds)
    return out


def compensated_noise(
    calibration: Calibration,
    recordings: list[Recording],
    axes: list[str] | None = None,
    *,
    with_accel: bool = False,
    split_gaps: bool = False,
    fit_taus_s: tuple[float, float] | None = None,
) -> tuple[NoiseModel, dict[str, BiasProcessNoise]]:
    """The noise model of the compensated gyro (what an estimator on the vehicle receives) and what the calibration
    buys its bias process noise (:func:`bias_process_noise`), on the same static runs.

    Parameters
    ----------
    calibration : Calibration
        The model.
    recordings : list of Recording
        Static runs held out from the fit [s, deg/s, g, degC].
    axes : list of str, optional
        Gyro and accelerometer axes (default every gyro axis, and the accelerometer's with ``with_accel``).
    with_accel : bool
        Also model the accelerometer axes.
    split_gaps : bool
        Pool the contiguous stretches of runs with time gaps.
    fit_taus_s : (float, float), optional
        The taus the descriptive IEEE 952 fit uses [s] (:func:`gyrocomp.measures.noise.analyse_noise`).
    """
    runs = list(recordings)
    names = _gyro_axes(calibration, runs, [a for a in axes if a.startswith("gyro")] if axes else None)
    compensated = _compensated(calibration, runs)  # once, for both
    benefit = _bias_bounds(runs, compensated, names)
    model = noise_model(
        [
            analyse_noise(
                r, axes, with_accel=with_accel, split_gaps=split_gaps, motion_check=False, fit_taus_s=fit_taus_s
            )
            for r in compensated
        ]
    )
    return model, benefit


__all__ = ["BiasProcessNoise", "MAX_TAU_FRACTION", "bias_process_noise", "compensated_noise"]
