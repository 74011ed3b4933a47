"""What a reader is told: the options every reader takes (:class:`ReadOptions`) and the parsing of their text."""

from __future__ import annotations


import math
from collections.abc import Callable
from dataclasses import dataclass, field


from ..errors import InputError
from ..option_spelling import Spelling, spelled
from .layout import TableLayout


#: ``progress(fraction_done)``, fraction in [0, 1]; readers call it now and then on long files
ProgressCallback = Callable[[float], None]


def parse_instance(text: str) -> int | str:
    """``--instance``'s text: a whole number >= 0, or ``all`` (every instance: ``gyrocomp fit`` alone takes it)."""
    if text.strip().lower() == "all":
        return "all"
    return _whole_number(text, "instance")


def _whole_number(text: str, name: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise InputError(f"{name}: {text!r}: give a whole number >= 0") from None
    if value < 0:
        raise InputError(f"{name}: {value}: give a whole number >= 0")
    return value


def parse_time_range(text: str) -> tuple[float | None, float | None]:
    """``--time A:B`` -> (A, B) [s from the file's first sample]; an empty side is open."""
    parts = text.split(":")
    try:
        if len(parts) != 2:
            raise ValueError
        bounds = tuple(None if p.strip() == "" else float(p) for p in parts)
    except ValueError:
        raise InputError(
            f"time_range_s: {text!r}: give A:B in seconds from the file's start (A: or :B for an open end)"
        ) from None
    if any(b is not None and not math.isfinite(b) for b in bounds) or bounds == (None, None):
        raise InputError(f"time_range_s: {text!r}: give finite seconds on at least one side")
    return bounds


@dataclass(frozen=True)
class ReadOptions:
    """What to read from a file, beyond its format. Each field is an option of every command that reads data,
    spelled on the command line as its metadata says (:mod:`gyrocomp.option_spelling`).

    Parameters
    ----------
    layout : TableLayout
        Column (or dataset) mapping and units, for tables and HDF5/NetCDF files.
    drop_nonfinite : bool
        Drop rows with NaN or infinite values instead of refusing the file.
    instance : int, optional
        Sensor instance in autopilot logs (PX4 ``multi_id``, ArduPilot ``I`` / IMU2 / IMU3; default 0), or in a ROS
        bag the index of its ``sensor_msgs/Imu`` topic in name order.
    device_id : int, optional
        PX4 device id of the gyro to read (instead of ``instance``).
    imu_topic, temperature_topic : str, optional
        ROS topics of the ``sensor_msgs/Imu`` and ``sensor_msgs/Temperature`` messages
        (default: the only topic of that type in the bag).
    record : str, optional
        ArduPilot DataFlash record to read: ``"IMU"`` (default) or ``"TCLR"`` (the onboard
        temperature-learning records).
    channels : tuple of str, optional
        Tables: read only these channels' columns (``time`` always), e.g. ``("gyro_x", "gyro_z")``; a command
        that uses three of eight columns then neither converts nor holds the others. Default: every channel.
    time_range_s : (float or None, float or None), optional
        Keep only the samples from A to B seconds after the file's first one, [A, B) [s]; None for an open end.
    """

    layout: TableLayout = field(default_factory=TableLayout)
    drop_nonfinite: bool = spelled(
        Spelling(
            "--drop-nan", "Drop rows with empty/NaN values (says how many) instead of refusing the file.", switch=True
        ),
        default=False,
    )
    instance: int | None = spelled(
        Spelling(
            "--instance",
            "Sensor instance in PX4/ArduPilot logs (uORB multi_id, IMU number from 0; default 0) or ROS "
            "bags (the IMU topic's index in name order); fit: all fits every instance, one model file each.",
            metavar="N",
            parse=parse_instance,
        ),
        default=None,
    )
    device_id: int | None = spelled(
        Spelling(
            "--device-id",
            "PX4 device id of the gyro to read.",
            metavar="ID",
            parse=lambda text: _whole_number(text, "device_id"),
        ),
        default=None,
    )
    imu_topic: str | None = spelled(
        Spelling("--imu-topic", "ROS bag: the sensor_msgs/Imu topic (default: the only one)."), default=None
    )
    temperature_topic: str | None = spelled(
        Spelling("--temperature-topic", "ROS bag: the sensor_msgs/Temperature topic (default: the only one)."),
        default=None,
    )
    record: str | None = spelled(
        Spelling("--record", "ArduPilot log: IMU (default) or TCLR (onboard learning records)."), default=None
    )
    channels: tuple[str, ...] | None = None
    time_range_s: tuple[float | None, float | None] | None = spelled(
        Spelling(
            "--time",
            "Only the samples from A to B seconds after the file's first ([A, B); A: or :B open).",
            metavar="A:B",
            parse=parse_time_range,
        ),
        default=None,
    )

    def __post_init__(self) -> None:
        if self.instance == "all":
            raise InputError("instance: all is for gyrocomp fit (one model per instance); give a number here")
        for name in ("instance", "device_id"):
            value = getattr(self, name)
            if value is not None and (isinstance(value, bool) or not isinstance(value, int) or value < 0):
                raise InputError(f"{name}: {value!r}: give a whole number >= 0")
