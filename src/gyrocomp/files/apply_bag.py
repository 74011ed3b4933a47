"""A ROS bag compensated into a bag of the same kind (``gyrocomp apply MODEL in.bag -o out.bag``; extra ``[ros]``).

Every connection, message and time stamp is copied unchanged except the ``sensor_msgs/Imu`` topic the model is
applied to: its ``angular_velocity`` (and ``linear_acceleration`` when the model has accelerometer terms) is
replaced by the compensated value, exactly what :func:`gyrocomp.apply` gives on the recording the bag reads as
(the temperature from the matched ``sensor_msgs/Temperature`` topic, as in reading). A message whose header stamp
repeats an earlier one (which reading leaves out) gets the same correction as that one; a message the recording
does not hold (outside the temperature topic's span, or dropped as non-finite) is copied as it is, and a warning
says how many. The covariance fields are written from a noise model when one is given, else left as they were.
A ROS 1 ``.bag`` gives a ``.bag``; a ROS 2 bag folder gives a folder in the same storage (sqlite3 or MCAP); a bare
``.mcap`` file (an MCAP bag without its folder, read with the message definitions it holds) gives a ``.mcap``. The
output is written beside its final name and moved there when complete; the input is never touched.

The bag goes through once, in memory bounded whatever its length: messages are held until ``chunk_rows`` IMU
messages (or :data:`WINDOW_BYTES` of messages, once :data:`FIRST_SAMPLES` IMU samples have set the rate) have come,
the IMU messages among them decoded and compensated as a batch (:class:`gyrocomp.io.rosbag.BagStream`'s reading,
one :class:`~gyrocomp.calibration.compensate.Compensator` carrying its state from batch to batch) and written back
into their bytes (:mod:`gyrocomp.io.ros_imu`), then everything held written out in its order. A batch holding a
single IMU sample (the last of a bag, say) is compensated as the next sample of the stream. A bag whose IMU
stamps go back further than the batch before is compensated from a whole read instead (the same result).

A ROS 1 bag or an MCAP file (bare, or a bag folder's one file) of uncompressed chunks (what ``rosbag record`` and
``ros2 bag record`` in MCAP storage write by default) is not rewritten message by message: its bytes are copied with
each IMU message's values written in place (:func:`_patched_bag`; a compensated message keeps its length, so every
record, offset and index stays valid; an MCAP file's CRC-32s are computed anew), the messages batched as above; a
bag folder's one sqlite3 file is copied and its IMU rows updated. Any other bag goes through rosbags' writer.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import os
import re
import shutil
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..calibration import Calibration
from ..calibration.compensate import accel_xyz, apply, compensator_for
from ..errors import DataQualityWarning, InputError, user_stacklevel
from ..io import ReadOptions
from ..io.atomic import atomic_folder, refuse_link
from ..io.foreign_libraries import require
from ..io.mcap_chunks import mcap_arrays, mcap_storage
from ..io.rosbag2_sqlite import sqlite_arrays, sqlite_storage
from ..io.rosbag2_storage import topic_ids
from ..io.rosbag1_chunks import lean_writer1
from ..io.ros_imu import (
    ANGULAR_VELOCITY,
    ANGULAR_VELOCITY_COVARIANCE,
    LINEAR_ACCELERATION,
    LINEAR_ACCELERATION_COVARIANCE,
    imu_batch,
)
from ..io.rosbag import (
    IMU_TYPE,
    KIND_WORDS,
    BagStream,
    any_reader,
    bag_kind,
    bag_path,
    damaged_bag,
    decoded_imu,
    header_stamp_s,
    read_rosbag,
)
from ..io.stream import CHUNK_ROWS, NotStreamable
from ..io.write_behind import write_behind
from ..measures.noise_model import noise_file_densities, per_sample_covariance
from ..units import unit_factor
from .bag_patch import BagCopy, McapCopy, SqliteCopy, patch_in_batches, uncompressed

_RAD = unit_factor("gyro", "rad/s")  # deg/s per rad/s
_MS2 = unit_factor("accel", "m/s2")  # g per m/s^2
#: messages held before the IMU messages among them are compensated and everything written [bytes]
WINDOW_BYTES = 64 << 20
#: IMU samples the first batch holds at least, whatever the bytes held: the compensator's rate is theirs
FIRST_SAMPLES = 1000


@dataclass(frozen=True)
class AppliedBag:
    """What :func:`apply_bag` wrote: the output, the topic compensated, the messages compensated and copied as
    they were, whether the accelerations were compensated too, and the covariance fields written (none: left as
    they were), and whether it went through the bag once in batches (``streamed``) or from a whole read (stamps
    that go back across batches)."""

    path: Path
    imu_topic: str
    compensated: int
    unchanged: int
    accel: bool
    covariances: tuple[str, ...] = ()
    streamed: bool = True


def _storage(folder: Path) -> str | None:
    """The storage a ROS 2 bag folder's ``metadata.yaml`` names (``sqlite3``, ``mcap``)."""
    found = re.search(r"storage_identifier:\s*['\"]?(\w+)", (folder / "metadata.yaml").read_text(errors="replace"))
    return found.group(1) if found else None


