"""rosbags' ROS 1 bag reader and writer, in memory bounded by a chunk whatever the bag's length (extra ``[ros]``).

rosbags' :class:`rosbags.rosbag1.Reader` reads an index entry of every message when it opens a bag (measured: about
155 bytes a message, 5.6 GB for a ten-hour IMU topic at 1 kHz), so that it can yield the messages of several
connections merged in time order. A ROS 1 bag's chunks follow each other in time, and within a chunk its messages in
the order they were recorded: :class:`ChunkedReader1` opens a bag from its connection and chunk-info records only
(the per-connection message counts come from the chunk infos) and yields the messages chunk by chunk as they lie in
the file, each chunk decompressed (none, bz2, lz4) when it is reached. The bag's index is read by rosbags' own
functions, a chunk's records by :func:`_chunk_messages` (walked by runs of records of one shape, their three header
fields read for all records of one layout at once), a topic that is a small part of an uncompressed chunk (a
temperature beside an IMU) where the chunk's index data records say (:func:`_indexed_messages`), and a chunk's
messages as arrays for a caller that decodes them together (:func:`_message_arrays`); everything else
(connections, message definitions, the type store of :class:`rosbags.highlevel.AnyReader`) is rosbags' as it is.

:func:`lean_writer1`'s writer is rosbags' writer that, once a chunk and its index records are in the file, keeps
only the chunk's message count per connection (what closing the bag writes) instead of an entry per message.

The ROS 1 bag format (version 2.0): records of a header (``op``, ``conn``, ``time``, ...) and data; chunks hold
connection and message-data records; after the chunks, at the bag header's ``index_pos``, the connection records and
one chunk-info record per chunk (its position and its message count per connection); each chunk is followed by one
index data record per connection in it (each message's time and offset in the uncompressed chunk).
"""

from __future__ import annotations

import functools
import os
import re
import struct
from typing import NamedTuple

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from .byte_fields import Places, among
from .foreign_libraries import require
from .read_ahead import ReadAhead


def _rosbag1():
    """rosbags' ROS 1 reader module (the records' parsers)."""
    return require("rosbags.rosbag1.reader", "ros", "reading ROS 1 bags")


def _open(self) -> None:
    """Open the bag and read its connections and chunk infos."""
    rb = _rosbag1()
    if self.bio is not None:
        raise rb.ReaderError("Reader is already open.")
    try:
        self.bio = self.path.open("rb")
    except OSError as err:
        raise rb.ReaderError(f"Could not open file {str(self.path)!r}: {err.strerror}.") from err
    try:
        _read_metadata(self, rb)
    except BaseException:
        self.bio.close()
        self.bio = None
        raise


def _read_metadata(self, rb) -> None:
    """The connections (their message counts summed over the chunk infos) and the chunk infos, in file order."""
    magic = self.bio.readline().decode(errors="replace")
    if not re.fullmatch(r"#ROSBAG V2\.0\n", magic):
        raise rb.ReaderError("File magic is invalid or the bag version is not 2.0.")
    header = rb.Header.read(self.bio, rb.RecordType.BAGHEADER)
    index_pos, conn_count = header.get_uint64("index_pos"), header.get_uint32("conn_count")
    chunk_count = header.get_uint32("chunk_count")
    if "encryptor" in header and header.get_string("encryptor"):
        raise rb.ReaderError("Bag encryption is not supported.")
    if index_pos == 0:
        raise rb.ReaderError("Bag is not indexed, reindex before reading.")
    size = os.fstat(self.bio.fileno()).st_size
    if index_pos > size:
        raise rb.ReaderError(f"Bag index position {index_pos} lies past the end of the file ({size} bytes).")
    self.bio.seek(index_pos)
    try:
        connections = [self.read_connection() for _ in range(conn_count)]
        self.chunk_infos = sorted((self.read_chunk_info() for _ in range(chunk_count)), key=lambda c: c.pos)
    except rb.ReaderError as err:
        raise rb.ReaderError(f"Bag index looks damaged: {err.args}") from None
    counts: dict[int, int] = {}
    for info in self.chunk_infos:
        for conn, count in info.connection_counts.items():
            counts[conn] = counts.get(conn, 0) + count
    connection = require("rosbags.interfaces", "ros", "reading ROS 1 bags").Connection
    self.connections = [connection(*c[0:5], counts.get(c.id, 0), *c[6:]) for c in connections]
    self.indexes = {}


