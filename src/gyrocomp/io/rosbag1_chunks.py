"""rosbags' ROS 1 bag reader, reading a bag chunk by chunk in memory bounded by a chunk (extra ``[ros]``).

rosbags' :class:`rosbags.rosbag1.Reader` reads an index entry of every message when it opens a bag (measured: about
155 bytes a message, 5.6 GB for a ten-hour IMU topic at 1 kHz), so that it can yield the messages of several
connections merged in time order. A ROS 1 bag's chunks follow each other in time, and within a chunk its messages in
the order they were recorded: :class:`ChunkedReader1` opens a bag from its connection and chunk-info records only
(the per-connection message counts come from the chunk infos) and yields the messages chunk by chunk as they lie in
the file, each chunk decompressed (none, bz2, lz4) when it is reached. The records are parsed by rosbags' own
functions; everything else (connections, message definitions, the type store of :class:`rosbags.highlevel.AnyReader`)
is rosbags' as it is.

The ROS 1 bag format (version 2.0): records of a header (``op``, ``conn``, ``time``, ...) and data; chunks hold
connection and message-data records; after the chunks, at the bag header's ``index_pos``, the connection records and
one chunk-info record per chunk (its position and its message count per connection).
"""

from __future__ import annotations

import functools
import os
import re
from io import BytesIO

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
        yield from _chunk_messages(rb, BytesIO(data), len(data), connmap, wanted, (start, stop))


def _chunk_messages(rb, chunk: BytesIO, size: int, connmap: dict, wanted: set, span: tuple):
    """The message-data records of one decompressed chunk, in their order."""
    start, stop = span
    while chunk.tell() < size:
        header = rb.Header.read(chunk)
        length = rb.read_uint32(chunk)
        if header.get_uint8("op") == rb.RecordType.MSGDATA:
            conn = header.get_uint32("conn")
            if conn in wanted:
                time = header.get_time("time")
                if (start is None or time >= start) and (stop is None or time < stop):
                    if conn not in connmap:
                        raise rb.ReaderError(f"A message of connection {conn}, which the bag's index lacks.")
                    yield connmap[conn], time, rb.read_bytes(chunk, length)
                    continue
        chunk.seek(length, os.SEEK_CUR)


@functools.cache
def chunked_reader1() -> type:
    """``ChunkedReader1``: a :class:`rosbags.rosbag1.Reader` without the per-message index (see the module), the
    same connections (with their message counts), messages yielded chunk by chunk in file order; made on first
    use (rosbags is an optional extra)."""
    return type("ChunkedReader1", (_rosbag1().Reader,), {"open": _open, "messages": _messages,
                                                          "__doc__": chunked_reader1.__doc__})


__all__ = ["chunked_reader1"]