def _writer(bag: Path, target: Path, connections, typestore):
    """A rosbags writer of the input's kind at ``target`` (a bare MCAP file: a ROS 2 folder in MCAP storage, whose
    file is taken out of it), with every connection of the input, by id (a connection of a bare MCAP file has no
    type hash: ``typestore``'s, from the definition in the file)."""
    kind = bag_kind(bag)
    if kind != "ros1":
        rosbag2 = require("rosbags.rosbag2", "ros", "writing ROS 2 bags")
        plugin = (
            rosbag2.StoragePlugin.MCAP if kind == "mcap" or _storage(bag) == "mcap" else rosbag2.StoragePlugin.SQLITE3
        )
        writer = rosbag2.Writer(target, version=9, storage_plugin=plugin)
        writer.open()
        out = {
            c.id: writer.add_connection(
                c.topic,
                c.msgtype,
                msgdef=c.msgdef.data,
                rihs01=c.digest or typestore.hash_rihs01(c.msgtype),
                serialization_format=c.ext.serialization_format,
                offered_qos_profiles=c.ext.offered_qos_profiles,
            )
            for c in connections
        }
    else:
        writer = lean_writer1()(target)
        writer.open()
        out = {
            c.id: writer.add_connection(
                c.topic,
                c.msgtype,
                msgdef=c.msgdef.data,
                md5sum=c.digest,
                callerid=c.ext.callerid,
                latching=c.ext.latching,
            )
            for c in connections
        }
    return writer, out


def apply_bag(
    calibration: Calibration,
    path,
    output,
    *,
    options: ReadOptions | None = None,
    noise=None,
    chunk_rows: int = CHUNK_ROWS,
) -> AppliedBag:
    """Compensate the IMU topic of a ROS bag into a bag of the same kind (see the module).

    Parameters
    ----------
    calibration : Calibration
        The model.
    path : path
        A ROS 1 ``.bag`` file, a ROS 2 bag folder or a bare ``.mcap`` file.
    output : path
        The bag to write, of the input's kind: a ``.bag`` file, a folder (replaced when it is a bag) or a
        ``.mcap`` file.
    options : ReadOptions, optional
        ``imu_topic`` or ``instance``, and ``temperature_topic`` (default: the only topic of each type).
    noise : path, optional
        A noise model (``gyrocomp noise --export json``): the compensated messages' ``angular_velocity_covariance``
        (and ``linear_acceleration_covariance`` when it models the accelerometer) are written from it, the
        variance of one sample at the bag's rate (N^2 rate) [rad^2/s^2, m^2/s^4]; without one they are left as
        they were.
    chunk_rows : int
        IMU messages compensated at once [messages].

    Returns
    -------
    AppliedBag
    """
    return _apply_bag({None: calibration}, path, output, options or ReadOptions(), noise, chunk_rows)[0]


