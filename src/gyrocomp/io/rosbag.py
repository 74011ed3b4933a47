"""ROS 1 and ROS 2 bag reader (optional extra ``[ros]``, rosbags).

Reads a ``sensor_msgs/Imu`` topic (rad/s, m/s^2, time from each message's header stamp) and a
``sensor_msgs/Temperature`` topic (degC) matched to it by time. Messages are read one topic at a
time, straight into arrays; a ROS 2 bag is its folder (with ``metadata.yaml``) or a file in it.
"""

from __future__ import annotations

import contextlib
import re
import warnings
from pathlib import Path

import numpy as np

from ..errors import DataQualityWarning, InputError, printable
from ..recording import Recording
from ..units import unit_factor
from .common import ProgressCallback, ReadOptions, keep_matched, log_recording, match_by_time, order_by_time, require
from .readers import Reader, register_reader

IMU_TYPE = "sensor_msgs/msg/Imu"
TEMPERATURE_TYPE = "sensor_msgs/msg/Temperature"
_RAD = unit_factor("gyro", "rad/s")
_MS2 = unit_factor("accel", "m/s2")
#: a message type name as ROS spells them (package/msg/Name): rosbags turns the bag's type names into Python code,
#: so anything else is refused before it gets there
_MSGTYPE = re.compile(r"[A-Za-z][A-Za-z0-9_]*(/[A-Za-z][A-Za-z0-9_]*){1,2}")


def bag_path(path: Path) -> Path:
    """The path rosbags opens: a ROS 1 ``.bag`` file, or a ROS 2 bag folder (given a file inside it too)."""
    if path.is_file() and path.suffix.lower() in (".db3", ".mcap") and (path.parent / "metadata.yaml").exists():
        return path.parent
    return path


def _only_its_own_files(path: Path, bag: Path) -> None:
    """Refuse a ROS 2 bag folder holding a link to a file outside it: a bag is read from its own files only."""
    if not bag.is_dir():
        return
    root = bag.resolve()
    for entry in sorted(bag.iterdir()):
        if entry.is_symlink() and root not in entry.resolve().parents:
            raise InputError(f"{path}: {entry.name} links to {entry.resolve()}, outside the bag folder; gyrocomp reads "
                             "only the bag's own files (copy the file into the folder)")


def _check_types(path: Path, readers: list) -> None:
    """Open each underlying reader once to refuse message type names that are not ROS names, before rosbags
    makes Python code of them."""
    for reader in readers:
        with reader:
            for connection in reader.connections:
                if not _MSGTYPE.fullmatch(str(connection.msgtype)):
                    raise InputError(f"{path}: topic {connection.topic!r} has the message type "
                                     f"{str(connection.msgtype)[:80]!r}, not a ROS type name; refused")


def _topics_of(connections: list, msgtype: str) -> list[str]:
    """The topics of a message type that hold messages, sorted."""
    return sorted({c.topic for c in connections if c.msgtype == msgtype and c.msgcount > 0})


def _open(path: Path):
    """An open rosbags reader of the bag at ``path`` (its message type names checked first); anything that is not
    a readable bag is refused in one line."""
    highlevel = require("rosbags.highlevel", "ros", "reading ROS bags")
    if not path.exists():
        raise InputError(f"{path}: no such file or folder")
    bag = bag_path(path)
    _only_its_own_files(path, bag)
    try:
        reader = highlevel.AnyReader([bag])
        _check_types(path, reader.readers)
        reader.open()
    except InputError:
        raise
    except Exception as exc:  # rosbags raises its own error types for files that are not bags
        raise InputError(f"{path}: not a readable ROS bag ({type(exc).__name__}: {exc})") from None
    return reader


def _imu_topic_asked(path: Path, connections: list, options: ReadOptions) -> str | None:
    """The IMU topic the options name: ``imu_topic``, or the ``instance``-th IMU topic in name order (a bag's
    sensors as the autopilots' instances), or None (the only one)."""
    if options.imu_topic is not None or options.instance is None:
        return options.imu_topic
    topics = _topics_of(connections, IMU_TYPE)
    if not 0 <= options.instance < len(topics):
        raise InputError(f"{path}: instance={options.instance}: the bag has {len(topics)} {IMU_TYPE} topic(s) "
                         f"({', '.join(topics) or 'none'}), instances 0 to {len(topics) - 1}")
    return topics[options.instance]


def rosbag_instances(path) -> tuple[int, ...]:
    """The sensor instances of a bag: one per ``sensor_msgs/Imu`` topic with messages, in topic-name order."""
    reader = _open(Path(path))
    try:
        return tuple(range(len(_topics_of(list(reader.connections), IMU_TYPE)))) or (0,)
    finally:
        reader.close()


def _topic(path: Path, connections: list, msgtype: str, asked: str | None, option: str):
    """The connections of the topic asked for, or of the only topic of that type."""
    of_type = _topics_of(connections, msgtype)
    if asked is not None:
        chosen = [c for c in connections if c.topic == asked]
        if not chosen:
            present = "; ".join(f"its {kind} topics are {', '.join(_topics_of(connections, kind)) or 'none'}"
                                for kind in (IMU_TYPE, TEMPERATURE_TYPE))
            raise InputError(f"{path}: {option}={asked}: no such topic in the bag; {present}")
        if chosen[0].msgtype != msgtype:
            raise InputError(f"{path}: {option}={asked}: the topic has type {chosen[0].msgtype}, not {msgtype}")
        if not sum(c.msgcount for c in chosen):
            raise InputError(f"{path}: {option}={asked}: the topic has no messages")
        return chosen
    if not of_type:
        return []
    if len(of_type) > 1:
        also = " or instance= (their index, from 0, in this order)" if msgtype == IMU_TYPE else ""
        raise InputError(f"{path}: {len(of_type)} {msgtype} topics ({', '.join(of_type)}); choose one with "
                         f"{option}={also}")
    return [c for c in connections if c.topic == of_type[0]]


