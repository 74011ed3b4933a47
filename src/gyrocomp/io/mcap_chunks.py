"""An MCAP file's messages read chunk by chunk as arrays (a ROS 2 bag in MCAP storage, or a bare ``.mcap``; extra
``[ros]``).

rosbags' MCAP reader (:class:`rosbags.rosbag2.storage_mcap.McapReader`) yields a topic's messages one Python object at
a time: it decompresses each chunk that holds the topic, walks every record in it (a ten-hour IMU topic at 1 kHz is
3.6e7 records, walked again for a temperature topic at 1 Hz, which lies in every chunk), sorts the chunk's messages
by log time and merges the chunks by log time. :func:`mcap_arrays` gives the same messages in the same order a
chunk at a time as arrays (:class:`~gyrocomp.io.rosbag1_chunks.ChunkArrays`: the chunk's records, and of its messages
the channel ids, log times [ns], where their data start and their lengths [bytes]), for a caller that decodes them
together.

A chunk's messages are found where its message index records say (one per channel in the chunk, after it: each
message's log time and offset). Each entry is checked at its place (a message record of that channel and log time),
and the records between consecutive messages are walked (a schema or channel record may lie there; a message record
there means the index is incomplete). A chunk whose index does not hold is walked record by record. A topic that is
a small part of an uncompressed chunk (a temperature at 1 Hz beside an IMU at 1 kHz) is read where the index says,
its records alone, each checked at its place.

The order is rosbags': in a chunk by log time (a stable sort of the records' order), chunk after chunk in file
order, which is rosbags' merge by log time when no chunk's time range starts before the previous one's ends; where
they overlap, :func:`mcap_arrays` gives None and the caller reads through rosbags. As rosbags does, only the chunks
whose index names the channel are read, and only the messages within their chunk's time range.

The MCAP format: records of an opcode (1 byte), a length (uint64) and content. A chunk record (0x06) holds its
messages' start and end log time, the records' uncompressed size and CRC-32, the compression and the records:
message records (0x05: channel id uint16, sequence uint32, log time uint64, publish time uint64, data) and schema
or channel records. The summary's chunk index (read by rosbags) says where each chunk and its message index records
(0x07: channel id uint16, then (log time, offset in the chunk's records) uint64 pairs) lie.
"""

from __future__ import annotations

import os
import struct
from collections.abc import Iterator

import numpy as np

from .byte_fields import Places, among
from .foreign_libraries import require
from .read_ahead import ReadAhead
from .rosbag1_chunks import SPARSE, ChunkArrays
from .rosbag2_storage import channel_ids, one_storage

_MESSAGE, _CHUNK, _MESSAGE_INDEX = 0x05, 0x06, 0x07
#: a message record's bytes before its data: opcode, length, channel id, sequence, log time, publish time
_MESSAGE_HEAD = 1 + 8 + 2 + 4 + 8 + 8
#: a message record's content before its data: channel id, sequence, log time, publish time
_MESSAGE_FIELDS = _MESSAGE_HEAD - 9
_RECORD = struct.Struct("<BQ")  # opcode, length
_CHUNK_HEAD = struct.Struct("<BQQQQI")  # opcode, length, start time, end time, uncompressed size, CRC-32
_INDEX_HEAD = struct.Struct("<BQHI")  # opcode, length, channel id, entries' length
_MESSAGE_ID = struct.Struct("<HIQ")  # channel id, sequence, log time
_U32, _U64 = struct.Struct("<I"), struct.Struct("<Q")


def _storage_mcap():
    """rosbags' MCAP storage module (its reader, its decompression and its error)."""
    return require("rosbags.rosbag2.storage_mcap", "ros", "reading MCAP bags")


