"""A ROS bag compensated into a bag of the same kind (``gyrocomp apply MODEL in.bag -o out.bag``; extra ``[ros]``).

Every connection, message and time stamp is copied unchanged except the ``sensor_msgs/Imu`` topic the model is
applied to: its ``angular_velocity`` (and ``linear_acceleration`` when the model has accelerometer terms) is
replaced by the compensated value, exactly what :func:`gyrocomp.apply` gives on the recording the bag reads as
(the temperature from the matched ``sensor_msgs/Temperature`` topic, as in reading). A message whose header stamp
repeats an earlier one (which reading leaves out) gets the same correction as that one; a message the recording
does not hold (outside the temperature topic's span, or dropped as non-finite) is copied as it is, and a warning
says how many. The covariance fields are written from a noise model when one is given, else left as they were.
A ROS 1 ``.bag`` gives a ``.bag``; a ROS 2 bag folder gives a folder in the same storage (sqlite3 or MCAP). The
output is written beside its final name and moved there when complete; the input is never touched.

This version reads the IMU topic into memory (as reading does) and copies the bag message by message.
"""

from __future__ import annotations

import dataclasses
import os
import re
import shutil
import tempfile
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..calibration import Calibration
from ..calibration.compensate import apply
from ..errors import DataQualityWarning, InputError
from ..io import ReadOptions
from ..io.atomic import refuse_link
from ..io.common import require
from ..io.rosbag import IMU_TYPE, bag_path, read_rosbag
from ..measures.noise_model import noise_file_densities, per_sample_covariance
from ..units import unit_factor

_RAD = unit_factor("gyro", "rad/s")  # deg/s per rad/s
_MS2 = unit_factor("accel", "m/s2")  # g per m/s^2


@dataclass(frozen=True)
class AppliedBag:
    """What :func:`apply_bag` wrote: the output, the topic compensated, the messages compensated and copied as
    they were, whether the accelerations were compensated too, and the covariance fields written (none: left as
    they were)."""

    path: Path
    imu_topic: str
    compensated: int
    unchanged: int
    accel: bool
    covariances: tuple[str, ...] = ()


def _stamp_s(header) -> float:
    return header.stamp.sec + header.stamp.nanosec * 1e-9


def _writer(bag: Path, target: Path, connections):
    """A rosbags writer of the input's kind at ``target``, with every connection of the input, by id."""
    if bag.is_dir():
        rosbag2 = require("rosbags.rosbag2", "ros", "writing ROS 2 bags")
        storage = re.search(r"storage_identifier:\s*['\"]?(\w+)", (bag / "metadata.yaml").read_text(errors="replace"))
        plugin = rosbag2.StoragePlugin.MCAP if storage and storage.group(1) == "mcap" else rosbag2.StoragePlugin.SQLITE3
        writer = rosbag2.Writer(target, version=9, storage_plugin=plugin)
        writer.open()
        out = {c.id: writer.add_connection(c.topic, c.msgtype, msgdef=c.msgdef.data, rihs01=c.digest,
                                           serialization_format=c.ext.serialization_format,
                                           offered_qos_profiles=c.ext.offered_qos_profiles) for c in connections}
    else:
        rosbag1 = require("rosbags.rosbag1", "ros", "writing ROS 1 bags")
        writer = rosbag1.Writer(target)
        writer.open()
        out = {c.id: writer.add_connection(c.topic, c.msgtype, msgdef=c.msgdef.data, md5sum=c.digest,
                                           callerid=c.ext.callerid, latching=c.ext.latching) for c in connections}
    return writer, out


def apply_bag(calibration: Calibration, path, output, *, options: ReadOptions | None = None,
              noise=None) -> AppliedBag:
    """Compensate the IMU topic of a ROS bag into a bag of the same kind (see the module).

    Parameters
    ----------
    calibration : Calibration
        The model.
    path : path
        A ROS 1 ``.bag`` file or a ROS 2 bag folder.
    output : path
        The bag to write: a ``.bag`` file for a ROS 1 bag, a folder for a ROS 2 bag (replaced when it exists).
    options : ReadOptions, optional
        ``imu_topic`` and ``temperature_topic`` (default: the only topic of each type).
    noise : path, optional
        A noise model (``gyrocomp noise --export json``): the compensated messages' ``angular_velocity_covariance``
        (and ``linear_acceleration_covariance`` when it models the accelerometer) are written from it, the
        variance of one sample at the bag's rate (N^2 rate) [rad^2/s^2, m^2/s^4]; without one they are left as
        they were.

    Returns
    -------
    AppliedBag
    """
    options = options or ReadOptions()
    path, output = Path(path), Path(output)
    bag = bag_path(path)
    if bag.is_dir() == (output.suffix.lower() == ".bag"):
        kind = "a folder (a ROS 2 bag)" if bag.is_dir() else "a .bag file (a ROS 1 bag)"
        raise InputError(f"output: {output}: a compensated bag is written as the input's kind: {kind}")
    refuse_link(output)
    if output.is_dir() and not (output / "metadata.yaml").is_file():
        raise InputError(f"output: {output}: is a folder that is not a ROS 2 bag; name a new path (gyrocomp replaces "
                         "only a bag)")
    covariance_of = _covariances(noise) if noise is not None else {}
    recording = read_rosbag(path, options)
    compensated = apply(calibration, recording)
    covariances = {field: make(recording.rate_hz) for field, make in covariance_of.items()}
    with_accel = recording.accel_g is not None and not np.array_equal(compensated.accel_g, recording.accel_g)
    topic = recording.metadata["imu_topic"]
    counts = {"compensated": 0, "unchanged": 0}
    _write_bag(bag, output, topic, (recording, compensated, with_accel, covariances), counts)
    if counts["unchanged"]:
        warnings.warn(f"{path}: {counts['unchanged']} message(s) of {topic} are not in the recording the bag reads as "
                      "(outside the temperature topic's span, or not finite) and were copied uncompensated",
                      DataQualityWarning, stacklevel=2)
    return AppliedBag(output, topic, counts["compensated"], counts["unchanged"], with_accel, tuple(covariances))


