"""Simulated gyro recordings with their exact truth: the tests' and the demo's ground truth.

    sim = simulate("mti10", profile="cycle", rate_hz=50, seed=3)
    sim.recording                 # what a logger would have written (gaps included)
    sim.truth.deterministic_error_dps, sim.truth.noise.total_dps, sim.truth.true_rate_dps
    # output = true rate + deterministic error + noise, sample by sample

The error model is documented in :mod:`gyrocomp.simulation.error_model`, the profiles in
:mod:`gyrocomp.simulation.profiles`, the sensor presets in :mod:`gyrocomp.simulation.presets`.
Not modelled: the Earth's rotation (the simulated table does not turn with the Earth),
vibration, and the accelerometer's own g x g and cross-axis errors.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from ..effects import quantize
from ..errors import InputError
from ..recording import ACCEL_AXES, Recording
from .error_model import (
    AccelErrorModel,
    GyroErrorModel,
    Hysteresis,
    NoiseTruth,
    flicker_bank,
    simulate_noise,
    structure_temperature,
)
from .presets import PRESETS, Preset, get_preset, preset_model
from .profiles import PROFILE_PARAMETERS, PROFILES, Profile, Trajectory, changed_profile, get_profile, tumble_positions

#: profiles whose temperature visits set points, which a preset's chamber range replaces by default
SET_POINT_PROFILES = ("chamber", "cycle", "combined")
#: profiles held at one temperature: with several set points, run i is held at set point i (cycling)
ONE_TEMPERATURE_PROFILES = ("static", "tumble", "ratetable")


def run_profiles(profile: Profile, runs: int) -> list[Profile]:
    """The profile of each of ``runs`` runs: a one-temperature profile (static, tumble, ratetable) given several
    set points holds run i at set point i (cycling through them), so a rate table at three temperatures is three
    runs; a field profile moves differently in each run (motion seeds motion_seed, motion_seed + 1, ...); every
    other profile is the same for every run."""
    if profile.name == "field":
        return [dataclasses.replace(profile, motion_seed=profile.motion_seed + i) for i in range(runs)]
    if profile.name not in ONE_TEMPERATURE_PROFILES or len(profile.set_points_degc) < 2:
        return [profile] * runs
    points = profile.set_points_degc
    return [dataclasses.replace(profile, set_points_degc=(points[i % len(points)],)) for i in range(runs)]


#: the parts of the deterministic error, in the order they are listed in the truth
COMPONENTS = ("temperature", "hysteresis", "acceleration", "scale_misalignment", "temperature_rate")


@dataclass(frozen=True)
class Truth:
    """What the simulator put into a recording, sample by sample (recorded samples only).

    Attributes
    ----------
    model : GyroErrorModel
        The parameters used (after any unit-to-unit randomization).
    profile : Profile
    seed : int
    rate_hz, duration_s : float
    turn_on_bias_dps : array (k,)
        The constant bias of this power-on, per axis [deg/s].
    components_dps : dict of arrays (n, k)
        The deterministic error by cause: ``temperature``, ``hysteresis``, ``acceleration``,
        ``scale_misalignment``, ``temperature_rate`` [deg/s].
    noise : NoiseTruth
        The random errors, output rounding included [deg/s].
    true_rate_dps : array (n, k)
        The body rate about each simulated axis [deg/s].
    reported_temperature_degc : array (n,)
        The temperature before the sensor's noise and rounding [degC].
    structure_temperature_degc : array (n,)
        The lagging temperature of the MEMS structure that drives the errors [degC].
    specific_force_g : array (n, 3)
        True specific force in the body frame [g].
    preset, unit : str or None, int or None
        The preset and unit number the model came from, if any.
    """

    model: GyroErrorModel
    profile: Profile
    seed: int
    rate_hz: float
    duration_s: float
    turn_on_bias_dps: np.ndarray
    components_dps: dict[str, np.ndarray] = field(repr=False)
    noise: NoiseTruth = field(repr=False)
    true_rate_dps: np.ndarray = field(repr=False)
    reported_temperature_degc: np.ndarray = field(repr=False)
    structure_temperature_degc: np.ndarray = field(repr=False)
    specific_force_g: np.ndarray = field(repr=False)
    preset: str | None = None
    unit: int | None = None

    @property
    def temperature_error_dps(self) -> np.ndarray:
        """The temperature-dependent bias, without the constant (n, k) [deg/s]."""
        return self.components_dps["temperature"]

    @property
    def deterministic_error_dps(self) -> np.ndarray:
        """Everything a perfect compensation removes (n, k) [deg/s]: the turn-on constant and every component."""
        return sum(self.components_dps.values()) + self.turn_on_bias_dps

    def truth_columns(self) -> dict[str, np.ndarray]:
        """Extra table columns: ``true_error_gyro_x`` (deterministic), ``true_noise_gyro_x``,
        ``true_rate_gyro_x`` per axis [deg/s] and ``true_structure_temperature`` [degC].

        Output = true_rate + true_error + true_noise in every row (to rounding of the last bit).
        """
        cols: dict[str, np.ndarray] = {}
        det, noise = self.deterministic_error_dps, self.noise.total_dps
        for j, axis in enumerate(self.model.axes):
            cols[f"true_error_{axis}"] = det[:, j]
            cols[f"true_noise_{axis}"] = noise[:, j]
            cols[f"true_rate_{axis}"] = self.true_rate_dps[:, j]
        cols["true_structure_temperature"] = self.structure_temperature_degc
        return cols

    def to_dict(self) -> dict:
        """Every parameter used, as JSON-ready data (no per-sample arrays)."""
        prof = dataclasses.asdict(self.profile)
        prof["duration_s"] = self.duration_s
        return {
            "preset": self.preset,
            "unit": self.unit,
            "seed": self.seed,
            "rate_hz": self.rate_hz,
            "duration_s": self.duration_s,
            "samples": int(self.true_rate_dps.shape[0]),
            "profile": prof,
            "error_model": self.model.to_dict(),
            "turn_on_bias_dps": dict(zip(self.model.axes, map(float, self.turn_on_bias_dps))),
            "deterministic_error_range_dps": {
                name: {axis: [float(c[:, j].min()), float(c[:, j].max())] for j, axis in enumerate(self.model.axes)}
                for name, c in self.components_dps.items()
            },
        }


@dataclass(frozen=True)
class Simulation:
    recording: Recording
    truth: Truth


def resolve_profile(profile: str | Profile, preset: str | None = None, **overrides) -> Profile:
    """A profile by name with optional parameter overrides; a preset's chamber range supplies the
    set points of ``chamber``, ``cycle`` and ``combined`` unless ``set_points_degc`` is given."""
    if isinstance(profile, Profile):
        return changed_profile(profile, overrides)
    if preset is not None and profile in SET_POINT_PROFILES and overrides.get("set_points_degc") is None:
        overrides["set_points_degc"] = get_preset(preset).set_points_degc
    return get_profile(profile, **overrides)


def _accelerometer(
    acc: AccelErrorModel,
    force: np.ndarray,
    structure: np.ndarray,
    t_ref: float,
    rate_hz: float,
    rng: np.random.Generator,
) -> np.ndarray:
    out = (
        force @ acc.sensitivity.T
        + np.asarray(acc.bias_g)
        + np.outer(structure - t_ref, np.asarray(acc.bias_tempco_g_per_degc))
    )
    if acc.scale_misalignment_per_degc is not None:
        out = out + (structure - t_ref)[:, None] * (force @ acc.sensitivity_per_degc.T)
    if acc.noise_density_g_per_sqrt_hz > 0:
        out = out + rng.standard_normal(force.shape) * acc.noise_density_g_per_sqrt_hz * math.sqrt(rate_hz)
    return quantize(out, acc.quantization_g)


def truth_document(runs: list[tuple[str, "Simulation"]]) -> dict:
    """The truth of several simulated runs of one part as one JSON document: the part's parameters once, then
    per run (named by its file) its seed, samples, turn-on bias [deg/s] and deterministic error range [deg/s]."""
    per_run = ("seed", "turn_on_bias_dps", "samples", "deterministic_error_range_dps")
    first = runs[0][1].truth.to_dict()
    doc = {k: v for k, v in first.items() if k not in per_run}
    doc["runs"] = [
        {
            "file": name,
            "seed": sim.truth.seed,
            "samples": sim.recording.n_samples,
            "turn_on_bias_dps": sim.truth.to_dict()["turn_on_bias_dps"],
            "deterministic_error_range_dps": sim.truth.to_dict()["deterministic_error_range_dps"],
        }
        for name, sim in runs
    ]
    return doc


# Over 60 lines on purpose: the simulation in the order the physics happens (trajectory, temperatures, each
# error term, sensor output, truth), each step a call; the docstring is a third of it.
def simulate(
    model: GyroErrorModel | str | None = None,
    *,
    profile: str | Profile = "chamber",
    duration_s: float | None = None,
    rate_hz: float = 100.0,
    seed: int = 0,
    unit: int | None = None,
    source: str | None = None,
) -> Simulation:
    """Simulate one power-on of a gyro through a test profile.

    Parameters
    ----------
    model : GyroErrorModel or str, optional
        Error parameters, or a preset name (``adxrs450``, ``mti10``, ``adis16488``, ``consumer``);
        default: a 3-axis MTi-10-class part with temperature drift and noise only.
    profile : str or Profile
        ``static``, ``warmup``, ``chamber``, ``cycle``, ``tumble``, ``combined``, ``ratetable``, ``field``, or
        a :class:`Profile` with its own parameters.
    duration_s : float, optional
        Length of the run [s]; default the profile's natural length (it is stretched to fit).
    rate_hz : float
        Sample rate [Hz].
    seed : int
        Seed of the random numbers of this run (turn-on bias and noise); the same seed gives the
        same run.
    unit : int, optional
        With a preset name: draw this unit of the production spread instead of the nominal part.
    source : str, optional
        Name recorded as the recording's source.
    """
    preset_name = model if isinstance(model, str) else None
    if preset_name is not None:
        model = preset_model(preset_name, unit)
    model = model or GyroErrorModel()
    prof = resolve_profile(profile, preset_name).with_duration(duration_s)
    if not rate_hz > 0:
        raise InputError(f"rate_hz: must be positive, got {rate_hz}")
    traj = prof.trajectory(rate_hz)
    n = traj.time_s.size
    rng = np.random.default_rng(seed)
    k = len(model.axes)
    structure = structure_temperature(model, traj.time_s, traj.temperature_degc, rate_hz)
    components = {
        "temperature": model.temperature_error_dps(structure),
        "hysteresis": model.hysteresis_error_dps(structure),
        "acceleration": model.acceleration_error_dps(traj.specific_force_g),
        "scale_misalignment": model.scale_error_dps(traj.angular_rate_dps, structure),
        "temperature_rate": model.temperature_rate_error_dps(traj.time_s, structure),
    }
    turn_on = rng.standard_normal(k) * model.turn_on_bias_sigma_dps
    noise = simulate_noise(n, rate_hz, model, rng, structure)
    true_rate = traj.angular_rate_dps[:, model.body_index]
    analog = true_rate + sum(components.values()) + turn_on + noise.total_dps
    gyro = quantize(analog, model.quantization_dps)
    noise = dataclasses.replace(noise, quantization_dps=gyro - analog)
    temperature = traj.temperature_degc
    if model.temperature_noise_degc > 0:
        temperature = temperature + rng.standard_normal(n) * model.temperature_noise_degc
    temperature = quantize(temperature, model.temperature_quantization_degc)
    accel = None
    if model.accelerometer is not None:
        accel = _accelerometer(model.accelerometer, traj.specific_force_g, structure, model.t_ref_degc, rate_hz, rng)

    keep = traj.recorded if not traj.recorded.all() else slice(None)
    src = source or f"simulated:{preset_name or 'model'}:{prof.name}:seed{seed}"
    rec = Recording(
        time_s=traj.time_s[keep],
        gyro_dps=gyro[keep],
        gyro_axes=model.axes,
        temperature_degc=temperature[keep],
        accel_g=None if accel is None else accel[keep],
        accel_axes=ACCEL_AXES if accel is not None else (),
        source=src,
        reference_rate_dps=traj.angular_rate_dps[keep] if prof.name == "ratetable" else None,
        metadata={"simulated": True, "preset": preset_name, "seed": seed, "unit": unit},
    )
    truth = Truth(
        model,
        prof,
        seed,
        float(rate_hz),
        prof.total_duration_s,
        turn_on,
        {name: c[keep] for name, c in components.items()},
        noise.take(keep),
        true_rate[keep],
        traj.temperature_degc[keep],
        structure[keep],
        traj.specific_force_g[keep],
        preset=preset_name,
        unit=unit,
    )
    return Simulation(rec, truth)


__all__ = [
    "AccelErrorModel",
    "COMPONENTS",
    "ONE_TEMPERATURE_PROFILES",
    "GyroErrorModel",
    "Hysteresis",
    "NoiseTruth",
    "PRESETS",
    "PROFILES",
    "PROFILE_PARAMETERS",
    "Preset",
    "Profile",
    "Simulation",
    "Trajectory",
    "Truth",
    "changed_profile",
    "flicker_bank",
    "get_preset",
    "get_profile",
    "preset_model",
    "resolve_profile",
    "run_profiles",
    "simulate",
    "simulate_noise",
    "truth_document",
    "tumble_positions",
]