def mcap_storage(reader):
    """The rosbags MCAP reader of the one MCAP file under an open :class:`rosbags.highlevel.AnyReader` (a ROS 2 bag
    folder holding one MCAP file, or a bare ``.mcap``) whose summary indexes its chunks; None for any other bag
    (ROS 1, sqlite3, several files, messages compressed one by one, no chunk index)."""
    found = one_storage(reader)
    if found is None or (found[1] is not None and found[1].compression_mode == "message"):
        return None
    storage = found[0]
    if not isinstance(storage, _storage_mcap().McapReader) or storage.bio is None or not storage.chunks:
        return None
    return storage


def mcap_arrays(reader, connections) -> Iterator[ChunkArrays] | None:
    """The messages of ``connections`` of an open rosbags reader of one MCAP file, chunk by chunk as arrays in the
    order rosbags yields them (see the module); None where they cannot be read so (not one MCAP file with a chunk
    index, or chunks whose time ranges overlap: read them through rosbags)."""
    storage = mcap_storage(reader)
    if storage is None:
        return None
    ids = channel_ids(storage, connections)
    chunks = sorted(
        (c for c in storage.chunks if any(c.channel_count.get(i, 0) for i in ids)), key=lambda c: c.chunk_start_offset
    )
    if any(a.message_end_time > b.message_start_time for a, b in zip(chunks, chunks[1:])):
        return None
    size = os.fstat(storage.bio.fileno()).st_size
    wanted = sum(c.channel_count.get(i, 0) for c in chunks for i in ids)
    if wanted * SPARSE <= sum(sum(c.channel_count.values()) for c in chunks):  # read where the indexes say
        return (_chunk_arrays(storage.bio, size, info, ids) for info in chunks)
    return _read_ahead(storage.bio, size, chunks, ids)


def _read_ahead(bio, size: int, chunks: list, ids: set[int]) -> Iterator[ChunkArrays]:
    """:func:`_chunk_arrays` of each of ``chunks``, the file read ahead by a thread of its own (the disk reads on
    while a chunk is decoded: :class:`~gyrocomp.io.read_ahead.ReadAhead`)."""
    with ReadAhead(getattr(bio, "name", None)) as ahead:
        for info in chunks:
            ahead.at(info.chunk_start_offset)
            yield _chunk_arrays(bio, size, info, ids)


def _chunk_arrays(bio, size: int, info, ids: set[int]) -> ChunkArrays:
    """One chunk's messages of the channels ``ids`` within its time range, sorted by log time (stably), from a file
    of ``size`` bytes: read where the index says when they are a small part of an uncompressed chunk
    (:func:`_sparse`), else from the whole chunk."""
    sparse = _sparse(bio, size, info, ids)
    if sparse is not None:
        return _chosen(*sparse, info, ids)
    data, records_at = _chunk_records(bio, size, info)
    found = _indexed(bio, size, info, data)
    return _chosen(data, records_at, *(found if found is not None else _walked(data)), info, ids)


def _chosen(data, data_pos: int, at, channel, time, length, info, ids: set[int]) -> ChunkArrays:
    """The messages of ``ids`` among records at ``at`` of ``data`` (their channel ids, log times [ns], lengths
    [bytes]) within the chunk's time range, sorted by log time (stably), as :class:`ChunkArrays`."""
    keep = among(channel, ids) & (time >= info.message_start_time)
    keep &= time <= info.message_end_time
    order = np.flatnonzero(keep)[np.argsort(time[keep], kind="stable")]
    return ChunkArrays(
        data, data_pos, channel[order], time[order], at[order] + _MESSAGE_HEAD, length[order] - _MESSAGE_FIELDS
    )