def apply_bag_instances(
    calibrations: Mapping[int, Calibration],
    path,
    output,
    *,
    options: ReadOptions | None = None,
    chunk_rows: int = CHUNK_ROWS,
) -> tuple[AppliedBag, ...]:
    """Compensate several IMU topics of a ROS bag in one pass, each with its own model, into a bag of the same
    kind (see the module): instance k is the bag's k-th ``sensor_msgs/Imu`` topic in name order, as reading and
    ``gyrocomp fit --instance all`` number them.

    Parameters
    ----------
    calibrations : mapping of int to Calibration
        The model of each instance compensated (the other IMU topics are copied as they are).
    path, output : path
        As :func:`apply_bag`.
    options : ReadOptions, optional
        ``temperature_topic`` (default: the only one).
    chunk_rows : int
        IMU messages of a topic compensated at once [messages].

    Returns
    -------
    tuple of AppliedBag
        One per instance, in the order of ``calibrations``.
    """
    if not calibrations:
        raise InputError("calibrations: no model given")
    return _apply_bag(dict(calibrations), path, output, options or ReadOptions(), None, chunk_rows)


def _warn_unchanged(path: Path, counts: dict) -> None:
    """Warn of each topic's IMU messages copied uncompensated (``counts``: by topic, ``compensated``/``unchanged``)."""
    for topic, count in counts.items():
        if count["unchanged"]:
            warnings.warn(
                f"{path}: {count['unchanged']} message(s) of {topic} are not in the recording the bag "
                "reads as (outside the temperature topic's span, or not finite) and were copied "
                "uncompensated",
                DataQualityWarning,
                stacklevel=user_stacklevel(),
            )


def _apply_bag(
    calibrations: dict, path, output, options: ReadOptions, noise, chunk_rows: int
) -> tuple[AppliedBag, ...]:
    """Each model of ``calibrations`` (by instance; None: the topic ``options`` choose) on its IMU topic."""
    path, output = Path(path), Path(output)
    bag = bag_path(path)
    if bag_kind(bag) != bag_kind(output):
        raise InputError(
            f"output: {output}: a compensated bag is written as the input's kind: {KIND_WORDS[bag_kind(bag)]}"
        )
    refuse_output(output)
    covariance_of = _covariances(noise) if noise is not None else {}
    streams = {
        k: BagStream(
            path,
            options if k is None else dataclasses.replace(options, instance=k, imu_topic=None),
            chunk_rows=chunk_rows,
        )
        for k in calibrations
    }
    topics = {k: stream.imu[0].topic for k, stream in streams.items()}
    counts = {topics[k]: {"compensated": 0, "unchanged": 0} for k in calibrations}
    streamed = True
    try:
        copiers = {
            topics[k]: _Copier(calibrations[k], streams[k], covariance_of, counts[topics[k]]) for k in calibrations
        }
        with damaged_bag(path, ", ".join(copiers)):  # a damaged IMU record: found here when reading skipped it
            if not _patched_bag(bag, output, copiers, chunk_rows):
                _write_bag(
                    bag,
                    output,
                    lambda reader, writer, connections: _copy_in_batches(
                        reader, writer, connections, copiers, chunk_rows
                    ),
                )
        for stream in streams.values():
            stream.warn_summary()
        done = {topic: (c.with_accel, tuple(c.covariances)) for topic, c in copiers.items()}
    except NotStreamable:
        streamed = False
        counts = {topic: {"compensated": 0, "unchanged": 0} for topic in counts}
        results = {topics[k]: _whole(calibrations[k], path, streams[k].options, covariance_of) for k in calibrations}
        with damaged_bag(path, ", ".join(results)):
            _write_bag(
                bag, output, lambda reader, writer, connections: _copy(reader, writer, connections, results, counts)
            )
        done = {topic: (result[2], tuple(result[3])) for topic, result in results.items()}
    _warn_unchanged(path, counts)
    return tuple(
        AppliedBag(
            output,
            topics[k],
            counts[topics[k]]["compensated"],
            counts[topics[k]]["unchanged"],
            *done[topics[k]],
            streamed,
        )
        for k in calibrations
    )