def _messages(self, connections=(), start: int | None = None, stop: int | None = None):
    """The messages of ``connections`` (all when empty), chunk by chunk in file order: (connection, time [ns],
    raw bytes); ``start`` and ``stop`` [ns] keep those from ``start`` to before ``stop``."""
    rb = _rosbag1()
    self._check_open()
    connmap = {c.id: c for c in self.connections}
    wanted = {c.id for c in connections} if connections else set(connmap)
    for info in self.chunk_infos:
        hits = sum(info.connection_counts.get(c, 0) for c in wanted)
        if not hits:
            continue
        if (start is not None and info.end_time <= start) or (stop is not None and info.start_time >= stop):
            continue
        self.bio.seek(info.pos)
        chunk = self.read_chunk()
        if chunk.decompressor is rb.decompressors["none"] and hits * SPARSE <= sum(info.connection_counts.values()):
            found = _indexed_messages(self, rb, chunk, len(info.connection_counts), connmap, wanted, (start, stop))
            if found is not None:
                yield from found
                continue
        data, index = _chunk_data(self, rb, chunk, len(info.connection_counts))
        yield from _chunk_messages(rb, data, connmap, wanted, (start, stop), index)


#: a chunk whose messages of the topics read are at most one in this many is read where its index says
#: (uncompressed), in a ROS 1 bag and in an MCAP file (:mod:`gyrocomp.io.mcap_chunks`) alike
SPARSE = 16
_INDEX_ENTRY = np.dtype([("sec", "<u4"), ("nsec", "<u4"), ("offset", "<u4")])


def _indexed_messages(self, rb, chunk, connections: int, connmap: dict, wanted: set, span: tuple) -> list | None:
    """The messages of ``wanted`` in an uncompressed chunk read where the chunk's index data records (which follow
    it, one per connection in it: a time and an offset per message) say they lie, instead of walking every record
    of the chunk (a temperature topic at 1 Hz among IMU messages at 1 kHz); each record read is checked against its
    index entry. None where the index does not hold or does not match: the chunk is then walked."""
    start, stop = span
    found = []
    self.bio.seek(chunk.datapos + chunk.datasize)
    index = _index_entries(self, rb, connections)
    if index is None:
        return None
    for conn, entries in index:
        if conn in wanted:
            found += [(int(o), conn, int(t)) for o, t in zip(entries["offset"].tolist(), _times(entries).tolist())]
    try:
        messages = []
        for offset, conn, time in sorted(found):  # the chunk's order
            if (start is not None and time < start) or (stop is not None and time >= stop):
                continue
            if not 0 <= offset <= chunk.datasize - 8:
                return None
            self.bio.seek(chunk.datapos + offset)
            length = rb.read_uint32(self.bio)
            head = rb.read_bytes(self.bio, length)
            raw = rb.read_bytes(self.bio, rb.read_uint32(self.bio))
            if offset + 8 + length + len(raw) > chunk.datasize or conn not in connmap:
                return None
            if _fields_of(head, 0, length) != (rb.RecordType.MSGDATA, conn, time):
                return None
            messages.append((connmap[conn], time, raw))
    except (rb.ReaderError, struct.error, IndexError, TypeError, ValueError):
        return None
    return messages


_UINT32 = struct.Struct("<I")
_TIME = struct.Struct("<II")
#: the header fields a chunk's records are read by
_FIELDS = (b"op", b"conn", b"time")


def _chunk_messages(rb, data: bytes, connmap: dict, wanted: set, span: tuple, index: list | None = None):
    """The message-data records of one decompressed chunk, in their order, as (connection, time [ns], raw bytes).

    The records are walked by their two lengths (:func:`_records`); their header fields (``op``, ``conn``,
    ``time``) are then read for all records of one header layout at once (:func:`_header_fields`; rosbags'
    :class:`Header` makes a dict of every record's, the reading of a long bag), or found where the chunk's
    ``index`` says (:func:`_chunk_arrays`). A record that runs past the chunk is a ReaderError."""
    conn, time, data_at, data_length = _chunk_arrays(rb, data, connmap, wanted, span, index)
    for k in range(conn.size):
        yield connmap[int(conn[k])], int(time[k]), data[data_at[k] : data_at[k] + data_length[k]]


