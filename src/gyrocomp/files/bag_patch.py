"""A bag compensated in place: its bytes copied through, each IMU message's values written where they lie
(:func:`gyrocomp.files.apply_bag.apply_bag`'s way for the bags ``rosbag record`` and ``ros2 bag record`` write by
default: a ROS 1 bag and an MCAP file of uncompressed chunks, and a ROS 2 sqlite3 file, whose IMU rows are
updated, :class:`SqliteCopy`).

A compensated message keeps its length, so every record, offset and index of the input stays valid (an MCAP file's
CRC-32s of a patched chunk and of the data section are written anew where the input has them, :class:`McapCopy`).
The messages are taken a chunk at a time as arrays (:meth:`ChunkedReader1.message_arrays`,
:func:`gyrocomp.io.mcap_chunks.mcap_arrays`; a sqlite3 file's rows in batches,
:func:`gyrocomp.io.rosbag2_sqlite.sqlite_arrays`), held until a batch is due by the same
rule as a message-by-message pass (a topic holds ``chunk_rows`` IMU messages, or ``window_bytes`` are held and every
topic's rate is set: its compensator made or ``first_samples`` of its messages held), found for a whole chunk at
once; a batch's IMU messages of one layout are decoded and written back field by field as arrays, without a Python
object per message (messages of other layouts go through the copier message by message).
"""

from __future__ import annotations

import contextlib
import shutil
import sqlite3
import struct
import zlib
from typing import Protocol

import numpy as np

from ..errors import InputError
from ..io.byte_fields import Places
from ..io.foreign_libraries import require
from ..io.ros_imu import imu_fields


def uncompressed(reader) -> bool:
    """Whether every chunk of a ROS 1 bag (rosbags' reader) is stored uncompressed."""
    rb = require("rosbags.rosbag1.reader", "ros", "reading ROS 1 bags")
    for info in reader.chunk_infos:
        reader.bio.seek(info.pos)
        if reader.read_chunk().decompressor is not rb.decompressors["none"]:
            return False
    return True


class BagOutput(Protocol):
    """Where :func:`patch_in_batches` writes a bag: each chunk (or batch of rows) once its IMU messages are
    compensated, in order, then the rest of the bag (:class:`BagCopy`, :class:`McapCopy`, :class:`SqliteCopy`)."""

    def chunk(self, found, data) -> None:
        """A chunk's arrays ``found`` with its bytes ``data``, its IMU messages compensated."""

    def finish(self) -> None:
        """The rest of the bag, after the last chunk."""


class BagCopy:
    """The output of an in-place compensation: the input's bytes copied through, each chunk's data from its patched
    copy."""

    def __init__(self, source, sink):
        self.source, self.sink, self.copied = source, sink, 0

    def write(self, block) -> None:
        """Bytes out (any buffer)."""
        self.sink.write(block)

    def chunk(self, found, data) -> None:
        """The input up to a chunk's data as it is (``found``: the chunk's arrays, where its data lie in the file),
        then the chunk's data (patched; any buffer)."""
        self.through(found.data_pos)
        self.write(data)
        self.copied = found.data_pos + len(data)

    def finish(self) -> None:
        """The rest of the input as it is."""
        self.through()

    def through(self, end: int | None = None) -> None:
        """The input's bytes from where the copy is to ``end`` (None: the end of the file)."""
        self.source.seek(self.copied)
        left = None if end is None else end - self.copied
        while left is None or left > 0:
            block = self.source.read(1 << 20 if left is None else min(1 << 20, left))
            if not block:
                break
            self.write(block)
            if left is not None:
                left -= len(block)
        self.copied = self.source.tell()


