"""How far an autopilot's correction, computed from an exported parameter file as its firmware computes it
(:mod:`gyrocomp.calibration.installed`: PX4's ``calc_thermal_offsets_3D`` with its 1 Hz / 1 degC republish, ArduPilot's
``TCal::correct_sensor``), is from the gyrocomp model it was exported from: inside the calibrated range, beyond
it (the firmware clamps) and through a heat-cool cycle as it runs (what the file cannot carry: lag, hysteresis).

Units at the interface: temperature [degC], corrections [deg/s] (what is subtracted from the gyro's output).
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from ..calibration import Calibration
from ..calibration.compensate import predict_error
from ..errors import DataQualityWarning, TemperatureRangeWarning
from ..calibration.installed import Autopilot, ardupilot_gyro_correction_dps, px4_as_run, px4_gyro_correction_dps
from ..recording import GYRO_AXES, Recording
from .autopilot import ardupilot_parameters, px4_parameters

#: how far beyond the calibrated range the exports judge the firmware against the model [degC]
BEYOND_DEGC = 20.0


@dataclass(frozen=True)
class FirmwareDifference:
    """How far the firmware's correction is from the model's [deg/s], per gyro axis the model has: the largest
    and the RMS difference inside the calibrated range, beyond it (``BEYOND_DEGC`` each side: the firmware clamps,
    the model continues), and over a heat-cool cycle through the range as the firmware runs (PX4's steps, the
    model's lag and hysteresis: what the file cannot carry). Each is taken about its mean: a constant is the turn-on
    bias, which neither removes.

    Attributes
    ----------
    target : str
        ``px4`` or ``ardupilot``.
    axes : tuple of str
        The gyro axes compared.
    in_range_max_dps, in_range_rms_dps : tuple of float
        Per axis, the largest and the RMS difference inside the calibrated range [deg/s].
    beyond_max_dps, beyond_rms_dps : tuple of float
        The same beyond it, ``BEYOND_DEGC`` each side [deg/s].
    as_run_max_dps, as_run_rms_dps : tuple of float
        The same over a heat-cool cycle as the firmware runs [deg/s].
    """

    target: str
    axes: tuple[str, ...]
    in_range_max_dps: tuple[float, ...]
    in_range_rms_dps: tuple[float, ...]
    beyond_max_dps: tuple[float, ...]
    beyond_rms_dps: tuple[float, ...]
    as_run_max_dps: tuple[float, ...]
    as_run_rms_dps: tuple[float, ...]

    def lines(self) -> list[str]:
        """The figures in words, one line per axis."""
        return [
            f"{axis}: firmware vs model, largest (RMS) [deg/s]: {self.in_range_max_dps[j]:.2g} "
            f"({self.in_range_rms_dps[j]:.2g}) in range, {self.beyond_max_dps[j]:.2g} ({self.beyond_rms_dps[j]:.2g}) "
            f"up to {BEYOND_DEGC:g} degC beyond it, {self.as_run_max_dps[j]:.2g} ({self.as_run_rms_dps[j]:.2g}) "
            f"through a 1 degC/min heat-cool cycle as it runs"
            for j, axis in enumerate(self.axes)
        ]


def _stats(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    a = a - a.mean(axis=0)
    return np.max(np.abs(a), axis=0), np.sqrt(np.mean(a**2, axis=0))


def firmware_difference(calibration: Calibration, params: dict, target: str, instance: int) -> FirmwareDifference:
    """The firmware's correction against the model's (:class:`FirmwareDifference`); ``target`` ``px4`` or
    ``ardupilot``, ``params`` the exported parameter values.

    Parameters
    ----------
    calibration : Calibration
        The model exported.
    params : dict
        The exported parameters (name to value).
    target : {"px4", "ardupilot"}
        The autopilot.
    instance : int
        The slot the parameters were written for (PX4 0..3, ArduPilot 1..3).
    """
    # the gyro's temperature correction is compared: neither firmware has a g-term, and the accelerometer's
    # calibration is the accelerometer's
    calibration = dataclasses.replace(
        calibration.without("acceleration") if calibration.has_acceleration else calibration,
        accel_axes={},
        accel_triad=None,
    )
    axes = _gyro_axes_with_curve(calibration)
    curves = [calibration.axes[a].temperature for a in axes]
    lo, hi = min(c.t_min_degc for c in curves), max(c.t_max_degc for c in curves)
    cols = [GYRO_AXES.index(a) for a in axes]
    inside = np.linspace(lo, hi, 400)
    beyond = np.concatenate([np.linspace(lo - BEYOND_DEGC, lo, 100), np.linspace(hi, hi + BEYOND_DEGC, 100)])
    # a heat-cool cycle at 1 degC/min through the range, 1 Hz: the model's memory and PX4's steps both show
    ramp = np.concatenate([np.linspace(lo, hi, int(60 * (hi - lo)) + 2), np.linspace(hi, lo, int(60 * (hi - lo)) + 2)])
    time_s = np.arange(ramp.size, dtype=float)

    def firmware(temperature: np.ndarray, time: np.ndarray | None = None) -> np.ndarray:
        if target == "px4":
            out = (
                px4_as_run(params, time, temperature, instance)
                if time is not None
                else px4_gyro_correction_dps(params, temperature, instance)
            )
        else:
            out = ardupilot_gyro_correction_dps(params, temperature, 0.5 * (lo + hi), instance)
        return out[:, cols]

    # static points of the curve (no history): the model without its memory there; the cycle with it
    static = (
        calibration.without("hysteresis", "lag", "rate")
        if any(calibration.axes[a].has_memory for a in axes)
        else calibration
    )
    diffs = [firmware(temps) - predict_error(static, _probe(temps, axes)) for temps in (inside, beyond)]
    diffs.append(firmware(ramp, time_s) - predict_error(calibration, _probe(ramp, axes, time_s)))
    figures = [tuple(float(v) for v in x) for d in diffs for x in _stats(d)]
    return FirmwareDifference(target, axes, *figures)


def _probe(temperature_degc: np.ndarray, axes: tuple, time_s: np.ndarray | None = None) -> Recording:
    """A recording of zero rate on ``axes`` at ``temperature_degc`` [degC] (one sample a second by default) [s]."""
    t = np.arange(temperature_degc.size, dtype=float) if time_s is None else time_s
    return Recording(t, np.zeros((t.size, len(axes))), axes, temperature_degc=temperature_degc, source="<firmware>")


#: the firmwares judged, and the slot each exports by default (PX4 TC_G0, ArduPilot INS_TCAL1)
TARGETS: dict[str, int] = {"px4": 0, "ardupilot": 1}
#: the device ids written when judging a PX4 file: an id chooses the slot, it does not enter the correction
_ANY_DEVICE_ID = 1


def _gyro_axes_with_curve(calibration: Calibration) -> tuple[str, ...]:
    return tuple(a for a in GYRO_AXES if a in calibration.axes and calibration.axes[a].temperature is not None)


def firmware_parameters(calibration: Calibration, target: Autopilot) -> dict[str, float]:
    """The gyro thermal parameters ``gyrocomp export --format target`` writes for ``calibration`` (default slot;
    the left-out terms are not warned about here: :func:`firmware_difference` measures them).

    Parameters
    ----------
    calibration : Calibration
        The model exported.
    target : {"px4", "ardupilot"}
        The autopilot.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DataQualityWarning)
        if target == "px4":
            return px4_parameters(
                calibration, instance=TARGETS["px4"], device_id=_ANY_DEVICE_ID, accel_device_id=_ANY_DEVICE_ID
            ).values
        return ardupilot_parameters(calibration, instance=TARGETS["ardupilot"]).values