def _chunk_arrays(
    rb, data: bytes, connmap: dict, wanted: set, span: tuple, index: list | None = None
) -> tuple[np.ndarray, ...]:
    """The message-data records of one decompressed chunk that :func:`_chunk_messages` yields, as arrays: their
    connection ids, times [ns], and where each one's data starts in ``data`` and its length [bytes]. With the
    chunk's ``index`` (:func:`_index_entries`) the records are found where it says (:func:`_located`), else
    walked."""
    start, stop = span
    located = _located(rb, data, index) if index is not None else None
    try:
        if located is None:
            records = _records(rb, data)
            located = (*records, *_header_fields(np.frombuffer(data, dtype=np.uint8), data, *records[:2]))
    except (struct.error, IndexError, TypeError, ValueError) as err:
        raise rb.ReaderError(f"A damaged record in a chunk ({type(err).__name__}: {err}).") from None
    records, (op, conn, time) = located[:4], located[4:]
    message = op == rb.RecordType.MSGDATA
    unknown = message & ~among(conn, connmap)
    if np.any(unknown):
        raise rb.ReaderError(f"A message of connection {int(conn[np.argmax(unknown)])}, which the bag's index lacks.")
    keep = message & among(conn, wanted)
    if start is not None:
        keep &= time >= start
    if stop is not None:
        keep &= time < stop
    chosen = np.flatnonzero(keep)
    return conn[chosen], time[chosen], records[2][chosen], records[3][chosen]


def _message_arrays(self, connections=()):
    """The messages of ``connections`` (all when empty) chunk by chunk in file order, each chunk as arrays: its
    decompressed bytes (uint8), and of its messages the connection ids, times [ns], where each one's data starts and
    its length [bytes] (:func:`_chunk_arrays`), as :class:`ChunkArrays`: a caller that decodes many messages at once
    reads them without a Python object per message. The file is read ahead by a thread of its own
    (:class:`~gyrocomp.io.read_ahead.ReadAhead`)."""
    rb = _rosbag1()
    self._check_open()
    connmap = {c.id: c for c in self.connections}
    wanted = {c.id for c in connections} if connections else set(connmap)
    with ReadAhead(self.path) as ahead:  # the disk reads on while a chunk is decoded
        for info in self.chunk_infos:
            if not wanted.intersection(info.connection_counts):
                continue
            ahead.at(info.pos)
            self.bio.seek(info.pos)
            chunk = self.read_chunk()
            data, index = _chunk_data(self, rb, chunk, len(info.connection_counts))
            yield ChunkArrays(
                np.frombuffer(data, dtype=np.uint8),
                chunk.datapos,
                *_chunk_arrays(rb, data, connmap, wanted, (None, None), index),
            )


def _chunk_data(self, rb, chunk, connections: int) -> tuple[bytes, list | None]:
    """A chunk's decompressed bytes and the index data records that follow it (:func:`_index_entries`, one per
    connection in it; None where they do not read)."""
    self.bio.seek(chunk.datapos)
    data = bytes(chunk.decompressor(rb.read_bytes(self.bio, chunk.datasize)))
    return data, _index_entries(self, rb, connections)


def _index_entries(self, rb, connections: int) -> list | None:
    """The index data records at the reader's place (those that follow a chunk, one per connection in it): each
    connection's (id, entries: time sec, nsec, offset in the uncompressed chunk); None where they do not read."""
    out = []
    try:
        for _ in range(connections):
            header = rb.Header.read(self.bio, rb.RecordType.IDXDATA)
            conn, count = header.get_uint32("conn"), header.get_uint32("count")
            entries = np.frombuffer(rb.read_bytes(self.bio, rb.read_uint32(self.bio)), dtype=_INDEX_ENTRY)
            if header.get_uint32("ver") != 1 or entries.size != count:
                return None
            out.append((conn, entries))
    except (rb.ReaderError, struct.error, IndexError, TypeError, ValueError):
        return None
    return out


def _times(entries: np.ndarray) -> np.ndarray:
    """Index entries' times [ns] from their sec and nsec."""
    return entries["sec"].astype(np.int64) * 1_000_000_000 + entries["nsec"]


