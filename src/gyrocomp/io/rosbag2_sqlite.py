"""A ROS 2 sqlite3 bag's messages read in batches of rows as arrays, with their row ids (extra ``[ros]``), for a
caller that writes compensated messages back over their rows (:mod:`gyrocomp.files.bag_patch`).

The rows come from rosbags' own query (``Sqlite3Reader.messages``: the messages of the connections asked for,
``ORDER BY timestamp``) with the row id added, through the reader's database connection, so they come in the order
rosbags yields them; ``rows`` at a time, each batch's data end to end in one byte array
(:class:`~gyrocomp.io.rosbag1_chunks.ChunkArrays`, ``data_pos`` -1: not a place in a file).
"""

from __future__ import annotations

from collections.abc import Iterator
from itertools import islice

import numpy as np

from .foreign_libraries import require
from .rosbag1_chunks import ChunkArrays
from .rosbag2_storage import channel_ids, one_storage

#: messages of a sqlite3 bag taken at once (about 20 MB of IMU messages)
SQLITE_ROWS = 65536


def sqlite_storage(reader):
    """The rosbags sqlite3 reader (open) of the one storage file of the ROS 2 bag folder an open
    :class:`~rosbags.highlevel.AnyReader` reads; None for any other bag (ROS 1, MCAP, several files, messages
    compressed one by one or the file compressed whole)."""
    found = one_storage(reader)
    if found is None or found[1] is None or found[1].compression_mode:
        return None
    sqlite = require("rosbags.rosbag2.storage_sqlite3", "ros", "reading ROS 2 bags").Sqlite3Reader
    return found[0] if isinstance(found[0], sqlite) and found[0].dbconn is not None else None


def sqlite_arrays(storage, connections, rows: int = SQLITE_ROWS) -> Iterator[ChunkArrays]:
    """The messages of ``connections`` (the bag's, matched to the storage's as rosbags matches them) of an open
    rosbags sqlite3 reader, ``rows`` at a time as arrays with their row ids, in the order rosbags yields them."""
    ids = tuple(channel_ids(storage, connections))
    if not ids:
        return
    query = (
        "SELECT topics.id,messages.timestamp,messages.data,messages.id FROM messages JOIN topics ON "
        f"messages.topic_id=topics.id WHERE topics.id IN ({','.join('?' for _ in ids)}) ORDER BY timestamp"
    )
    cursor = storage.dbconn.execute(query, ids)
    while batch := list(islice(cursor, rows)):
        conn, time, data, row = zip(*batch)
        length = np.fromiter(map(len, data), dtype=np.int64, count=len(data))
        at = np.zeros(length.size, dtype=np.int64)
        np.cumsum(length[:-1], out=at[1:])
        yield ChunkArrays(
            np.frombuffer(b"".join(data), dtype=np.uint8),
            -1,
            np.array(conn, dtype=np.int64),
            np.array(time, dtype=np.int64),
            at,
            length,
            np.array(row, dtype=np.int64),
        )


__all__ = ["SQLITE_ROWS", "sqlite_arrays", "sqlite_storage"]