def _whole(calibration: Calibration, path: Path, options: ReadOptions, covariance_of: dict) -> tuple:
    """(recording, its compensation, whether the accelerations are compensated, the covariance fields) of a whole
    read of the topic ``options`` choose."""
    recording = read_rosbag(path, options)
    compensated = apply(calibration, recording)
    covariances = {field: make(recording.rate_hz) for field, make in covariance_of.items()}
    accel = recording.accel_g is not None and not np.array_equal(compensated.accel_g, recording.accel_g)
    return recording, compensated, accel, covariances


def _batch_due(copiers: dict, raws: dict, most: int, held_bytes: int, chunk_rows: int) -> bool:
    """Whether the messages held are compensated and written now: a topic of ``copiers`` holds ``chunk_rows`` IMU
    messages (``most``), or :data:`WINDOW_BYTES` are held and each topic's rate is set (its compensator made, or
    :data:`FIRST_SAMPLES` of its messages held in ``raws``)."""
    return most >= chunk_rows or (
        held_bytes >= WINDOW_BYTES
        and all(copiers[t].comp is not None or len(m) >= FIRST_SAMPLES for t, m in raws.items())
    )


def _copy_in_batches(reader, writer, connections: dict, copiers: dict, chunk_rows: int) -> None:
    """Every message of the bag into ``writer`` in one pass: held until a topic of ``copiers`` has ``chunk_rows``
    IMU messages (or :data:`WINDOW_BYTES` are held, each topic's rate set: its compensator made, or
    :data:`FIRST_SAMPLES` held), the IMU messages among them compensated by their topic's copier, then everything
    held written in its order."""
    held, raws, held_bytes = [], {topic: [] for topic in copiers}, 0

    def write() -> None:
        out = {topic: copiers[topic].compensated(reader, messages) for topic, messages in raws.items() if messages}
        for connection, timestamp, topic, slot, raw in held:
            writer.write(connection, timestamp, raw if topic is None else out[topic][slot])

    imu = {c.id: c.topic for c in reader.connections if c.topic in copiers and c.msgtype == IMU_TYPE}
    most = 0  # the most IMU messages held of one topic
    for connection, timestamp, raw in reader.messages():
        topic = imu.get(connection.id)
        if topic is None:
            held.append((connections[connection.id], timestamp, None, -1, raw))
        else:
            messages = raws[topic]
            held.append((connections[connection.id], timestamp, topic, len(messages), raw))
            messages.append(raw)
            most = max(most, len(messages))
        held_bytes += len(raw)
        if _batch_due(copiers, raws, most, held_bytes, chunk_rows):
            write()
            held, raws, held_bytes, most = [], {topic: [] for topic in copiers}, 0, 0
    write()


def _patched_bag(bag: Path, output: Path, copiers: dict, chunk_rows: int) -> bool:
    """A bag compensated in one pass by copying it with each IMU message's values written in place (a compensated
    message keeps its length, so every record, offset and index stays as it was): a ROS 1 bag or one MCAP file (bare
    or the storage of a bag folder) of uncompressed chunks, the input's chunks, connections and index byte for byte
    (an MCAP file's CRC-32s computed anew); a bag folder's one sqlite3 file, its rows but the IMU messages' as they
    were. The IMU messages are batched as :func:`_copy_in_batches` does. False (nothing written) for any other bag."""
    kind = bag_kind(bag)
    with any_reader(bag) as reader:
        imu = [c for c in reader.connections if c.topic in copiers and c.msgtype == IMU_TYPE]
        if kind == "ros1":
            place = _ros1_in_place(reader, imu)
        else:
            place = _mcap_in_place(bag, reader, imu) or _sqlite_in_place(reader, imu)
        if place is None:
            return False
        file, arrays, ids, copy_to = place
        limits = (chunk_rows, WINDOW_BYTES, FIRST_SAMPLES)  # read now: the tests make windows smaller
        with staged_bag(output, kind) as target:
            if kind != "ros1":  # a folder: the bag's metadata.yaml as it is, beside its file
                target.mkdir()
                if bag.is_dir():
                    shutil.copyfile(bag / "metadata.yaml", target / "metadata.yaml")
                target = target / file.name
            with copy_to(file, target) as copy:
                patch_in_batches(reader, arrays, copy, copiers, ids, limits)
    return True