def _located(rb, data: bytes, index: list) -> tuple | None:
    """A chunk's records found where its index data say the messages lie instead of walked: (header start, header
    length, data start, data length, op, conn, time [ns]) of each record in the chunk's order, as :func:`_records`
    and :func:`_header_fields` give them. The records between the messages (a connection record) are walked;
    every message must lie where its entry says with its entry's connection and time, the records must tile the
    chunk, and no message may be missing from the index: else None (the chunk is then walked)."""
    try:
        offsets = np.concatenate([e["offset"] for _, e in index]).astype(np.int64)
        conns = np.concatenate([np.full(e.size, c, dtype=np.int64) for c, e in index])
        times = np.concatenate([_times(e) for _, e in index])
        order = np.argsort(offsets, kind="stable")
        offsets, conns, times = offsets[order], conns[order], times[order]
        size, array = len(data), np.frombuffer(data, dtype=np.uint8)
        if offsets.size == 0 or offsets[-1] + 8 > size:
            return None
        places = Places(array, offsets)
        header_length = places.read(0, "<u4").astype(np.int64)
        if np.any(offsets + 8 + header_length > size):
            return None
        if np.all(header_length == header_length[0]):
            data_length = places.read(4 + int(header_length[0]), "<u4").astype(np.int64)
        else:
            data_length = sliding_window_view(array, 4)[offsets + 4 + header_length].view("<u4")[:, 0].astype(np.int64)
        ends = offsets + 8 + header_length + data_length
        if ends[-1] > size or np.any(ends[:-1] > offsets[1:]):
            return None
        # (header start, header length, data start, data length, listed in the index)
        listed = np.ones(offsets.size, dtype=np.int64)
        parts = [np.column_stack([offsets + 4, header_length, offsets + 8 + header_length, data_length, listed])]
        gap_starts, gap_stops = np.r_[0, ends], np.r_[offsets, size]
        between = gap_starts < gap_stops
        for a, b in zip(gap_starts[between].tolist(), gap_stops[between].tolist()):
            walked = np.column_stack(_records(rb, data[a:b]))
            parts.append(np.column_stack([walked + np.array([a, 0, a, 0]), np.zeros(len(walked), np.int64)]))
        table = np.concatenate(parts)
        if len(parts) > 1:
            table = table[np.argsort(table[:, 0], kind="stable")]
        listed = table[:, 4].astype(bool)
        op, conn, time = (np.full(len(table), -1, dtype=np.int64) for _ in range(3))
        rest = ~listed
        if _as_indexed(rb, places, data, header_length, conns, times):
            op[listed], conn[listed], time[listed] = rb.RecordType.MSGDATA, conns, times
        else:
            rest[:] = True
        if rest.any():
            op[rest], conn[rest], time[rest] = _header_fields(array, data, table[rest, 0], table[rest, 1])
    except (rb.ReaderError, struct.error, IndexError, TypeError, ValueError):
        return None
    if np.any(op[~listed] == rb.RecordType.MSGDATA):
        return None  # a message the index does not list
    if not (np.all(op[listed] == rb.RecordType.MSGDATA) and np.array_equal(conn[listed], conns)):
        return None
    if not np.array_equal(time[listed], times):
        return None
    return table[:, 0], table[:, 1], table[:, 2], table[:, 3], op, conn, time


def _as_indexed(rb, places: Places, data: bytes, header_length, conns, times) -> bool:
    """Whether the records at ``places`` (:class:`~gyrocomp.io.byte_fields.Places` of the chunk) share one header
    length and their ``op``, ``conn`` and ``time`` values, read at the places the first record's header gives them
    (:func:`_field_places`), are a message's with the index entries' connections ``conns`` and times ``times``
    [ns]: three small reads per record instead of its whole header (:func:`_header_fields`). A header of another
    layout of the same length would put other bytes there and not match."""
    if np.any(header_length != header_length[0]):
        return False
    first = int(places.at[0]) + 4
    found = _field_places(data, first, first + int(header_length[0]))
    if [found.get(name, (0, -1))[1] for name in _FIELDS] != [1, 4, 8]:
        return False
    if np.any(places.read(4 + found[b"op"][0], np.uint8) != rb.RecordType.MSGDATA):
        return False
    if not np.array_equal(places.read(4 + found[b"conn"][0], "<u4"), conns):
        return False
    sec_nsec = places.read(4 + found[b"time"][0], "<u4", 2).astype(np.int64)
    return bool(np.array_equal(sec_nsec[:, 0] * 1_000_000_000 + sec_nsec[:, 1], times))


