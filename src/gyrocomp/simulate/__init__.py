"""Simulated gyro recordings with their truth: the tests' and the demo's source of ground truth."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..recording import ACCEL_AXES, Recording
from .error_model import GyroErrorModel, NoiseTruth, flicker_bank, simulate_noise
from .profiles import PROFILES, SetPointProfile, get_profile


@dataclass(frozen=True)
class Truth:
    """What the simulator put into a recording.

    Attributes
    ----------
    model : GyroErrorModel
    profile : SetPointProfile
    seed : int
    turn_on_bias_dps : array (k,)
        The constant bias of this power-on, per axis [deg/s].
    temperature_error_dps : array (n, k)
        The temperature-dependent bias, without the constant [deg/s].
    noise : NoiseTruth
        The random errors [deg/s].
    """

    model: GyroErrorModel
    profile: SetPointProfile
    seed: int
    rate_hz: float
    duration_s: float
    turn_on_bias_dps: np.ndarray
    temperature_error_dps: np.ndarray = field(repr=False)
    noise: NoiseTruth = field(repr=False)

    @property
    def deterministic_error_dps(self) -> np.ndarray:
        """Everything a perfect compensation removes: turn-on constant plus temperature bias (n, k) [deg/s]."""
        return self.temperature_error_dps + self.turn_on_bias_dps

    def to_dict(self) -> dict:
        return {
            "seed": self.seed,
            "rate_hz": self.rate_hz,
            "duration_s": self.duration_s,
            "profile": {"name": self.profile.name, "set_points_degc": list(self.profile.set_points_degc),
                        "dwell_fraction": self.profile.dwell_fraction},
            "error_model": self.model.to_dict(),
            "turn_on_bias_dps": dict(zip(self.model.axes, map(float, self.turn_on_bias_dps))),
        }


@dataclass(frozen=True)
class Simulation:
    recording: Recording
    truth: Truth


def simulate(model: GyroErrorModel | None = None, *, profile: str | SetPointProfile = "chamber",
             duration_s: float = 3600.0, rate_hz: float = 100.0, seed: int = 0,
             source: str | None = None) -> Simulation:
    """Simulate one power-on of a gyro at rest.

    Parameters
    ----------
    model : GyroErrorModel, optional
        Error parameters; default a 3-axis MTi-10-class part.
    profile : str or SetPointProfile
        Temperature profile (``chamber``, ``cycle``, ``static``) or a custom one.
    duration_s : float
        Length of the run [s].
    rate_hz : float
        Sample rate [Hz].
    seed : int
        Seed of the random numbers; the same seed gives the same run.
    """
    model = model or GyroErrorModel()
    prof = get_profile(profile) if isinstance(profile, str) else profile
    if not duration_s > 0 or not rate_hz > 0:
        raise InputError("--duration and --rate must be positive")
    n = int(math.floor(duration_s * rate_hz)) + 1
    if n < 2:
        raise InputError("--duration: too short for one sample period at this --rate")
    rng = np.random.default_rng(seed)
    time_s = np.arange(n) / rate_hz
    temperature = prof.temperature_degc(time_s)
    turn_on = rng.standard_normal(len(model.axes)) * model.turn_on_bias_sigma_dps
    temp_error = model.temperature_error_dps(temperature)
    noise = simulate_noise(n, rate_hz, model, rng)
    gyro = temp_error + turn_on + noise.total_dps
    accel = None if model.accel_g is None else np.tile(np.asarray(model.accel_g, dtype=float), (n, 1))
    rec = Recording(time_s=time_s, gyro_dps=gyro, gyro_axes=model.axes, temperature_degc=temperature,
                    accel_g=accel, accel_axes=ACCEL_AXES if accel is not None else (),
                    source=source or f"simulated:{prof.name}:seed{seed}")
    truth = Truth(model, prof, seed, rate_hz, duration_s, turn_on, temp_error, noise)
    return Simulation(rec, truth)


__all__ = ["GyroErrorModel", "NoiseTruth", "PROFILES", "SetPointProfile", "Simulation", "Truth",
           "flicker_bank", "get_profile", "simulate", "simulate_noise"]