class McapCopy(BagCopy):
    """:class:`BagCopy` of an MCAP file of uncompressed chunks: a patched chunk's CRC-32 (in its record, before its
    records: CRC uint32, compression "" as its length uint32, the records' length uint64) and the data section's
    (in the data end record at ``data_end``, of every byte before it; ``data_crc``: the input has one) computed anew
    where the input has them (zero: none). ``sink`` is a :class:`~gyrocomp.io.write_behind.WriteBehind`: the
    checksums (two passes over every byte of the bag) are computed in its thread, in order with the writes."""

    #: a chunk record's bytes from its CRC to its records, uncompressed
    HEAD = 16
    DATA_END = struct.Struct("<BQI")  # opcode 0x0F, length 4, CRC-32

    def __init__(self, source, sink, data_end: int, data_crc: bool):
        super().__init__(source, sink)
        self.data_end, self.data_crc, self.written, self.crc = data_end, data_crc, 0, 0

    def write(self, block) -> None:
        self.sink.call(self._out, block)

    def _out(self, block) -> None:
        """Bytes out, in the writer's thread, added to the data section's CRC while within it."""
        if self.data_crc and self.written < self.data_end:
            self.crc = zlib.crc32(memoryview(block)[: self.data_end - self.written], self.crc)
        self.written += len(block)
        self.sink.file.write(block)

    def chunk(self, found, data) -> None:
        self.through(found.data_pos - self.HEAD)
        self.sink.call(self._chunk_out, bytearray(self.source.read(self.HEAD)), data)
        self.copied = found.data_pos + len(data)

    def _chunk_out(self, head: bytearray, data) -> None:
        """A patched chunk's head (its CRC computed anew where it has one) and records, in the writer's thread."""
        if head[:4] != bytes(4):
            head[:4] = struct.pack("<I", zlib.crc32(data))
        self._out(head)
        self._out(data)

    def finish(self) -> None:
        self.through(self.data_end)
        op, length, crc = self.DATA_END.unpack(self.source.read(self.DATA_END.size))
        if (op, length) != (0x0F, 4):
            raise InputError(f"no MCAP data end record at byte {self.data_end}")
        self.sink.call(lambda: self._out(self.DATA_END.pack(op, length, self.crc if crc else 0)))  # the CRC so far
        self.copied = self.data_end + self.DATA_END.size
        self.through()


class SqliteCopy:
    """The output of an in-place compensation of a ROS 2 sqlite3 bag's storage file: the file copied as it is,
    then each batch's IMU messages (the rows of the topic ids ``imu``) written over their rows by row id, in one
    transaction without a journal (a compensated message keeps its length; every other row, table and index stays as
    it was)."""

    def __init__(self, source, target, imu):
        shutil.copyfile(source, target)
        self.db = sqlite3.connect(target, isolation_level=None)
        # no rollback journal and no syncs: the copy is a staged file, moved into place only when complete
        self.db.execute("PRAGMA journal_mode = OFF")
        self.db.execute("PRAGMA synchronous = OFF")
        self.db.execute("BEGIN")
        self.imu = np.fromiter(imu, dtype=np.int64)

    def chunk(self, found, data) -> None:
        """A batch's IMU messages from their patched bytes ``data`` (``found``: the batch's arrays with row ids)."""
        rows = np.flatnonzero(np.isin(found.conn, self.imu))
        starts, lengths, ids = found.data_at[rows].tolist(), found.data_length[rows].tolist(), found.ids[rows].tolist()
        self.db.executemany(
            "UPDATE messages SET data = ? WHERE id = ?",
            ((data[a : a + n].tobytes(), i) for a, n, i in zip(starts, lengths, ids)),
        )

    def finish(self) -> None:
        """Commit and close."""
        self.db.execute("COMMIT")
        self.db.close()

    def abandon(self) -> None:
        """Close after an error part way (the staged copy is then removed, never moved into place)."""
        with contextlib.suppress(sqlite3.Error):
            self.db.close()


def due_at(
    topic_of: np.ndarray,
    lengths: np.ndarray,
    held: np.ndarray,
    held_bytes: int,
    ready: np.ndarray,
    limits: tuple[int, int, int],
) -> int | None:
    """The first message after which a batch is due, or None: messages of topics ``topic_of`` (index, -1: not
    compensated) and data ``lengths`` [bytes] in order, after ``held`` messages of each topic and ``held_bytes``
    already held, ``ready`` the topics whose compensator is made; ``limits`` = (chunk_rows, window_bytes,
    first_samples). Due when a topic holds chunk_rows messages, or window_bytes are held and every topic is ready
    or holds first_samples."""
    chunk_rows, window_bytes, first_samples = limits
    counts = held[None, :] + np.cumsum(topic_of[:, None] == np.arange(held.size)[None, :], axis=0)
    full = counts.max(axis=1, initial=0) >= chunk_rows
    window = (held_bytes + np.cumsum(lengths) >= window_bytes) & np.all(ready | (counts >= first_samples), axis=1)
    due = full | window
    return int(np.argmax(due)) if due.any() else None


