"""rosbags' ROS 1 bag reader and writer, in memory bounded by a chunk whatever the bag's length (extra ``[ros]``).

rosbags' :class:`rosbags.rosbag1.Reader` reads an index entry of every message when it opens a bag (measured: about
155 bytes a message, 5.6 GB for a ten-hour IMU topic at 1 kHz), so that it can yield the messages of several
connections merged in time order. A ROS 1 bag's chunks follow each other in time, and within a chunk its messages in
the order they were recorded: :class:`ChunkedReader1` opens a bag from its connection and chunk-info records only
(the per-connection message counts come from the chunk infos) and yields the messages chunk by chunk as they lie in
the file, each chunk decompressed (none, bz2, lz4) when it is reached. The bag's index is read by rosbags' own
functions, a chunk's records by :func:`_chunk_messages` (their three header fields in place); everything else (connections, message definitions, the type store of :class:`rosbags.highlevel.AnyReader`)
is rosbags' as it is.

:func:`lean_writer1`'s writer is rosbags' writer that, once a chunk and its index records are in the file, keeps
only the chunk's message count per connection (what closing the bag writes) instead of an entry per message.

The ROS 1 bag format (version 2.0): records of a header (``op``, ``conn``, ``time``, ...) and data; chunks hold
connection and message-data records; after the chunks, at the bag header's ``index_pos``, the connection records and
one chunk-info record per chunk (its position and its message count per connection).
"""

from __future__ import annotations

import functools
import os
import re
import struct

from .common import require


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
        if not wanted.intersection(info.connection_counts):
            continue
        if (start is not None and info.end_time <= start) or (stop is not None and info.start_time >= stop):
            continue
        self.bio.seek(info.pos)
        chunk = self.read_chunk()
        self.bio.seek(chunk.datapos)
        data = chunk.decompressor(rb.read_bytes(self.bio, chunk.datasize))
        yield from _chunk_messages(rb, bytes(data), connmap, wanted, (start, stop))


_UINT32 = struct.Struct("<I")
_TIME = struct.Struct("<II")


def _chunk_messages(rb, data: bytes, connmap: dict, wanted: set, span: tuple):
    """The message-data records of one decompressed chunk, in their order: each record's header fields (``op``,
    ``conn``, ``time``) read in place with ``struct`` (rosbags' :class:`Header` makes a dict of every record's; this
    is the reading of a long bag), a record that runs past the chunk a ReaderError."""
    start, stop = span
    size, pos = len(data), 0
    try:
        while pos < size:
            (length,), pos = _UINT32.unpack_from(data, pos), pos + 4
            end = pos + length
            if end + 4 > size:
                raise rb.ReaderError("A record's header runs past the end of its chunk.")
            op = conn = time = None
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
            (length,), pos = _UINT32.unpack_from(data, end), end + 4
            if pos + length > size:
                raise rb.ReaderError("A record's data runs past the end of its chunk.")
            if (
                op == rb.RecordType.MSGDATA
                and conn in wanted
                and (start is None or time >= start)
                and (stop is None or time < stop)
            ):
                if conn not in connmap:
                    raise rb.ReaderError(f"A message of connection {conn}, which the bag's index lacks.")
                yield connmap[conn], time, data[pos : pos + length]
            pos += length
    except (struct.error, IndexError, TypeError) as err:
        raise rb.ReaderError(f"A damaged record in a chunk ({type(err).__name__}: {err}).") from None


@functools.cache
def chunked_reader1() -> type:
    """``ChunkedReader1``: a :class:`rosbags.rosbag1.Reader` without the per-message index (see the module), the
    same connections (with their message counts), messages yielded chunk by chunk in file order; made on first
    use (rosbags is an optional extra)."""
    return type(
        "ChunkedReader1",
        (_rosbag1().Reader,),
        {"open": _open, "messages": _messages, "__doc__": chunked_reader1.__doc__},
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


__all__ = ["chunked_reader1", "lean_writer1"]
