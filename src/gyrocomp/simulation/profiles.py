"""Calibration test profiles: what the chamber and the positioning table do to the sensor.

A profile gives, on a uniform time grid, the reported temperature [degC], the specific force
in the body frame [g] (gravity for the current orientation), the true angular rate [deg/s]
while the unit is being turned, and which samples are recorded (a ``combined`` run pauses the
recording while the unit is repositioned, so its file has time gaps). Profiles follow the test
setups of the reference thesis (M. Ali, METU, 2014, chapter 2.3-2.4).

Every profile has a natural duration from its parameters; ``with_duration`` stretches or
compresses its time axis to another one (ramp rates change in proportion).
"""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass

import numpy as np

from ..errors import InputError

#: the accelerations each axis is set to in a tumble test [g] (thesis section 2.3.2)
TUMBLE_LEVELS_G = (1.0, 0.75, 0.5, 0.25, 0.0, -0.25, -0.5, -0.75, -1.0)
UP = (0.0, 0.0, 1.0)


def tumble_positions(levels_g: tuple[float, ...] = TUMBLE_LEVELS_G) -> tuple[tuple[float, float, float], ...]:
    """Orientations of a tumble test as specific-force vectors [g] (unit length).

    Each axis in turn is set to every level c: x by tilting about y, f = (c, 0, sqrt(1-c^2));
    y by tilting about x, f = (0, c, sqrt(1-c^2)); z by tilting about y, f = (sqrt(1-c^2), 0, c).
    """
    out = []
    for axis in range(3):
        for c in levels_g:
            s = math.sqrt(max(0.0, 1.0 - c * c))
            out.append(((c, 0.0, s), (0.0, c, s), (s, 0.0, c))[axis])
    return tuple(out)


@dataclass(frozen=True)
class Trajectory:
    """What the sensor experiences, sample by sample, on a uniform grid.

    Attributes
    ----------
    time_s : array (n,)
        Sample times [s].
    temperature_degc : array (n,)
        Temperature the sensor reports, before its own noise and quantization [degC].
    specific_force_g : array (n, 3)
        Specific force in the body frame [g] (at rest: minus gravity, 1 g up).
    angular_rate_dps : array (n, 3)
        True angular rate of the body [deg/s].
    recorded : array (n,) of bool
        Samples written to the output (False while the recording is paused).
    """

    time_s: np.ndarray
    temperature_degc: np.ndarray
    specific_force_g: np.ndarray
    angular_rate_dps: np.ndarray
    recorded: np.ndarray


#: what simulating one sample holds at its peak (truth, components, trajectory; measured: about 400) [bytes]
SIMULATION_BYTES_PER_SAMPLE = 500


def _memory_bytes() -> int | None:
    """This machine's physical memory [bytes], or None where the platform does not say."""
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):
        return None


def _check_memory(n_samples: int, duration_s: float, rate_hz: float) -> None:
    """Refuse up front a simulation that cannot fit in this machine's memory, naming the two settings."""
    need = n_samples * SIMULATION_BYTES_PER_SAMPLE
    have = _memory_bytes()
    if have is not None and need > have:
        raise InputError(
            f"duration_s: {duration_s:g} s at rate_hz={rate_hz:g} is {n_samples:.3g} samples, about "
            f"{need / 1e9:.3g} GB to simulate, more than this machine's {have / 1e9:.3g} GB; "
            "shorten duration_s= or lower rate_hz="
        )