def _stamp_s(header) -> float:
    stamp = header.stamp
    return stamp.sec + stamp.nanosec * 1e-9


@contextlib.contextmanager
def _damaged(path: Path, topic: str):
    """Any error rosbags raises on the messages of ``topic`` (a damaged record, a length past the file, a message
    that does not deserialize) as one line naming the bag and the topic."""
    try:
        yield
    except InputError:
        raise
    except Exception as exc:  # rosbags' own errors, and what a damaged record makes its parsers raise
        raise InputError(f"{path}: damaged ROS bag: topic {topic}: {type(exc).__name__}: "
                         f"{printable(str(exc))[:160]}") from None


def _read_all(path: Path, counted: int, read: int, topic: str) -> None:
    """Warn when fewer messages were read than the bag's index counts (a damaged or cut-short bag)."""
    if read < counted:
        warnings.warn(f"{path}: topic {topic}: the bag's index counts {counted} messages, {read} were read; the "
                      "rest is damaged or missing", DataQualityWarning, stacklevel=3)


def _imu_samples(path: Path, reader, imu: list, progress: ProgressCallback | None, total: int):
    """(time [s], gyro [deg/s], accel [g]) of every message on the IMU topic, in time order."""
    n = sum(c.msgcount for c in imu)
    time_s, gyro, accel = np.empty(n), np.empty((n, 3)), np.empty((n, 3))
    i = 0
    with _damaged(path, imu[0].topic):
        for connection, _, raw in reader.messages(connections=imu):
            if i == n:
                raise InputError(f"{path}: damaged ROS bag: topic {imu[0].topic}: more messages than the bag's "
                                 f"index counts ({n})")
            msg = reader.deserialize(raw, connection.msgtype)
            time_s[i] = _stamp_s(msg.header)
            w, a = msg.angular_velocity, msg.linear_acceleration
            gyro[i] = (w.x, w.y, w.z)
            accel[i] = (a.x, a.y, a.z)
            i += 1
            if progress and i % 20000 == 0:
                progress(i / total)
    _read_all(path, n, i, imu[0].topic)
    return order_by_time(str(path), time_s[:i], gyro[:i] * _RAD, accel[:i] * _MS2)


def _temperature_samples(path: Path, reader, thermo: list):
    """(time [s], temperature [degC]) of every message on the temperature topic, in time order."""
    t_time, t_value = [], []
    with _damaged(path, thermo[0].topic):
        for connection, _, raw in reader.messages(connections=thermo):
            msg = reader.deserialize(raw, connection.msgtype)
            t_time.append(_stamp_s(msg.header))
            t_value.append(msg.temperature)
    _read_all(path, sum(c.msgcount for c in thermo), len(t_time), thermo[0].topic)
    return order_by_time(str(path), np.array(t_time), np.array(t_value, dtype=float))


def read_rosbag(path, options: ReadOptions | None = None, progress: ProgressCallback | None = None) -> Recording:
    """Read a ROS 1 or ROS 2 bag into a :class:`Recording` [s, deg/s, g, degC].

    Parameters
    ----------
    path : path
        A ROS 1 ``.bag`` file or a ROS 2 bag folder.
    options : ReadOptions, optional
        ``imu_topic`` and ``temperature_topic`` (default: the only topic of each type).
    progress : callable, optional
        Called with the fraction done.
    """
    options = options or ReadOptions()
    path = Path(path)
    reader = _open(path)
    try:
        connections = list(reader.connections)
        imu = _topic(path, connections, IMU_TYPE, _imu_topic_asked(path, connections, options), "imu_topic")
        if not imu:
            topics = ", ".join(sorted(f"{c.topic} ({c.msgtype})" for c in connections)) or "none"
            raise InputError(f"{path}: no {IMU_TYPE} topic in the bag; its topics are {topics}")
        thermo = _topic(path, connections, TEMPERATURE_TYPE, options.temperature_topic, "temperature_topic")
        total = max(1, sum(c.msgcount for c in imu + thermo))
        time_s, gyro, accel = _imu_samples(path, reader, imu, progress, total)
        temperature = None
        if thermo:
            t_time, t_value = _temperature_samples(path, reader, thermo)
            what = f"temperature topic {thermo[0].topic}"
            temperature, ok = match_by_time(str(path), what, time_s, t_time, t_value)
            keep = keep_matched(str(path), what, ok)
            time_s, gyro, accel, temperature = time_s[keep], gyro[keep], accel[keep], temperature[keep]
    finally:
        reader.close()
    if temperature is None:
        warnings.warn(f"{path}: no {TEMPERATURE_TYPE} topic; the recording has no temperature "
                      "(only noise analysis works without it)", DataQualityWarning, stacklevel=2)
    if progress:
        progress(1.0)
    return log_recording(path, options, time_s, gyro, accel, temperature,
                         {"path": str(path), "format": "rosbag", "imu_topic": imu[0].topic,
                          "temperature_topic": thermo[0].topic if thermo else None})


register_reader(Reader("rosbag", "ROS 1 bag, ROS 2 bag folder or its .db3/.mcap, extra [ros]", read_rosbag,
                       suffixes=(".bag", ".db3", ".mcap"), magic=(b"#ROSBAG", b"\x89MCAP"), aliases=("bag", "ros"),
                       folder_marker="metadata.yaml", instances=rosbag_instances))