@contextlib.contextmanager
def _file_copy(make, source_path: Path, target_path: Path):
    """A :class:`BagCopy` (``make`` with the open source and sink) from ``source_path`` to ``target_path``, written
    by a thread of its own while the next chunks are compensated (:func:`~gyrocomp.io.write_behind.write_behind`)."""
    with open(source_path, "rb") as source, open(target_path, "wb") as sink, write_behind(sink) as behind:
        yield make(source, behind)


@contextlib.contextmanager
def _sqlite_copy(imu, source_path: Path, target_path: Path):
    """A :class:`SqliteCopy` from ``source_path`` to ``target_path``, closed on an error (the staged copy is then
    removed)."""
    copy = SqliteCopy(source_path, target_path, imu)
    try:
        yield copy
    except BaseException:
        copy.abandon()
        raise


def _ros1_in_place(reader, imu: list):
    """(the file, its messages as chunk arrays, IMU connection id -> topic, the copy's maker: source and target
    paths to a context of the copy) of a ROS 1 bag whose chunks are uncompressed, else None."""
    inner = reader.readers[0]
    if not hasattr(inner, "message_arrays") or not uncompressed(inner):
        return None
    return inner.path, inner.message_arrays(), {c.id: c.topic for c in imu}, functools.partial(_file_copy, BagCopy)


def _mcap_in_place(bag: Path, reader, imu: list):
    """What :func:`_ros1_in_place` gives, of a bag that is one MCAP file (bare, or a bag folder's only file as it
    lies there) with a summary, whose chunks are uncompressed and in time order (:func:`mcap_arrays`), else None."""
    storage = mcap_storage(reader)
    if storage is None or any(c.compression for c in storage.chunks):
        return None
    file = Path(storage.path)
    if (file.parent if bag.is_dir() else file).resolve() != bag.resolve():  # a bag folder's file decompressed
        return None
    data_end = storage.data_end - McapCopy.DATA_END.size  # the data end record, just before the summary
    storage.bio.seek(data_end)
    record = storage.bio.read(McapCopy.DATA_END.size)
    if len(record) != McapCopy.DATA_END.size or McapCopy.DATA_END.unpack(record)[:2] != (0x0F, 4):
        return None
    arrays = mcap_arrays(reader, list(reader.connections))
    if arrays is None:
        return None
    ids = topic_ids(storage, imu)
    data_crc = McapCopy.DATA_END.unpack(record)[2] != 0
    make = functools.partial(_file_copy, lambda source, sink: McapCopy(source, sink, data_end, data_crc))
    return file, arrays, ids, make


def _sqlite_in_place(reader, imu: list):
    """What :func:`_ros1_in_place` gives, of a ROS 2 bag folder whose one storage file is sqlite3 (messages not
    compressed): its rows in batches with their row ids (:func:`sqlite_arrays`), else None."""
    storage = sqlite_storage(reader)
    if storage is None:
        return None
    ids = topic_ids(storage, imu)
    return (
        Path(storage.path),
        sqlite_arrays(storage, list(reader.connections)),
        ids,
        functools.partial(_sqlite_copy, ids),
    )