class ChunkArrays(NamedTuple):
    """One chunk's messages as arrays (:meth:`ChunkedReader1.message_arrays`, and an MCAP file's:
    :func:`gyrocomp.io.mcap_chunks.mcap_arrays`; a batch of a sqlite3 bag's rows:
    :func:`gyrocomp.io.rosbag2_sqlite.sqlite_arrays`)."""

    data: np.ndarray  # the decompressed chunk's bytes (uint8)
    data_pos: int  # where the chunk's data lie in the file [bytes] (their place, when uncompressed)
    conn: np.ndarray  # each message's connection id (an MCAP file's channel id)
    time: np.ndarray  # each message's time [ns]
    data_at: np.ndarray  # where each message's data start in ``data`` [bytes]
    data_length: np.ndarray  # and their length [bytes]
    ids: np.ndarray | None = None  # each message's row id (a sqlite3 bag's: :mod:`gyrocomp.io.rosbag2_sqlite`)


#: records walked one by one after a run of fewer than this many of one shape, before trying runs again
_WALK = 32


def _records(rb, data: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Each record of a chunk: where its header starts and its length, where its data starts and its length
    [bytes].

    A record's lengths say where the next one starts. A chunk of IMU messages is mostly records of one shape (one
    header length, one data length) one after the other: from each record, the records of its shape that follow
    are found at once (:func:`_same_shape`, each checked at its place), the others walked one by one."""
    array = np.frombuffer(data, dtype=np.uint8)
    size, pos, walk = len(data), 0, 0
    parts, single = [], []
    while pos < size:
        (length,) = _UINT32.unpack_from(data, pos)
        end = pos + 4 + length
        if end + 4 > size:
            raise rb.ReaderError("A record's header runs past the end of its chunk.")
        (count,) = _UINT32.unpack_from(data, end)
        if end + 4 + count > size:
            raise rb.ReaderError("A record's data runs past the end of its chunk.")
        run = 1 if walk else _same_shape(array, pos, length, count)
        if run == 1:
            single.append((pos, length, count))
            walk = walk - 1 if walk else _WALK
        else:
            if single:
                parts.append(np.array(single, dtype=np.int64).reshape(-1, 3))
                single = []
            starts = pos + (8 + length + count) * np.arange(run, dtype=np.int64)
            parts.append(np.column_stack([starts, np.full(run, length), np.full(run, count)]))
        pos += run * (8 + length + count)
    if single:
        parts.append(np.array(single, dtype=np.int64).reshape(-1, 3))
    table = np.concatenate(parts) if parts else np.empty((0, 3), dtype=np.int64)
    header_at = table[:, 0] + 4
    return header_at, table[:, 1], header_at + table[:, 1] + 4, table[:, 2]


def _same_shape(array: np.ndarray, pos: int, length: int, count: int) -> int:
    """How many records from ``pos`` on, one after the other, have the header length ``length`` and the data length
    ``count`` of the record at ``pos`` (at least that one): each candidate's two lengths read at its place, the run
    ending at the first that differs or at the end of the chunk (looked at in windows that double, so that a short
    run costs little whatever the chunk's size)."""
    total = 8 + length + count
    fits = (array.size - pos) // total
    checked, window = 1, 1024
    while checked < fits:
        starts = pos + total * np.arange(checked, min(fits, checked + window), dtype=np.int64)
        words = sliding_window_view(array, 4)  # the four bytes from each offset, read where asked
        lengths = words[starts].view("<u4")[:, 0]
        counts = words[starts + 4 + length].view("<u4")[:, 0]
        same = (lengths == length) & (counts == count)
        if not same.all():
            return checked + int(np.argmin(same))
        checked, window = checked + starts.size, window * 2
    return max(fits, 1)


def _header_fields(array: np.ndarray, data: bytes, header_at: np.ndarray, header_length: np.ndarray) -> tuple:
    """Each record's ``op`` (-1 where absent), ``conn`` (-1) and ``time`` [ns] (-1): the records whose headers have
    one length and the same bytes as the first of them but for these three values are read as one array; any other
    record field by field (:func:`_fields_of`)."""
    n = len(header_at)
    op, conn, time = np.full(n, -1, np.int64), np.full(n, -1, np.int64), np.full(n, -1, np.int64)
    starts, lengths = np.asarray(header_at, dtype=np.int64), np.asarray(header_length, dtype=np.int64)
    for length in np.unique(lengths).tolist():
        group = np.flatnonzero(lengths == length)
        first = int(starts[group[0]])
        places = _field_places(data, first, first + length)
        headers = sliding_window_view(array, length)[starts[group]] if length else np.empty((group.size, 0), np.uint8)
        fixed = np.ones(length, dtype=bool)
        for at, width in places.values():
            fixed[at : at + width] = False
        same = np.all(headers[:, fixed] == headers[0, fixed], axis=1)
        if any(places.get(name, (0, width))[1] != width for name, width in zip(_FIELDS, (1, 4, 8))):
            same[:] = False  # a value of another width: read as it is (and refused as a field-by-field reading does)
        if b"op" in places:
            op[group[same]] = headers[same, places[b"op"][0]]
        if b"conn" in places:
            at = places[b"conn"][0]
            conn[group[same]] = np.ascontiguousarray(headers[same, at : at + 4]).view("<u4")[:, 0]
        if b"time" in places:
            at = places[b"time"][0]
            sec_nsec = np.ascontiguousarray(headers[same, at : at + 8]).view("<u4").astype(np.int64)
            time[group[same]] = sec_nsec[:, 0] * 1_000_000_000 + sec_nsec[:, 1]
        for k in group[~same].tolist():  # another layout: read as it is
            op[k], conn[k], time[k] = _fields_of(data, int(header_at[k]), int(header_at[k] + header_length[k]))
    return op, conn, time


def _field_places(data: bytes, pos: int, end: int) -> dict[bytes, tuple[int, int]]:
    """Where in a header (from ``pos`` to ``end``) the values of ``op``, ``conn`` and ``time`` lie: their offset from
    the header's start and their length [bytes]."""
    places, start = {}, pos
    while pos < end:
        (field,) = _UINT32.unpack_from(data, pos)
        name, sign, _ = data[pos + 4 : pos + 4 + field].partition(b"=")
        if name in _FIELDS and sign:  # a field given twice: its last value, as a field-by-field reading takes
            places[name] = (pos + 4 + len(name) + 1 - start, field - len(name) - 1)
        pos += 4 + field
    if pos != end:
        raise ValueError("a header field runs past its header")
    return places


def _fields_of(data: bytes, pos: int, end: int) -> tuple[int, int, int]:
    """One header's ``op``, ``conn`` and ``time`` [ns] read field by field (-1 where absent)."""
    op = conn = time = -1
    while pos < end:
        (field,), pos = _UINT32.unpack_from(data, pos), pos + 4
        name, _, value = data[pos : pos + field].partition(b"=")
        pos += field
        if name == b"op":
            op = value[0]
        elif name == b"conn":
            conn = _UINT32.unpack(value)[0]
        elif name == b"time":
            sec, nsec = _TIME.unpack(value)
            time = sec * 1_000_000_000 + nsec
    return op, conn, time


@functools.cache
def chunked_reader1() -> type:
    """``ChunkedReader1``: a :class:`rosbags.rosbag1.Reader` without the per-message index (see the module), the
    same connections (with their message counts), messages yielded chunk by chunk in file order; made on first
    use (rosbags is an optional extra)."""
    return type(
        "ChunkedReader1",
        (_rosbag1().Reader,),
        {"open": _open, "messages": _messages, "message_arrays": _message_arrays, "__doc__": chunked_reader1.__doc__},
    )


def _write_chunk(self, chunk) -> None:
    """rosbags' ``write_chunk``, then the chunk's index entries (a time and an offset per message, kept until the
    bag is closed) replaced by their counts, all that closing the bag reads of them."""
    _rosbag1_writer().Writer.write_chunk(self, chunk)
    if chunk.pos != -1:
        chunk.connections = {conn: range(len(items)) for conn, items in chunk.connections.items()}


def _rosbag1_writer():
    return require("rosbags.rosbag1.writer", "ros", "writing ROS 1 bags")


@functools.cache
def lean_writer1() -> type:
    """``LeanWriter1``: a :class:`rosbags.rosbag1.Writer` that keeps of each written chunk only its message counts
    (rosbags' keeps an index entry of every message until it closes the bag: 5.6 GB for ten hours of IMU messages at
    1 kHz); the bag it writes is rosbags' byte for byte."""
    return type(
        "LeanWriter1", (_rosbag1_writer().Writer,), {"write_chunk": _write_chunk, "__doc__": lean_writer1.__doc__}
    )


__all__ = ["SPARSE", "ChunkArrays", "chunked_reader1", "lean_writer1"]