def firmware_correction(calibration: Calibration, recording: Recording, target: Autopilot) -> np.ndarray:
    """(n, 3) what the autopilot subtracts from gyro x, y, z [deg/s] at each sample of ``recording`` with the file
    exported from ``calibration``: PX4 as it runs (1 Hz, 1 degC republish), ArduPilot relative to the run's first
    temperature (where its boot-time gyro offset is taken).

    Parameters
    ----------
    calibration : Calibration
        The model exported.
    recording : Recording
        The samples [s, deg/s, degC].
    target : {"px4", "ardupilot"}
        The autopilot.
    """
    params = firmware_parameters(calibration, target)
    temperature = recording.temperature_degc
    if target == "px4":
        return px4_as_run(params, recording.time_s, temperature, TARGETS["px4"])
    return ardupilot_gyro_correction_dps(params, temperature, float(temperature[0]), TARGETS["ardupilot"])


def firmware_corrected_axes(
    calibration: Calibration, recording: Recording, target: Autopilot
) -> Iterator[tuple[str, np.ndarray]]:
    """(axis, output [deg/s]) of each gyro axis of ``recording`` as the autopilot outputs it with the file
    exported from ``calibration`` (:func:`firmware_correction`; an axis without a temperature curve in the model
    is not corrected). Each output is written into one buffer, valid until the next axis is yielded: a day at
    100 Hz is read axis by axis without a copy of the recording.

    Parameters
    ----------
    calibration : Calibration
        The model exported.
    recording : Recording
        The samples [s, deg/s, degC].
    target : {"px4", "ardupilot"}
        The autopilot.
    """
    correction = firmware_correction(calibration, recording, target)
    corrected = _gyro_axes_with_curve(calibration)
    buffer = np.empty(recording.n_samples)
    for j, axis in enumerate(recording.gyro_axes):
        if axis in corrected:
            np.subtract(recording.gyro_dps[:, j], correction[:, GYRO_AXES.index(axis)], out=buffer)
        else:
            buffer[:] = recording.gyro_dps[:, j]
        yield axis, buffer


def firmware_corrected(calibration: Calibration, recording: Recording, target: Autopilot) -> Recording:
    """``recording`` corrected as the autopilot would correct it with the file exported from ``calibration``
    (:func:`firmware_correction`). Only the gyro axes the model has a temperature curve for are corrected
    [deg/s].

    Parameters
    ----------
    calibration : Calibration
        The model exported.
    recording : Recording
        The samples [s, deg/s, degC].
    target : {"px4", "ardupilot"}
        The autopilot.
    """
    gyro = np.empty_like(recording.gyro_dps, dtype=float)
    for j, (_, output) in enumerate(firmware_corrected_axes(calibration, recording, target)):
        gyro[:, j] = output
    return recording.with_gyro(gyro)


def firmware_costs(calibration: Calibration) -> dict[str, FirmwareDifference]:
    """What loading ``calibration`` into each autopilot costs: :func:`firmware_difference` of the PX4 and the
    ArduPilot file export writes, by target; empty when no gyro axis has a temperature curve.

    Parameters
    ----------
    calibration : Calibration
        The model exported.
    """
    if not _gyro_axes_with_curve(calibration):
        return {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TemperatureRangeWarning)  # the model continues past its range: the point
        return {
            target: firmware_difference(calibration, firmware_parameters(calibration, target), target, slot)
            for target, slot in TARGETS.items()
        }


__all__ = [
    "BEYOND_DEGC",
    "FirmwareDifference",
    "TARGETS",
    "ardupilot_gyro_correction_dps",
    "firmware_correction",
    "firmware_corrected",
    "firmware_corrected_axes",
    "firmware_costs",
    "firmware_difference",
    "firmware_parameters",
    "px4_as_run",
    "px4_gyro_correction_dps",
]