class _Copier:
    """One IMU topic's part of the pass of :func:`apply_bag`: its messages compensated a batch at a time, the
    compensator's state carried from one batch to the next (see the module)."""

    def __init__(self, calibration: Calibration, stream: BagStream, covariance_of: dict, counts: dict):
        self.calibration, self.stream, self.covariance_of, self.counts = calibration, stream, covariance_of, counts
        self.comp = None
        self.with_accel = False
        self.covariances: dict = {}
        self.twin: tuple | None = None  # the last batch's last stamp and its corrections [rad/s, m/s^2] (or None)

    def compensated(self, reader, raws: list) -> list:
        """The IMU messages ``raws`` compensated (those outside the recording as they were)."""
        stamp, gyro_rad, accel_ms2 = decoded_imu(reader, IMU_TYPE, raws)
        done, new, new_accel = self._corrected(stamp, gyro_rad, accel_ms2)
        return self._encoded(reader, raws, done, new, new_accel)

    def compensated_fields(self, stamp_s: np.ndarray, gyro_rad: np.ndarray, accel_ms2: np.ndarray) -> tuple:
        """IMU messages of stamps ``stamp_s`` [s], angular velocities [rad/s] and linear accelerations [m/s^2]
        (n, 3) compensated, as what to write into them: the rows changed (in order) and, for each field written,
        (its first value's index among the message's float64 values, the rows' values (len(rows), m)) (those
        outside the recording as they were)."""
        done, new, new_accel = self._corrected(stamp_s, gyro_rad, accel_ms2)
        return done, self._fields(done, new, new_accel)

    def _corrected(self, stamp: np.ndarray, gyro_rad: np.ndarray, accel_ms2: np.ndarray) -> tuple:
        """(the rows compensated, their new angular velocity [rad/s] (n, 3), new linear acceleration [m/s^2] or
        None) of IMU messages of stamps ``stamp`` [s] as the stream's next; NaN in the rows left as they were."""
        stream = self.stream
        with_twin = self.twin is not None and np.any(stamp == self.twin[0])
        time_s, gyro, accel = stream.ordered(stamp, gyro_rad * _RAD, accel_ms2 * _MS2)
        part = stream.matched(time_s, gyro, accel)
        rec = None
        if part[0].size >= 2 or (part[0].size and self.comp is None):
            rec = stream.chunk_of(part).recording
        elif part[0].size:  # one sample (the last of a bag, say): compensated as the next of the stream
            rec = stream.lone_sample(part)
        values, correction, accel_values, accel_correction = self._corrections(rec)
        # each message: the first of its stamp takes the recording's value, a repeat the same correction
        count = stamp.size
        new = np.full((count, 3), np.nan)
        new_accel = np.full((count, 3), np.nan) if self.with_accel else None
        times = rec.time_s if rec is not None else np.empty(0)
        k = np.minimum(np.searchsorted(times, stamp), max(times.size - 1, 0))
        found = (times[k] == stamp) if times.size else np.zeros(count, dtype=bool)
        _, first_of = np.unique(stamp, return_index=True)
        first = np.zeros(count, dtype=bool)
        first[first_of] = True
        repeat = found & ~first
        new[found & first] = values[k[found & first]]
        new[repeat] = gyro_rad[repeat] - correction[k[repeat]]
        if self.with_accel:
            new_accel[found & first] = accel_values[k[found & first]]
            new_accel[repeat] = accel_ms2[repeat] - accel_correction[k[repeat]]
        if with_twin:  # repeats of the last batch's last sample
            again = stamp == self.twin[0]
            if self.twin[1] is not None:
                new[again] = gyro_rad[again] - self.twin[1]
                if self.with_accel:
                    new_accel[again] = accel_ms2[again] - self.twin[2]
        done = np.flatnonzero(np.all(np.isfinite(new), axis=1))
        if times.size:
            last = times.size - 1
            self.twin = (float(times[-1]), correction[last], accel_correction[last] if self.with_accel else None)
        self.counts["compensated"] += done.size
        self.counts["unchanged"] += count - done.size
        return done, new, new_accel

    def _corrections(self, rec):
        """(compensated gyro [rad/s], its correction, compensated accel [m/s^2], its correction) of the recording's
        samples."""
        if rec is None or rec.n_samples == 0:
            return np.empty((0, 3)), np.empty((0, 3)), np.empty((0, 3)), np.empty((0, 3))
        if self.comp is None:
            self.comp = compensator_for(self.calibration, rec)
            self.with_accel = self.comp.compensates_accel
            self.covariances = {field: make(rec.rate_hz) for field, make in self.covariance_of.items()}
        gyro = self.comp.update(rec.time_s, rec.gyro_dps, rec.temperature_degc, accel_xyz(rec))
        out = (gyro / _RAD, (rec.gyro_dps - gyro) / _RAD)
        if not self.with_accel:
            return (*out, None, None)
        accel = self.comp.take_accel()
        return (*out, accel / _MS2, (rec.accel_g - accel) / _MS2)

    def _encoded(self, reader, raws: list, done: np.ndarray, gyro: np.ndarray, accel) -> list:
        """The messages with the new values in rows ``done``: written into their bytes when they share a layout,
        else through rosbags message by message."""
        batch = imu_batch(raws, cdr=reader.is2)
        if batch is None:
            return self._reserialized(reader, raws, done, gyro, accel)
        for start, values in self._fields(done, gyro, accel):
            batch = batch.with_values(start, done, values)
        return [batch.message(i) for i in range(len(raws))]

    def _fields(self, done: np.ndarray, gyro: np.ndarray, accel) -> list:
        """(first value's index, values of the rows ``done``) of each field a compensated message gets: the angular
        velocity [rad/s], the linear acceleration [m/s^2] when compensated, the covariances when given."""
        fields = [(ANGULAR_VELOCITY, gyro[done])]
        if accel is not None:
            fields.append((LINEAR_ACCELERATION, accel[done]))
        for field, start in (
            ("angular_velocity_covariance", ANGULAR_VELOCITY_COVARIANCE),
            ("linear_acceleration_covariance", LINEAR_ACCELERATION_COVARIANCE),
        ):
            if field in self.covariances:
                fields.append((start, np.tile(np.asarray(self.covariances[field], dtype=float), (done.size, 1))))
        return fields

    def _reserialized(self, reader, raws: list, done: np.ndarray, gyro: np.ndarray, accel) -> list:
        store = reader.typestore
        serialize = store.serialize_cdr if reader.is2 else store.serialize_ros1
        out = list(raws)
        for i in done:
            msg = reader.deserialize(raws[i], IMU_TYPE)
            out[i] = serialize(_replaced(msg, gyro[i], None if accel is None else accel[i], self.covariances), IMU_TYPE)
        return out