def _chunk_head(bio, file_size: int, info) -> tuple[int, int]:
    """(where a chunk's records lie in the file [bytes], their CRC-32) from its record's head, checked against the
    chunk index; a chunk record that disagrees with it, or runs past the end of the file, is an error."""
    mcap = _storage_mcap()
    bio.seek(info.chunk_start_offset)
    op, length, _, _, size, crc = _CHUNK_HEAD.unpack(mcap.read_exact(bio, _CHUNK_HEAD.size))
    end = info.chunk_start_offset + 9 + length
    (name_length,) = _U32.unpack(mcap.read_exact(bio, 4))
    if op != _CHUNK or end > file_size or bio.tell() + name_length + 8 > end:
        raise mcap.ReaderError(f"The chunk at byte {info.chunk_start_offset} does not match the file's chunk index.")
    compression = mcap.read_exact(bio, name_length).decode(errors="replace")
    (compressed,) = _U64.unpack(mcap.read_exact(bio, 8))
    records_at = bio.tell()
    if (compression, compressed, size) != (
        info.compression,
        info.compressed_size,
        info.uncompressed_size,
    ) or records_at + compressed > end:
        raise mcap.ReaderError(f"The chunk at byte {info.chunk_start_offset} does not match the file's chunk index.")
    return records_at, crc


def _chunk_records(bio, file_size: int, info) -> tuple[np.ndarray, int]:
    """A chunk's records, decompressed and checked (size and CRC-32, by rosbags), as uint8, and where they lie in the
    file [bytes] (their place when uncompressed)."""
    records_at, crc = _chunk_head(bio, file_size, info)
    mcap = _storage_mcap()
    raw = mcap.decompress(mcap.read_exact(bio, info.compressed_size), info.compression, info.uncompressed_size, crc)
    return np.frombuffer(raw, dtype=np.uint8), records_at


def _index_entries(bio, file_size: int, offset: int, cid: int) -> np.ndarray | None:
    """The entries (log time [ns], offset in the chunk's records [bytes]) (n, 2) of channel ``cid``'s message index
    record at ``offset`` of the file; None where it does not read as one."""
    bio.seek(offset)
    head = bio.read(_INDEX_HEAD.size)
    if len(head) < _INDEX_HEAD.size:
        return None
    op, length, index_channel, size = _INDEX_HEAD.unpack(head)
    if op != _MESSAGE_INDEX or index_channel != cid or size % 16 or size + 6 > length:
        return None
    if offset + _INDEX_HEAD.size + size > file_size:
        return None
    raw = bio.read(size)
    return np.frombuffer(raw, dtype="<u8").reshape(-1, 2) if len(raw) == size else None


def _sparse(bio, file_size: int, info, ids: set[int]):
    """What :func:`_chosen` takes, of the messages of ``ids`` in an uncompressed chunk where they are at most one in
    :data:`~gyrocomp.io.rosbag1_chunks.SPARSE` of its messages (a temperature topic at 1 Hz beside an IMU at 1
    kHz), each message record read where the chunk's message index says and checked there (a message of its
    channel and log time, inside the chunk) instead of reading the whole chunk; None where that does not apply or does not hold (the chunk is then
    read whole). Those records alone are read (their bytes end to end, ``data_pos`` -1: not the chunk's place), and
    the chunk's CRC-32 is not checked."""
    hits = sum(info.channel_count.get(i, 0) for i in ids)
    if info.compression or hits * SPARSE > sum(info.channel_count.values()):
        return None
    records_at, _ = _chunk_head(bio, file_size, info)
    found = []
    for cid in sorted(ids & info.message_index_offsets.keys()):
        entries = _index_entries(bio, file_size, info.message_index_offsets[cid], cid)
        if entries is None:
            return None
        found += [(int(o), cid, int(t)) for t, o in entries.tolist()]
    records, at, channel, time, lengths = [], [], [], [], []
    held = 0
    for offset, cid, log_time in sorted(found):  # the records' order
        if offset + _MESSAGE_HEAD > info.uncompressed_size:
            return None
        bio.seek(records_at + offset)
        record = bio.read(_MESSAGE_HEAD)
        if len(record) < _MESSAGE_HEAD:
            return None
        op, length = _RECORD.unpack_from(record)
        channel_id, _, record_time = _MESSAGE_ID.unpack_from(record, 9)
        if (op, channel_id, record_time) != (_MESSAGE, cid, log_time) or length < _MESSAGE_FIELDS:
            return None
        if offset + 9 + length > info.uncompressed_size:
            return None
        record += bio.read(length - _MESSAGE_FIELDS)
        records.append(record)
        at.append(held)
        channel.append(cid)
        time.append(log_time)
        lengths.append(length)
        held += len(record)
    return (
        np.frombuffer(b"".join(records), dtype=np.uint8),
        -1,
        np.array(at, dtype=np.int64),
        np.array(channel, dtype=np.int64),
        np.array(time, dtype=np.int64),
        np.array(lengths, dtype=np.int64),
    )