def patch_in_batches(reader, arrays, copy: BagOutput, copiers: dict, imu: dict, limits: tuple[int, int, int]) -> None:
    """Every message of the bag in its order, a chunk at a time, held until a batch is due (:func:`due_at`); at
    each batch each topic's IMU messages are compensated by its copier and written into their chunk's copy, and
    every chunk whose messages are all done goes out.

    Parameters
    ----------
    reader
        rosbags' reader of the bag.
    arrays : iterable of ChunkArrays
        Every message of the bag, chunk by chunk as arrays, in the order of ``reader.messages()``.
    copy : BagOutput
        Where the bag goes.
    copiers : dict
        Each compensated topic's copier (``comp``, ``compensated(reader, raws)``, ``compensated_fields(stamp_s,
        gyro_rad, accel_ms2)``).
    imu : dict
        Connection id (an MCAP file's channel id) -> topic of the IMU connections compensated.
    limits : (int, int, int)
        chunk_rows, window_bytes [bytes], first_samples: the batching rule.
    """
    topics = list(copiers)
    ids = {conn: topics.index(topic) for conn, topic in imu.items()}
    chunks: list = []  # (arrays, patched copy) of the chunks not yet written, in order
    held: list = [[] for _ in topics]  # each topic's messages held: (chunk copy, data_at, data_length) pieces
    counts, held_bytes = np.zeros(len(topics), dtype=np.int64), 0

    def write(done: int) -> None:
        for topic, pieces in zip(topics, held):
            if pieces:
                _write_topic(reader, topic, copiers[topic], pieces)
        for found, data in chunks[:done]:
            copy.chunk(found, data)
        del chunks[:done]

    for found in arrays:
        data = found.data.copy()
        chunks.append((found, data))
        topic_of = np.full(found.conn.size, -1, dtype=np.int64)
        for conn, index in ids.items():
            topic_of[found.conn == conn] = index
        start = 0
        while start < topic_of.size:
            ready = np.array([copiers[t].comp is not None for t in topics], dtype=bool)
            hit = due_at(topic_of[start:], found.data_length[start:], counts, held_bytes, ready, limits)
            stop = topic_of.size if hit is None else start + hit + 1
            for index in range(len(topics)):
                rows = start + np.flatnonzero(topic_of[start:stop] == index)
                if rows.size:
                    held[index].append((data, found.data_at[rows], found.data_length[rows]))
                    counts[index] += rows.size
            held_bytes += int(found.data_length[start:stop].sum())
            if hit is not None:
                write(len(chunks) - 1)  # the chunks before this one are done
                held, counts, held_bytes = [[] for _ in topics], np.zeros(len(topics), dtype=np.int64), 0
            start = stop
    write(len(chunks))
    copy.finish()


def _write_topic(reader, topic: str, copier, pieces: list) -> None:
    """One topic's held IMU messages compensated and written into their chunks' copies: when they share one layout
    as arrays, field by field; else message by message."""
    lengths = np.concatenate([p[2] for p in pieces])
    if lengths.size and np.all(lengths == lengths[0]):
        width = int(lengths[0])
        read = [imu_fields(p[0], p[1], width, cdr=reader.is2) for p in pieces]
        if all(f is not None and f.values_at == read[0].values_at for f in read):
            done, fields = copier.compensated_fields(
                np.concatenate([f.stamp_s for f in read]),
                np.concatenate([f.angular_velocity for f in read]),
                np.concatenate([f.linear_acceleration for f in read]),
            )  # rows in order
            firsts = np.cumsum([0] + [p[1].size for p in pieces])
            cuts = np.searchsorted(done, firsts)
            places = [Places(data, at) for data, at, _ in pieces]
            for start, values in fields:
                values = np.ascontiguousarray(values, dtype="<f8")
                for k, place in enumerate(places):
                    rows = done[cuts[k] : cuts[k + 1]] - firsts[k]  # this chunk's rows compensated, in order
                    every = rows.size == place.at.size
                    place.write(read[0].values_at + 8 * start, values[cuts[k] : cuts[k + 1]], None if every else rows)
            return
    places = [(p[0], a, n) for p in pieces for a, n in zip(p[1].tolist(), p[2].tolist())]
    for (data, a, n), new in zip(
        places, copier.compensated(reader, [data[a : a + n].tobytes() for data, a, n in places])
    ):
        if len(new) != n:  # values replaced in a fixed layout: never; the offsets would not hold
            raise InputError(f"topic {topic}: a compensated IMU message changed its length")
        data[a : a + n] = np.frombuffer(new, dtype=np.uint8)


__all__ = ["BagCopy", "BagOutput", "McapCopy", "SqliteCopy", "due_at", "patch_in_batches", "uncompressed"]