def _replaced(msg, gyro_rad, accel_ms2, covariances: dict):
    """An IMU message with its angular velocity (x, y, z) [rad/s], its linear acceleration [m/s^2] (None: as it
    was) and the covariance fields ``covariances`` replaced."""
    changes = {
        "angular_velocity": dataclasses.replace(
            msg.angular_velocity, x=float(gyro_rad[0]), y=float(gyro_rad[1]), z=float(gyro_rad[2])
        )
    }
    if accel_ms2 is not None:
        changes["linear_acceleration"] = dataclasses.replace(
            msg.linear_acceleration, x=float(accel_ms2[0]), y=float(accel_ms2[1]), z=float(accel_ms2[2])
        )
    for field, values in covariances.items():
        changes[field] = np.asarray(values, dtype=np.float64)
    return dataclasses.replace(msg, **changes)


def _covariances(noise) -> dict:
    """The covariance fields a noise model's JSON file gives, each as a function of the bag's rate [Hz]."""
    gyro, accel = noise_file_densities(noise)
    out = {}
    if gyro is not None:
        out["angular_velocity_covariance"] = lambda rate: per_sample_covariance(gyro / _RAD, rate)
    if accel is not None:
        out["linear_acceleration_covariance"] = lambda rate: per_sample_covariance(accel / _MS2, rate)
    return out


def refuse_output(output: Path) -> None:
    """An output bag that is a link, or an existing folder that is not a ROS 2 bag (gyrocomp replaces only a bag),
    refused in one line."""
    refuse_link(output)
    if output.is_dir() and not (output / "metadata.yaml").is_file():
        raise InputError(
            f"output: {output}: is a folder that is not a ROS 2 bag; name a new path (gyrocomp replaces only a bag)"
        )


