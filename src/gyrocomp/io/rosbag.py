"""ROS 1 and ROS 2 bag reader (optional extra ``[ros]``, rosbags).

Reads a ``sensor_msgs/Imu`` topic (rad/s, m/s^2, time from each message's header stamp) and a
``sensor_msgs/Temperature`` topic (degC) matched to it by time. Messages are read one topic at a
time, the IMU's decoded a batch at a time (:mod:`gyrocomp.io.ros_imu`); a ROS 1 bag's and an MCAP file's chunk by
chunk as arrays (:mod:`gyrocomp.io.rosbag1_chunks`, :mod:`gyrocomp.io.mcap_chunks`), a ROS 2 sqlite3 bag's message
by message through rosbags; a ROS 2 bag is its folder (with
``metadata.yaml``) or a file in it. :class:`BagStream` reads the IMU topic in chunks, in memory bounded by the
chunk whatever the bag's length (``allan``, ``apply``, ``evaluate`` and ``convert`` read bags so).
"""

from __future__ import annotations

import contextlib
import itertools
import re
import warnings
import weakref
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pyarrow as pa

from ..errors import DataQualityWarning, InputError, TimeOrderWarning, foreign_message, user_stacklevel
from ..recording import ACCEL_AXES, GYRO_AXES, Recording
from ..units import unit_factor
from .log_samples import (
    keep_matched,
    left_out,
    log_recording,
    match_by_time,
    none_matched,
    order_by_time,
    time_order_warning,
)
from .foreign_libraries import require
from .read_options import ProgressCallback, ReadOptions
from .layout import TIME_COLUMN, TableLayout
from .mcap_chunks import mcap_arrays
from .readers import Reader, register_reader
from .stamps import stamp_s
from .ros_imu import ANGULAR_VELOCITY, LINEAR_ACCELERATION, ImuBatch, imu_batch, imu_fields, temperature_fields
from .rosbag1_chunks import chunked_reader1
from .stream import CHUNK_ROWS, NotStreamable
from .tables import recording_table, rows_dropped

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


#: what a bag of each kind is, for messages
KIND_WORDS = {
    "ros1": "a .bag file (a ROS 1 bag)",
    "ros2": "a folder (a ROS 2 bag)",
    "mcap": "a .mcap file (an MCAP bag without its folder)",
}


def bag_kind(path: Path) -> str:
    """``ros1`` (a ``.bag`` file), ``ros2`` (a ROS 2 bag folder) or ``mcap`` (a bare ``.mcap`` file) for the path
    rosbags opens (:func:`gyrocomp.io.rosbag.bag_path`), or for an output by its name (no suffix: a folder)."""
    if path.is_dir():
        return "ros2"
    suffix = path.suffix.lower()
    return "mcap" if suffix == ".mcap" else "ros1" if suffix == ".bag" or path.is_file() else "ros2"


def _only_its_own_files(path: Path, bag: Path) -> None:
    """Refuse a ROS 2 bag folder holding a link to a file outside it: a bag is read from its own files only."""
    if not bag.is_dir():
        return
    root = bag.resolve()
    for entry in sorted(bag.iterdir()):
        if entry.is_symlink() and root not in entry.resolve().parents:
            raise InputError(
                f"{path}: {entry.name} links to {entry.resolve()}, outside the bag folder; gyrocomp reads "
                "only the bag's own files (copy the file into the folder)"
            )


def _check_types(path: Path, readers: list) -> None:
    """Refuse message type names that are not ROS names, before rosbags makes Python code of them: the topics of a
    ROS 2 bag folder's ``metadata.yaml`` (where rosbags' reader of a folder takes its connections from), read
    without opening its storage (rosbags' sqlite3 storage counts every topic's messages when it opens: seconds
    for an hour at 1 kHz); any other reader's connections, opening it once."""
    for reader in readers:
        named = _folder_topics(reader)
        if named is None:
            with reader:
                named = [(connection.topic, connection.msgtype) for connection in reader.connections]
        for topic, msgtype in named:
            if not _MSGTYPE.fullmatch(str(msgtype)):
                raise InputError(
                    f"{path}: topic {topic!r} has the message type {str(msgtype)[:80]!r}, not a ROS type name; refused"
                )