@dataclass(frozen=True)
class Profile:
    """A calibration test profile (see the module doc); build one with :func:`get_profile`.

    Parameters
    ----------
    name : str
        ``static``, ``warmup``, ``chamber``, ``cycle``, ``tumble``, ``combined``, ``ratetable`` or ``field``.
    set_points_degc : tuple of float
        Temperatures visited, in order [degC] (``static``, ``tumble``, ``ratetable``: the first one; with
        several, :func:`gyrocomp.simulation.run_profiles` holds run i at set point i).
    ramp_rate_degc_per_min : float
        Rate of the ramps between set points [degC/min].
    dwell_s : float
        Time held at each set point [s].
    cycles : int
        Repetitions of the set-point sequence (``cycle``: cold-hot-cold N times).
    warmup_rise_degc, warmup_time_constant_s : float
        ``warmup``: self-heating of the part, T = T0 + rise (1 - exp(-t / time constant)).
    position_s : float
        ``tumble``/``combined``: time at each position [s].
    move_s : float
        ``tumble``: time to turn from one position to the next [s] (recorded, at constant rate);
        ``combined``: pause of the recording while the unit is repositioned [s].
    positions_g : tuple of 3-tuples
        Orientations as specific-force vectors [g]. ``warmup``, ``chamber`` and ``cycle`` with more than one
        visit them in turn, ``position_s`` each, paused ``move_s`` between (as ``combined``).
    rates_dps : tuple of float
        ``ratetable``: rates applied about each axis in turn [deg/s], ``position_s`` each.
    motion_seed : int
        ``field``: seed of the moves (their axes, angles, accelerations and vibration); the same seed gives the
        same trajectory.
    duration_s : float, optional
        Total length [s]; default: the natural length from the parameters above.
    """

    name: str
    set_points_degc: tuple[float, ...] = (25.0,)
    ramp_rate_degc_per_min: float = 1.0
    dwell_s: float = 900.0
    cycles: int = 1
    warmup_rise_degc: float = 20.0
    warmup_time_constant_s: float = 600.0
    position_s: float = 300.0
    move_s: float = 10.0
    positions_g: tuple[tuple[float, float, float], ...] = (UP,)
    rates_dps: tuple[float, ...] = ()
    duration_s: float | None = None
    motion_seed: int = 0

    def __post_init__(self) -> None:
        if not self.set_points_degc:
            raise InputError("set_points_degc: give at least one temperature")
        for option, value in (("ramp_rate_degc_per_min", self.ramp_rate_degc_per_min), ("position_s", self.position_s)):
            if not value > 0:
                raise InputError(f"{option}: must be positive, got {value}")
        if self.dwell_s < 0 or self.move_s < 0:
            raise InputError("dwell_s: the dwell and move times must not be negative")
        if self.cycles < 1:
            raise InputError(f"cycles: must be at least 1, got {self.cycles}")
        if self.duration_s is not None and not self.duration_s > 0:
            raise InputError(f"duration_s: must be positive, got {self.duration_s}")

    # -- temperature ----------------------------------------------------------------------------
    def _temperature_knots(self) -> tuple[np.ndarray, np.ndarray]:
        points = list(self.set_points_degc)
        if self.name in ("cycle", "combined"):
            # cold-hot-cold, N times: -20, 70, -20, 70, -20 for two cycles
            cold_hot = points if len(points) > 1 else points * 2
            seq = [cold_hot[0]]
            for _ in range(self.cycles):
                seq += cold_hot[1:] + cold_hot[-2::-1]
            points = seq
        elif self.cycles > 1:
            points = points + points[1:] * (self.cycles - 1)
        knots_t, knots_T = [0.0], [points[0]]
        t = self.dwell_s
        knots_t.append(t)
        knots_T.append(points[0])
        for prev, temp in zip(points, points[1:]):
            t += abs(temp - prev) / (self.ramp_rate_degc_per_min / 60.0)
            knots_t.append(t)
            knots_T.append(temp)
            t += self.dwell_s
            knots_t.append(t)
            knots_T.append(temp)
        return np.asarray(knots_t), np.asarray(knots_T, dtype=float)

    # -- motion ---------------------------------------------------------------------------------
    def _segments(self) -> list[tuple[float, tuple, tuple, bool]]:
        """(length [s], force at start, force at end, recorded) for each stretch of the motion."""
        if self.name == "ratetable":
            return [(self.position_s, UP, UP, True)] * (1 + 3 * len(self.rates_dps))
        if self.name not in ("tumble", "combined") and len(self.positions_g) == 1:
            return [(self._natural_duration(), self.positions_g[0], self.positions_g[0], True)]
        segs = []
        positions = self.positions_g
        if self.name != "tumble":  # a temperature profile visiting the positions in turn, as ``combined``
            total = self._natural_duration()
            count = max(1, int(total // (self.position_s + self.move_s)))
            positions = tuple(positions[k % len(positions)] for k in range(count))
        for k, pos in enumerate(positions):
            segs.append((self.position_s, pos, pos, True))
            if k + 1 < len(positions):
                segs.append((self.move_s, pos, positions[k + 1], self.name == "tumble"))
        return segs

    def _natural_duration(self) -> float:
        if self.name in ("chamber", "cycle", "combined"):
            return float(self._temperature_knots()[0][-1])
        if self.name in ("tumble", "ratetable"):
            return float(sum(s[0] for s in self._segments()))
        return 3600.0  # static, warmup, field

    @property
    def natural_duration_s(self) -> float:
        """Length of the profile from its parameters [s]."""
        return self._natural_duration()

    @property
    def total_duration_s(self) -> float:
        """Length of the run [s]: ``duration_s`` if set, else the natural length."""
        return self.duration_s if self.duration_s is not None else self._natural_duration()

    def with_duration(self, duration_s: float | None) -> "Profile":
        """The same profile stretched or compressed to ``duration_s`` [s] (None: unchanged)."""
        return self if duration_s is None else dataclasses.replace(self, duration_s=float(duration_s))

    def trajectory(self, rate_hz: float) -> Trajectory:
        """Sample the profile every 1/rate_hz seconds over its total duration."""
        if not rate_hz > 0:
            raise InputError(f"rate_hz: must be positive, got {rate_hz}")
        duration = self.total_duration_s
        n = int(math.floor(duration * rate_hz + 1e-9)) + 1
        if n < 2:
            raise InputError(f"duration_s: {duration:g} s is too short for two samples at {rate_hz:g} Hz")
        _check_memory(n, duration, rate_hz)
        time_s = np.arange(n) / rate_hz
        natural = self._natural_duration()
        stretch = natural / duration  # profile time per run time
        if self.name == "static" or self.name in ("tumble", "ratetable"):
            temperature = np.full(n, float(self.set_points_degc[0]))
        elif self.name in ("warmup", "field"):
            temperature = self.set_points_degc[0] + self.warmup_rise_degc * -np.expm1(
                -time_s / self.warmup_time_constant_s
            )
        else:
            knots_t, knots_T = self._temperature_knots()
            temperature = np.interp(time_s * stretch, knots_t, knots_T)
        force = np.empty((n, 3))
        rate = np.zeros((n, 3))
        recorded = np.ones(n, dtype=bool)
        if self.name == "field":
            field_motion(
                time_s,
                self.position_s / stretch,
                self.move_s / stretch,
                self.positions_g[0],
                np.random.default_rng(self.motion_seed),
                force,
                rate,
            )
        elif self.name in ("static", "warmup", "chamber", "cycle") and len(self.positions_g) == 1:
            force[:] = self.positions_g[0]
        else:
            self._fill_motion(time_s * stretch, stretch, force, rate, recorded)
        return Trajectory(time_s, temperature, force, rate, recorded)

    def _fill_motion(
        self, profile_t: np.ndarray, stretch: float, force: np.ndarray, rate: np.ndarray, recorded: np.ndarray
    ) -> None:
        start = 0.0
        segs = self._segments()
        for k, (length, f0, f1, rec) in enumerate(segs):
            stop = start + length
            last = k == len(segs) - 1
            sel = (profile_t >= start) & ((profile_t < stop) | last)
            tau = (profile_t[sel] - start) / length if length > 0 else np.zeros(int(sel.sum()))
            if self.name == "ratetable":
                # the turned axis is mounted vertical, so gravity stays on it while the table spins
                force[sel] = UP
                if k:
                    axis, which = divmod(k - 1, len(self.rates_dps))
                    force[sel] = np.eye(3)[axis]
                    rate[sel, axis] = self.rates_dps[which]
            elif f0 == f1:
                force[sel] = f0
            else:
                omega_axis, angle = _rotation_between(np.asarray(f0), np.asarray(f1))
                force[sel] = _rotate(np.asarray(f0), omega_axis, angle * tau)
                # body rate that turns the fixed gravity vector from f0 to f1 in body axes:
                # df/dt = -omega x f, so omega = -(angle / length) * axis  [rad per profile second]
                rate[sel] = -np.degrees(angle / length) * omega_axis * stretch
            recorded[sel] = rec
            start = stop


#: field profile: largest turn of one move [deg], RMS of the vibration while moving [g] and [deg/s], peak of the
#: manoeuvring acceleration [g]
FIELD_TURN_DEG = 120.0
FIELD_VIBRATION_G = 0.15
FIELD_VIBRATION_DPS = 1.0
FIELD_ACCELERATION_G = 0.3


#: field profile: longest single turn [s]
FIELD_TURN_S = 20.0


def field_motion(
    time_s: np.ndarray,
    still_s: float,
    move_s: float,
    start_g: tuple[float, float, float],
    rng: np.random.Generator,
    force: np.ndarray,
    rate: np.ndarray,
) -> np.ndarray:
    """Fill ``force`` [g] and ``rate`` [deg/s] with a field log's motion: still for ``still_s``, then moving for
    ``move_s``, in turn, from ``start_g``. A move is a series of turns of at most FIELD_TURN_S seconds, each about
    a random axis by up to FIELD_TURN_DEG with a smooth start and stop (angle Phi (tau - sin(2 pi tau) / (2 pi)),
    tau the turn's fraction), with white vibration (FIELD_VIBRATION_G and FIELD_VIBRATION_DPS RMS) and a
    manoeuvring acceleration (a half-sine of up to FIELD_ACCELERATION_G along a random direction, body frame); the
    vehicle then rests at its new attitude. Returns the mask of the still samples."""
    still = np.ones(time_s.size, dtype=bool)
    gravity = np.asarray(start_g, dtype=float)
    period = still_s + move_s
    turns = max(1, int(np.ceil(move_s / FIELD_TURN_S)))
    for k in range(int(np.ceil(time_s[-1] / period)) + 1):
        begin = k * period
        force[(time_s >= begin) & (time_s < begin + still_s)] = gravity
        for j in range(turns if move_s > 0 else 0):
            start = begin + still_s + j * move_s / turns
            moving = (time_s >= start) & (time_s < start + move_s / turns)
            if not moving.any():
                continue
            still[moving] = False
            gravity = _turn(time_s[moving], start, move_s / turns, gravity, rng, force, rate, moving)
    return still


def _turn(
    t: np.ndarray,
    start: float,
    length: float,
    gravity: np.ndarray,
    rng: np.random.Generator,
    force: np.ndarray,
    rate: np.ndarray,
    where: np.ndarray,
) -> np.ndarray:
    """One smooth turn of a field move (see :func:`field_motion`); returns the gravity direction after it."""
    tau = (t - start) / length
    axis = rng.standard_normal(3)
    axis /= np.linalg.norm(axis)
    turn = np.radians(rng.uniform(-FIELD_TURN_DEG, FIELD_TURN_DEG))
    angle = turn * (tau - np.sin(2 * np.pi * tau) / (2 * np.pi))
    push = rng.standard_normal(3)
    push *= rng.uniform(0, FIELD_ACCELERATION_G) / np.linalg.norm(push)
    m = t.size
    force[where] = (
        _rotate(gravity, axis, angle)
        + np.outer(np.sin(np.pi * tau), push)
        + rng.standard_normal((m, 3)) * FIELD_VIBRATION_G
    )
    # df/dt = -omega x f, as in _fill_motion: omega = -(d angle / dt) axis
    rate[where] = (
        -np.degrees(turn * (1 - np.cos(2 * np.pi * tau)) / length)[:, None] * axis
        + rng.standard_normal((m, 3)) * FIELD_VIBRATION_DPS
    )
    return _rotate(gravity, axis, np.array([turn]))[0]


def _rotation_between(f0: np.ndarray, f1: np.ndarray) -> tuple[np.ndarray, float]:
    """Unit axis and angle [rad] of the rotation taking unit vector f0 to f1."""
    cross = np.cross(f0, f1)
    sin, cos = np.linalg.norm(cross), float(np.dot(f0, f1))
    if sin < 1e-12:  # parallel or opposite: any perpendicular axis
        helper = np.array([1.0, 0.0, 0.0]) if abs(f0[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        cross = np.cross(f0, helper)
        sin = np.linalg.norm(cross)
        return cross / sin, (0.0 if cos > 0 else math.pi)
    return cross / sin, math.atan2(sin, cos)


def _rotate(v: np.ndarray, axis: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Rodrigues: v rotated about ``axis`` by each of ``angles`` [rad] (m, 3)."""
    c, s = np.cos(angles)[:, None], np.sin(angles)[:, None]
    return v * c + np.cross(axis, v) * s + axis * float(np.dot(axis, v)) * (1.0 - c)


def _profiles() -> dict[str, Profile]:
    cold_hot = (-20.0, 70.0)
    return {
        "static": Profile("static", set_points_degc=(25.0,)),
        "warmup": Profile("warmup", set_points_degc=(25.0,)),
        "chamber": Profile("chamber", set_points_degc=cold_hot),
        "cycle": Profile("cycle", set_points_degc=cold_hot, cycles=2),
        "tumble": Profile("tumble", set_points_degc=(25.0,), positions_g=tumble_positions()),
        "combined": Profile(
            "combined",
            set_points_degc=cold_hot,
            cycles=1,
            ramp_rate_degc_per_min=0.5,
            dwell_s=1800.0,
            position_s=240.0,
            move_s=60.0,
            positions_g=tumble_positions((1.0, 0.0, -1.0)),
        ),
        "ratetable": Profile(
            "ratetable", set_points_degc=(25.0,), position_s=60.0, rates_dps=(10.0, -10.0, 100.0, -100.0)
        ),
        # a field log: powered on at room temperature, warming by self-heating, still 2 minutes then moving 4
        "field": Profile(
            "field",
            set_points_degc=(20.0,),
            warmup_rise_degc=25.0,
            warmup_time_constant_s=900.0,
            position_s=120.0,
            move_s=240.0,
        ),
    }


#: the built-in profiles by name, with their default parameters
PROFILES: dict[str, Profile] = _profiles()


#: the parameters of a profile that can be changed (the fields of :class:`Profile` but its name)
PROFILE_PARAMETERS: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(Profile) if f.name != "name")


def changed_profile(base: Profile, overrides: dict) -> Profile:
    """``base`` with the parameters in ``overrides`` that are not None changed (see :class:`Profile` for their
    units); a name that is not a parameter is refused, naming it."""
    unknown = sorted(set(overrides) - set(PROFILE_PARAMETERS))
    if unknown:
        raise InputError(f"{unknown[0]}: not a parameter of a profile; use any of {', '.join(PROFILE_PARAMETERS)}")
    changes = {k: v for k, v in overrides.items() if v is not None}
    return dataclasses.replace(base, **changes) if changes else base


def get_profile(name: str, **overrides) -> Profile:
    """A built-in profile, optionally with parameters changed (e.g. ``ramp_rate_degc_per_min=3``; any of
    :data:`PROFILE_PARAMETERS`)."""
    try:
        base = PROFILES[name]
    except KeyError:
        raise InputError(f"profile: unknown profile {name!r}; use one of {', '.join(PROFILES)}") from None
    return changed_profile(base, overrides)