def _covariances(noise) -> dict:
    """The covariance fields a noise model's JSON file gives, each as a function of the bag's rate [Hz]."""
    gyro, accel = noise_file_densities(noise)
    out = {}
    if gyro is not None:
        out["angular_velocity_covariance"] = lambda rate: per_sample_covariance(gyro / _RAD, rate)
    if accel is not None:
        out["linear_acceleration_covariance"] = lambda rate: per_sample_covariance(accel / _MS2, rate)
    return out


def _write_bag(bag: Path, output: Path, topic: str, result: tuple, counts: dict) -> None:
    """The copy written beside ``output`` in a temporary folder, moved into place when complete."""
    highlevel = require("rosbags.highlevel", "ros", "reading ROS bags")
    parent = output.parent if str(output.parent) else Path(".")
    tmp = Path(tempfile.mkdtemp(prefix=f".{output.name}.", dir=parent))
    target = tmp / (output.name if output.suffix else "bag")
    try:
        with highlevel.AnyReader([bag]) as reader:
            writer, connections = _writer(bag, target, reader.connections)
            try:
                _copy(reader, writer, connections, topic, result, counts)
            finally:
                writer.close()
        _move_into_place(target, output)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _copy(reader, writer, connections: dict, topic: str, result: tuple, counts: dict) -> None:
    """Every message into ``writer``: the IMU topic's compensated (``result``: the recording, its compensation,
    whether the accelerations are compensated, the covariance fields to write), the rest as its bytes."""
    recording, compensated, with_accel, covariances = result
    time_s = recording.time_s
    gyro_rad = compensated.gyro_dps / _RAD
    correction = (recording.gyro_dps - compensated.gyro_dps) / _RAD
    accel_ms2 = compensated.accel_g / _MS2 if with_accel else None
    accel_correction = (recording.accel_g - compensated.accel_g) / _MS2 if with_accel else None
    axes = [recording.gyro_axes.index(a) for a in ("gyro_x", "gyro_y", "gyro_z")]
    seen: set[int] = set()
    store = reader.typestore
    serialize = store.serialize_cdr if reader.is2 else store.serialize_ros1
    for connection, timestamp, raw in reader.messages():
        out = connections[connection.id]
        if connection.topic != topic or connection.msgtype != IMU_TYPE:
            writer.write(out, timestamp, raw)
            continue
        msg = reader.deserialize(raw, connection.msgtype)
        stamp = _stamp_s(msg.header)
        k = int(np.searchsorted(time_s, stamp))
        if k >= time_s.size or time_s[k] != stamp:
            counts["unchanged"] += 1
            writer.write(out, timestamp, raw)
            continue
        first = k not in seen  # a repeated stamp gets the same correction as the message reading kept
        seen.add(k)
        w = msg.angular_velocity
        values = gyro_rad[k, axes] if first else np.array([w.x, w.y, w.z]) - correction[k, axes]
        changes = {"angular_velocity": dataclasses.replace(w, x=float(values[0]), y=float(values[1]),
                                                           z=float(values[2]))}
        if with_accel:
            a = msg.linear_acceleration
            acc = accel_ms2[k] if first else np.array([a.x, a.y, a.z]) - accel_correction[k]
            changes["linear_acceleration"] = dataclasses.replace(a, x=float(acc[0]), y=float(acc[1]), z=float(acc[2]))
        for field, values in covariances.items():
            changes[field] = np.asarray(values, dtype=np.float64)
        writer.write(out, timestamp, serialize(dataclasses.replace(msg, **changes), connection.msgtype))
        counts["compensated"] += 1


def _move_into_place(source: Path, output: Path) -> None:
    """``source`` (a file or a folder) to ``output``: a file replaces it in one step; a folder replaces an older
    folder by moving that aside first, then removing it."""
    if source.is_file() or not output.exists():
        os.replace(source, output)
        return
    aside = output.with_name(f".{output.name}.old")
    os.replace(output, aside)
    os.replace(source, output)
    shutil.rmtree(aside, ignore_errors=True)


__all__ = ["AppliedBag", "apply_bag"]