@contextlib.contextmanager
def staged_bag(output: Path, kind: str):
    """The path to write a bag of ``kind`` (``ros1``, ``ros2``, ``mcap``) at: beside ``output``, in a temporary
    folder (:func:`gyrocomp.io.atomic.atomic_folder`: one a killed process left is removed by the next run) moved
    into place when the block ends without an error (a bare MCAP file: its storage file alone, out of the folder
    rosbags writes it in), removed either way."""
    with atomic_folder(output) as tmp:
        target = tmp / (output.name if kind == "ros1" else "bag")
        yield target
        move_into_place(next(target.glob("*.mcap")) if kind == "mcap" else target, output, tmp / "replaced")


def _write_bag(bag: Path, output: Path, copy) -> None:
    """``copy(reader, writer, connections)`` into a bag of the input's kind, staged beside ``output``
    (:func:`staged_bag`)."""
    with staged_bag(output, bag_kind(bag)) as target, any_reader(bag) as reader:
        writer, connections = _writer(bag, target, reader.connections, reader.typestore)
        try:
            copy(reader, writer, connections)
        finally:
            writer.close()


def _copy(reader, writer, connections: dict, results: dict, counts: dict) -> None:
    """Every message into ``writer``: the IMU topics of ``results`` compensated (by topic: the recording, its
    compensation, whether the accelerations are compensated, the covariance fields to write), the rest as its
    bytes (a bag compensated from a whole read: message by message through rosbags)."""
    prepared = {topic: _prepared(result) for topic, result in results.items()}
    seen: dict[str, set[int]] = {topic: set() for topic in results}
    store = reader.typestore
    serialize = store.serialize_cdr if reader.is2 else store.serialize_ros1
    for connection, timestamp, raw in reader.messages():
        out = connections[connection.id]
        topic = connection.topic
        if topic not in results or connection.msgtype != IMU_TYPE:
            writer.write(out, timestamp, raw)
            continue
        time_s, gyro_rad, correction, accel_ms2, accel_correction, covariances = prepared[topic]
        msg = reader.deserialize(raw, connection.msgtype)
        stamp = header_stamp_s(msg.header)
        k = int(np.searchsorted(time_s, stamp))
        if k >= time_s.size or time_s[k] != stamp:
            counts[topic]["unchanged"] += 1
            writer.write(out, timestamp, raw)
            continue
        first = k not in seen[topic]  # a repeated stamp gets the same correction as the message reading kept
        seen[topic].add(k)
        w = msg.angular_velocity
        values = gyro_rad[k] if first else np.array([w.x, w.y, w.z]) - correction[k]
        acc = None
        if accel_ms2 is not None:
            a = msg.linear_acceleration
            acc = accel_ms2[k] if first else np.array([a.x, a.y, a.z]) - accel_correction[k]
        writer.write(out, timestamp, serialize(_replaced(msg, values, acc, covariances), connection.msgtype))
        counts[topic]["compensated"] += 1


def _prepared(result: tuple) -> tuple:
    """(time [s], compensated gyro [rad/s] (x, y, z), its correction, compensated accel [m/s^2] and its correction
    or None, covariance fields) of a whole read's ``result``."""
    recording, compensated, with_accel, covariances = result
    axes = [recording.gyro_axes.index(a) for a in ("gyro_x", "gyro_y", "gyro_z")]
    gyro_rad = (compensated.gyro_dps / _RAD)[:, axes]
    correction = ((recording.gyro_dps - compensated.gyro_dps) / _RAD)[:, axes]
    accel_ms2 = compensated.accel_g / _MS2 if with_accel else None
    accel_correction = (recording.accel_g - compensated.accel_g) / _MS2 if with_accel else None
    return recording.time_s, gyro_rad, correction, accel_ms2, accel_correction, covariances


def move_into_place(source: Path, output: Path, aside: Path) -> None:
    """``source`` (a file or a folder) to ``output``: a file replaces it in one step; a folder replaces an older
    folder by moving that to ``aside`` first (a new path in the staging folder, removed with it)."""
    if source.is_file() or not output.exists():
        os.replace(source, output)
        return
    os.replace(output, aside)
    os.replace(source, output)


__all__ = ["AppliedBag", "apply_bag", "apply_bag_instances", "refuse_output", "staged_bag"]