def _indexed(bio, file_size: int, info, data: np.ndarray):
    """(where each record starts [bytes], channel id, log time [ns], record length [bytes]) of every message in a
    chunk, in the records' order, found by the chunk's message index records (every channel's); None where they do
    not hold (an entry not at a message record of its channel and time, a message record between the indexed ones,
    records that do not tile the chunk)."""
    at, channel, time = [], [], []
    for cid, offset in info.message_index_offsets.items():
        entries = _index_entries(bio, file_size, offset, cid)
        if entries is None:
            return None
        time.append(entries[:, 0])
        at.append(entries[:, 1])
        channel.append(np.full(entries.shape[0], cid, dtype=np.int64))
    if not at or not sum(a.size for a in at):
        return None
    at, channel, time = np.concatenate(at), np.concatenate(channel), np.concatenate(time)
    if data.size < _MESSAGE_HEAD or at.max() > data.size - _MESSAGE_HEAD:
        return None
    order = np.argsort(at, kind="stable")
    at, channel, time = at[order].astype(np.int64), channel[order], time[order]
    places = Places(data, at)
    length = places.read(1, "<u8")
    if np.any(places.read(0, np.uint8) != _MESSAGE) or np.any(length < _MESSAGE_FIELDS) or np.any(length > data.size):
        return None
    length = length.astype(np.int64)
    ends = at + 9 + length
    if ends[-1] > data.size:
        return None
    if not np.array_equal(places.read(9, "<u2"), channel) or not np.array_equal(places.read(15, "<u8"), time):
        return None
    between = np.flatnonzero(at[1:] != ends[:-1])
    spans = [(0, int(at[0])), *((int(ends[i]), int(at[i + 1])) for i in between), (int(ends[-1]), data.size)]
    if not all(_no_messages(data, start, stop) for start, stop in spans):
        return None
    return at, channel, time.astype(np.int64), length


def _no_messages(data: np.ndarray, start: int, stop: int) -> bool:
    """Whether the records from ``start`` end exactly at ``stop`` [bytes] and none of them is a message."""
    pos = start
    while pos < stop:
        if pos + 9 > stop:
            return False
        op, length = _RECORD.unpack_from(data, pos)
        if op == _MESSAGE:
            return False
        pos += 9 + length
    return pos == stop


def _walked(data: np.ndarray):
    """What :func:`_indexed` gives, found by walking the chunk's records one by one."""
    mcap = _storage_mcap()
    at, channel, time, lengths = [], [], [], []
    pos = 0
    while pos < data.size:
        if pos + 9 > data.size:
            raise mcap.ReaderError("A record runs past the end of its chunk.")
        op, length = _RECORD.unpack_from(data, pos)
        if pos + 9 + length > data.size:
            raise mcap.ReaderError("A record runs past the end of its chunk.")
        if op == _MESSAGE:
            if length < _MESSAGE_FIELDS:
                raise mcap.ReaderError(f"Invalid message record length {length}.")
            cid, _, log_time = _MESSAGE_ID.unpack_from(data, pos + 9)
            at.append(pos)
            channel.append(cid)
            time.append(log_time)
            lengths.append(length)
        pos += 9 + length
    return (
        np.array(at, dtype=np.int64),
        np.array(channel, dtype=np.int64),
        np.array(time, dtype=np.uint64).astype(np.int64),
        np.array(lengths, dtype=np.int64),
    )


__all__ = ["mcap_arrays", "mcap_storage"]