def _folder_topics(reader) -> list[tuple] | None:
    """(topic, message type) of each topic the ``metadata.yaml`` of the ROS 2 bag folder ``reader`` (rosbags'
    reader, not open) reads names, as rosbags' reader of a folder reads them; None for any other reader, or a
    metadata file that does not read so (rosbags' reader then says what is wrong when it opens)."""
    directory = require("rosbags.rosbag2.reader", "ros", "reading ROS 2 bags").DirectoryReader
    if not isinstance(getattr(reader, "storage", None), directory):
        return None
    yaml = require("ruamel.yaml", "ros", "reading ROS 2 bags")
    try:
        info = yaml.YAML(typ="safe").load((reader.path / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
        return [(t["topic_metadata"]["name"], t["topic_metadata"]["type"]) for t in info["topics_with_message_count"]]
    except Exception:  # noqa: BLE001 - any metadata rosbags cannot read: its reader says so
        return None


def _topics_of(connections: list, msgtype: str) -> list[str]:
    """The topics of a message type that hold messages, sorted."""
    return sorted({c.topic for c in connections if c.msgtype == msgtype and c.msgcount > 0})


def any_reader(bag: Path, highlevel=None):
    """rosbags' :class:`~rosbags.highlevel.AnyReader` of a bag (not opened), a ROS 1 bag read chunk by chunk
    (:mod:`gyrocomp.io.rosbag1_chunks`: without an index entry of every message in memory)."""
    highlevel = highlevel or require("rosbags.highlevel", "ros", "reading ROS bags")
    reader = highlevel.AnyReader([bag])
    if not reader.is2:
        reader.readers = [chunked_reader1()(bag)]
    return reader


def _open(path: Path):
    """An open rosbags reader of the bag at ``path`` (its message type names checked first); anything that is not
    a readable bag is refused in one line."""
    highlevel = require("rosbags.highlevel", "ros", "reading ROS bags")
    if not path.exists():
        raise InputError(f"{path}: no such file or folder")
    bag = bag_path(path)
    _only_its_own_files(path, bag)
    try:
        reader = any_reader(bag, highlevel)
        _check_types(path, reader.readers)
        reader.open()
    except InputError:
        raise
    except Exception as exc:  # rosbags raises its own error types for files that are not bags
        raise InputError(f"{path}: not a readable ROS bag ({foreign_message(exc)})") from None
    return reader


def _imu_topic_asked(path: Path, connections: list, options: ReadOptions) -> str | None:
    """The IMU topic the options name: ``imu_topic``, or the ``instance``-th IMU topic in name order (a bag's
    sensors as the autopilots' instances), or None (the only one)."""
    if options.imu_topic is not None or options.instance is None:
        return options.imu_topic
    topics = _topics_of(connections, IMU_TYPE)
    if not 0 <= options.instance < len(topics):
        raise InputError(
            f"{path}: instance={options.instance}: the bag has {len(topics)} {IMU_TYPE} topic(s) "
            f"({', '.join(topics) or 'none'}), instances 0 to {len(topics) - 1}"
        )
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
            present = "; ".join(
                f"its {kind} topics are {', '.join(_topics_of(connections, kind)) or 'none'}"
                for kind in (IMU_TYPE, TEMPERATURE_TYPE)
            )
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
        raise InputError(
            f"{path}: {len(of_type)} {msgtype} topics ({', '.join(of_type)}); choose one with {option}={also}"
        )
    return [c for c in connections if c.topic == of_type[0]]


def header_stamp_s(header) -> float:
    """A message header's stamp [s]: sec + nanosec 1e-9."""
    stamp = header.stamp
    return float(stamp_s(stamp.sec, stamp.nanosec))


@contextlib.contextmanager
def damaged_bag(path: Path, topic: str):
    """Any error rosbags raises on the messages of ``topic`` (a damaged record, a length past the file, a message
    that does not deserialize) as one line naming the bag and the topic (:class:`NotStreamable` passes: the caller
    reads the bag whole; so does an OSError, the system's: a full disk writing an output, say)."""
    try:
        yield
    except (InputError, NotStreamable, OSError):
        raise
    except Exception as exc:  # rosbags' own errors, and what a damaged record makes its parsers raise
        raise InputError(f"{path}: damaged ROS bag: topic {topic}: {foreign_message(exc)}") from None


def _read_all(path: Path, counted: int, read: int, topic: str) -> None:
    """Warn when fewer messages were read than the bag's index counts (a damaged or cut-short bag)."""
    if read < counted:
        warnings.warn(
            f"{path}: topic {topic}: the bag's index counts {counted} messages, {read} were read; the "
            "rest is damaged or missing",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )


#: IMU messages decoded at once (about 20 MB of messages)
DECODE_BATCH = 65536


def decoded_imu(reader, msgtype: str, raws: list) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(stamp [s], angular velocity [rad/s] (n, 3), linear acceleration [m/s^2] (n, 3)) of serialized IMU
    messages: a batch of one layout at once, any other message by message through rosbags."""
    batch = imu_batch(raws, cdr=reader.is2)
    if batch is not None:
        return _batch_values(batch, reader.is2)
    time_s, gyro, accel = np.empty(len(raws)), np.empty((len(raws), 3)), np.empty((len(raws), 3))
    for i, raw in enumerate(raws):
        msg = reader.deserialize(raw, msgtype)
        time_s[i] = header_stamp_s(msg.header)
        w, a = msg.angular_velocity, msg.linear_acceleration
        gyro[i] = (w.x, w.y, w.z)
        accel[i] = (a.x, a.y, a.z)
    return time_s, gyro, accel


def _batch_values(batch: ImuBatch, cdr: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A batch's stamps [s], angular velocities [rad/s] and linear accelerations [m/s^2]."""
    values = batch.values
    return (
        batch.stamp_s(cdr=cdr),
        values[:, ANGULAR_VELOCITY : ANGULAR_VELOCITY + 3],
        values[:, LINEAR_ACCELERATION : LINEAR_ACCELERATION + 3],
    )


def message_arrays(reader, connections: list):
    """The messages of ``connections`` chunk by chunk as arrays (:class:`~gyrocomp.io.rosbag1_chunks.ChunkArrays`,
    no Python object per message), in the order rosbags yields them: a ROS 1 bag's
    (:meth:`ChunkedReader1.message_arrays`) or one MCAP file's (:func:`~gyrocomp.io.mcap_chunks.mcap_arrays`); None
    for any other bag (read message by message through rosbags)."""
    readers = getattr(reader, "readers", ())
    arrays = getattr(readers[0], "message_arrays", None) if len(readers) == 1 else None
    return arrays(connections=connections) if arrays is not None else mcap_arrays(reader, connections)


def _decoded_groups(reader, imu: list, size: int):
    """The IMU topic's messages as they lie in the bag, decoded a group at a time [s, rad/s, m/s^2]: a ROS 1 bag's
    or an MCAP file's a chunk at a time from the chunk's bytes (:func:`message_arrays`), any other bag's ``size``
    messages at a time as rosbags yields them."""
    chunks = message_arrays(reader, imu)
    if chunks is None:
        raws = []
        for _, _, raw in reader.messages(connections=imu):
            raws.append(raw)
            if len(raws) == size:
                yield decoded_imu(reader, imu[0].msgtype, raws)
                raws = []
        if raws:
            yield decoded_imu(reader, imu[0].msgtype, raws)
        return
    for found in chunks:
        chunk, data_at, data_length = found.data, found.data_at, found.data_length
        if data_length.size and np.all(data_length == data_length[0]):
            fields = imu_fields(chunk, data_at, int(data_length[0]), cdr=reader.is2)
            if fields is not None:
                yield fields.stamp_s, fields.angular_velocity, fields.linear_acceleration
                continue
        if data_length.size:
            yield decoded_imu(reader, imu[0].msgtype, _raws(found))


def _raws(found) -> list[bytes]:
    """The serialized messages of a chunk's arrays."""
    return [found.data[at : at + n].tobytes() for at, n in zip(found.data_at.tolist(), found.data_length.tolist())]


def _imu_batches(path: Path, reader, imu: list, size: int, progress: ProgressCallback | None = None):
    """The IMU topic's messages as they lie in the bag, ``size`` at a time, decoded (:func:`decoded_imu`) [s, rad/s,
    m/s^2]; a damaged bag or one holding more messages than its index counts is one line naming the topic."""
    n = sum(c.msgcount for c in imu)
    pending, held, read = [], 0, 0
    with damaged_bag(path, imu[0].topic):
        for group in _decoded_groups(reader, imu, size):
            read += group[0].size
            if read > n:
                raise InputError(
                    f"{path}: damaged ROS bag: topic {imu[0].topic}: more messages than the bag's index counts ({n})"
                )
            pending.append(group)
            held += group[0].size
            while held >= size:  # batches of ``size`` whatever the groups' sizes: as a message-by-message reading
                joined = pending[0] if len(pending) == 1 else _joined(pending)
                pending, held = [tuple(values[size:] for values in joined)], held - size
                yield tuple(values[:size] for values in joined)
                if progress:
                    progress((read - held) / max(n, 1))
        if held:
            yield _joined(pending)
    _read_all(path, n, read, imu[0].topic)


def _imu_samples(path: Path, reader, imu: list, progress: ProgressCallback | None, total: int):
    """(time [s], gyro [deg/s], accel [g]) of every message on the IMU topic, in time order."""
    n = sum(c.msgcount for c in imu)
    time_s, gyro, accel = np.empty(n), np.empty((n, 3)), np.empty((n, 3))  # filled batch by batch: no copies
    done = 0
    for t, g, a in _imu_batches(
        path, reader, imu, DECODE_BATCH, (lambda f: progress(f * n / total)) if progress else None
    ):
        time_s[done : done + t.size], gyro[done : done + t.size], accel[done : done + t.size] = t, g, a
        done += t.size
    gyro, accel = gyro[:done], accel[:done]
    gyro *= _RAD
    accel *= _MS2
    return order_by_time(str(path), time_s[:done], gyro, accel)


def _temperature_samples(path: Path, reader, thermo: list):
    """(time [s], temperature [degC]) of every message on the temperature topic, in time order (an MCAP file's
    found by its chunks' indexes, :func:`~gyrocomp.io.mcap_chunks.mcap_arrays`; a ROS 1 bag's by rosbags' interface
    to :class:`ChunkedReader1`, which reads a sparse topic where the index says)."""
    times, values = [], []
    with damaged_bag(path, thermo[0].topic):
        chunks = mcap_arrays(reader, thermo)
        if chunks is None:
            raws = (raw for _, _, raw in reader.messages(connections=thermo))
        else:
            raws = (raw for found in chunks for raw in _raws(found))
        while batch := list(itertools.islice(raws, DECODE_BATCH)):
            time_s, temperature = _decoded_temperatures(reader, thermo[0].msgtype, batch)
            times.append(time_s)
            values.append(temperature)
    time_s, temperature = (np.concatenate(v) if v else np.empty(0) for v in (times, values))
    _read_all(path, sum(c.msgcount for c in thermo), time_s.size, thermo[0].topic)
    return order_by_time(str(path), time_s, temperature)


def _decoded_temperatures(reader, msgtype: str, raws: list) -> tuple[np.ndarray, np.ndarray]:
    """(stamp [s], temperature [degC]) of serialized temperature messages: a batch of one layout at once
    (:func:`~gyrocomp.io.ros_imu.temperature_fields`), any other message by message through rosbags."""
    fields = temperature_fields(raws, cdr=reader.is2)
    if fields is not None:
        return fields
    messages = [reader.deserialize(raw, msgtype) for raw in raws]
    return (
        np.array([header_stamp_s(m.header) for m in messages], dtype=float),
        np.array([m.temperature for m in messages], dtype=float),
    )


def chosen_topics(path: Path, connections: list, options: ReadOptions) -> tuple[list, list]:
    """The connections of the IMU topic the options choose and of its temperature topic (empty: none)."""
    imu = _topic(path, connections, IMU_TYPE, _imu_topic_asked(path, connections, options), "imu_topic")
    if not imu:
        topics = ", ".join(sorted(f"{c.topic} ({c.msgtype})" for c in connections)) or "none"
        raise InputError(f"{path}: no {IMU_TYPE} topic in the bag; its topics are {topics}")
    return imu, _topic(path, connections, TEMPERATURE_TYPE, options.temperature_topic, "temperature_topic")


def _metadata(path: Path, imu: list, thermo: list) -> dict:
    return {
        "path": str(path),
        "format": "rosbag",
        "imu_topic": imu[0].topic,
        "temperature_topic": thermo[0].topic if thermo else None,
    }


def _warn_no_temperature(path: Path) -> None:
    warnings.warn(
        f"{path}: no {TEMPERATURE_TYPE} topic; the recording has no temperature (only noise analysis works without it)",
        DataQualityWarning,
        stacklevel=user_stacklevel(),
    )


def read_rosbag(path, options: ReadOptions | None = None, progress: ProgressCallback | None = None) -> Recording:
    """Read a ROS 1 or ROS 2 bag into a :class:`Recording` [s, deg/s, g, degC].

    Parameters
    ----------
    path : path
        A ROS 1 ``.bag`` file, a ROS 2 bag folder (or a file in it) or a bare ``.mcap`` file.
    options : ReadOptions, optional
        ``imu_topic`` and ``temperature_topic`` (default: the only topic of each type).
    progress : callable, optional
        Called with the fraction done.
    """
    options = options or ReadOptions()
    path = Path(path)
    reader = _open(path)
    try:
        imu, thermo = chosen_topics(path, list(reader.connections), options)
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
        _warn_no_temperature(path)
    if progress:
        progress(1.0)
    return log_recording(path, options, time_s, gyro, accel, temperature, _metadata(path, imu, thermo))


@dataclass(frozen=True, eq=False)
class BagChunk:
    """Consecutive samples of a bag's IMU topic: the recording (``recording``), the same as a table in the
    default layout (``table``), every row of which is kept (``kept``), and the index of its first sample."""

    table: pa.Table
    recording: Recording
    kept: np.ndarray
    first_row: int


class BagStream:
    """A ROS bag's IMU topic read in chunks of about ``chunk_rows`` samples [s, deg/s, g, degC], each chunk the
    samples :func:`read_rosbag` gives for those messages, in memory bounded by the chunk whatever the bag's
    length: the temperature topic (a message a second, say) is read whole first and matched to each chunk, the
    IMU messages decoded a batch at a time. Repeated stamps are dropped and a batch out of time order sorted, as a
    whole read does, with its warning once for the bag; a stamp earlier than the last of a batch before cannot be
    sorted in chunks (:class:`~gyrocomp.io.stream.NotStreamable`: the bag is read whole). The interface of
    :class:`gyrocomp.io.stream.TableStream` that the file commands use: the chunks, the axes, the default
    layout, the gaps between chunks, :meth:`warn_summary`.

    Parameters
    ----------
    path : path
        A ROS 1 ``.bag`` file, a ROS 2 bag folder (or a file in it) or a bare ``.mcap`` file.
    options : ReadOptions, optional
        ``imu_topic``, ``instance``, ``temperature_topic``, ``drop_nonfinite``.
    chunk_rows : int
        Samples per chunk.
    progress : callable, optional
        Called with the fraction of the IMU messages read.
    """

    def __init__(self, path, options: ReadOptions | None = None, *, chunk_rows: int = CHUNK_ROWS, progress=None):
        self.path = Path(path)
        self.options = options or ReadOptions()
        self.chunk_rows = int(chunk_rows)
        self.progress = progress
        reader = _open(self.path)
        try:
            self.imu, self.thermo = chosen_topics(self.path, list(reader.connections), self.options)
            self._temperature = _temperature_samples(self.path, reader, self.thermo) if self.thermo else None
        except BaseException:
            reader.close()
            raise
        # kept open for the first reading of the chunks (an opening can take seconds: rosbags' sqlite3 storage
        # counts every topic's messages), closed then or when the stream is dropped unread
        self._reader, self._close_unread = reader, weakref.finalize(self, reader.close)
        self.layout = TableLayout()
        self.text_format = None
        self.gyro_axes, self.accel_axes = GYRO_AXES, ACCEL_AXES
        self.columns = {name: name for name in (TIME_COLUMN, *GYRO_AXES, *ACCEL_AXES)}
        self.rows = self.rows_dropped = self.gaps = 0
        self._period_s: float | None = None  # the first chunk's sample period [s]
        self._last_s: float | None = None  # the last chunk's last time [s]
        self._order = {"moved": 0, "dropped": 0, "back": 0.0, "samples": 0, "unmatched": 0, "last": -np.inf}

    def ordered(self, time_s, gyro, accel):
        """A batch sorted by time, repeated stamps dropped (the first kept), as :func:`order_by_time` does for
        the whole bag; a stamp not after the batches before: NotStreamable."""
        again = time_s == self._order["last"]  # the last sample's stamp repeated across the batches: dropped
        if np.any(again):
            self._order["dropped"] += int(np.count_nonzero(again))
            time_s, gyro, accel = time_s[~again], gyro[~again], accel[~again]
        if time_s.size and time_s.min() < self._order["last"]:
            raise NotStreamable("IMU stamps earlier than those of a batch before")
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always", TimeOrderWarning)
            time_s, gyro, accel = order_by_time(str(self.path), time_s, gyro, accel)
        for warning in said:
            if isinstance(warning.message, TimeOrderWarning):
                self._order["moved"] += warning.message.moved
                self._order["dropped"] += warning.message.dropped
                self._order["back"] = max(self._order["back"], warning.message.largest_back_s)
            else:
                warnings.warn_explicit(warning.message, warning.category, warning.filename, warning.lineno)
        if time_s.size:
            self._order["last"] = float(time_s[-1])
        return time_s, gyro, accel

    def matched(self, time_s, gyro, accel):
        """The samples within the temperature topic's span, with their temperature [degC] (None: no topic)."""
        self._order["samples"] += time_s.size
        if self._temperature is None:
            return time_s, gyro, accel, None
        what = f"temperature topic {self.thermo[0].topic}"
        temperature, ok = match_by_time(str(self.path), what, time_s, *self._temperature)
        missed = int(np.count_nonzero(~ok))
        self._order["unmatched"] += missed
        if not missed:  # the usual case: no copies
            return time_s, gyro, accel, temperature
        return time_s[ok], gyro[ok], accel[ok], temperature[ok]

    def chunks(self):
        """The IMU topic as :class:`BagChunk` s."""
        if self._temperature is None:
            _warn_no_temperature(self.path)
        reader, self._reader = self._reader, None
        if reader is None:
            reader = _open(self.path)
        else:
            self._close_unread.detach()
        held, parts = None, []
        try:
            imu = [c for c in reader.connections if c.topic == self.imu[0].topic]  # this reader's connections
            batch = max(2, min(DECODE_BATCH, self.chunk_rows))
            for time_s, gyro, accel in _imu_batches(self.path, reader, imu, batch, self.progress):
                part = self.matched(*self.ordered(time_s, gyro * _RAD, accel * _MS2))
                if part[0].size:
                    parts.append(part)
                if sum(p[0].size for p in parts) >= self.chunk_rows:
                    if held is not None:
                        yield self.chunk_of(held)
                    held, parts = _joined(parts), []
        finally:
            reader.close()
        rest = _joined(parts) if parts else None
        if held is not None and rest is not None and rest[0].size < 2:
            held, rest = _joined([held, rest]), None
        for part in (held, rest):
            if part is not None:
                yield self.chunk_of(part)
        if self._temperature is not None and self._order["unmatched"] == self._order["samples"]:
            raise none_matched(str(self.path), f"temperature topic {self.thermo[0].topic}")
        if self.progress:
            self.progress(1.0)

    def chunk_of(self, part: tuple) -> BagChunk:
        """The chunk of the samples ``part`` (time, gyro, accel, temperature or None, from :meth:`matched`), the
        next after those of the chunks before; gaps and dropped rows counted."""
        time_s, gyro, accel, temperature = part
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DataQualityWarning)  # rows dropped: counted over the bag, said once
            recording = log_recording(
                self.path,
                self.options,
                time_s,
                gyro,
                accel,
                temperature,
                _metadata(self.path, self.imu, self.thermo),
                first_row=self.rows,
            )
        self.rows_dropped += recording.metadata["rows_dropped"]
        first, self.rows = self.rows, self.rows + time_s.size
        if recording.n_samples:
            self._count_gap_before(recording.time_s[0])
        self.gaps += len(recording.gaps)
        if recording.n_samples > 1:
            self._period_s = self._period_s or 1.0 / recording.rate_hz
            self._last_s = float(recording.time_s[-1])
        return BagChunk(recording_table(recording), recording, np.arange(recording.n_samples), first)

    def _count_gap_before(self, first_s: float) -> None:
        """Count a gap between the chunks before and one starting at ``first_s`` [s] (more than two periods)."""
        if self._last_s is not None and first_s - self._last_s > 2 * self._period_s:
            self.gaps += 1

    def lone_sample(self, part: tuple):
        """One sample (``part`` as :meth:`chunk_of` takes it) as the next after those before, where a chunk of one
        sample cannot be a :class:`Recording` (at least two rows): its arrays [s, deg/s, g, degC] with the chunk's
        bookkeeping (rows, a gap before it, a non-finite sample dropped: None)."""
        time_s, gyro, accel, temperature = part
        values = [v for v in (gyro, accel, temperature) if v is not None]
        if self.options.drop_nonfinite and not all(np.all(np.isfinite(v)) for v in (time_s, *values)):
            self.rows_dropped += 1
            return None
        self._count_gap_before(time_s[0])
        self.rows += 1
        self._last_s = float(time_s[0])
        return LoneSample(time_s, gyro, self.gyro_axes, temperature, accel, self.accel_axes)

    def warn_summary(self) -> None:
        """The warnings a whole read gives, once for the bag: samples sorted or repeated, samples outside the
        temperature topic's span, rows dropped."""
        moved, dropped = self._order["moved"], self._order["dropped"]
        if moved or dropped:
            warnings.warn(
                time_order_warning(str(self.path), moved, dropped, self._order["back"]), stacklevel=user_stacklevel()
            )
        if self._order["unmatched"]:
            warnings.warn(
                left_out(
                    str(self.path),
                    f"temperature topic {self.thermo[0].topic}",
                    self._order["unmatched"],
                    self._order["samples"],
                ),
                DataQualityWarning,
                stacklevel=user_stacklevel(),
            )
        if self.rows_dropped:
            warnings.warn(
                rows_dropped(self.path, self.rows_dropped, self.rows), DataQualityWarning, stacklevel=user_stacklevel()
            )


class LoneSample(NamedTuple):
    """One sample of a stream [s, deg/s, g, degC], what a compensator reads of a recording
    (:meth:`BagStream.lone_sample`)."""

    time_s: np.ndarray
    gyro_dps: np.ndarray
    gyro_axes: tuple
    temperature_degc: np.ndarray | None
    accel_g: np.ndarray | None
    accel_axes: tuple

    @property
    def n_samples(self) -> int:
        return 1


def _joined(parts: list) -> tuple:
    """Sample tuples (time, gyro, accel, temperature or None) end to end."""
    return tuple(None if values[0] is None else np.concatenate(values) for values in zip(*parts))


def bag_stream(path: Path, options: ReadOptions, chunk_rows: int, progress) -> BagStream:
    """The :class:`BagStream` of a bag (the reader's ``stream``)."""
    return BagStream(path, options, chunk_rows=chunk_rows, progress=progress)


register_reader(
    Reader(
        "rosbag",
        "ROS 1 bag, ROS 2 bag folder or its .db3/.mcap, a bare .mcap, extra [ros]",
        read_rosbag,
        suffixes=(".bag", ".db3", ".mcap"),
        magic=(b"#ROSBAG", b"\x89MCAP"),
        aliases=("bag", "ros"),
        folder_marker="metadata.yaml",
        instances=rosbag_instances,
        stream=bag_stream,
    )
)
