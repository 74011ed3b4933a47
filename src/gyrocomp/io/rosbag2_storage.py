"""The storage file under rosbags' reader of a ROS 2 bag (a bag folder's one file, or a bare ``.mcap``), for the
readers of this package that read a storage's bytes or rows themselves (:mod:`gyrocomp.io.mcap_chunks`,
:mod:`gyrocomp.io.rosbag2_sqlite`), and a storage's ids of the bag's connections (extra ``[ros]``).

rosbags' :class:`rosbags.highlevel.AnyReader` reads a ROS 2 bag through its :class:`rosbags.rosbag2.Reader`, whose
storage is a folder's reader (its files' readers, read one after the other, its connections from ``metadata.yaml``)
or, for a bare ``.mcap``, the MCAP reader itself.
"""

from __future__ import annotations

from .foreign_libraries import require


def one_storage(reader):
    """(the storage reader of the one storage file, the bag folder's metadata or None for a bare file) of an open
    :class:`~rosbags.highlevel.AnyReader` of one ROS 2 bag; None for a ROS 1 bag, several bags, or a folder of
    several files."""
    readers = getattr(reader, "readers", ())
    if not getattr(reader, "is2", False) or len(readers) != 1:
        return None
    storage = readers[0].storage
    if not isinstance(storage, require("rosbags.rosbag2.reader", "ros", "reading ROS 2 bags").DirectoryReader):
        return storage, None
    return (storage.storages[0], storage.metadata) if len(storage.storages) == 1 else None


def channel_ids(storage, connections) -> set[int]:
    """A storage's ids of ``connections`` (a bag folder's connections come from its ``metadata.yaml``: they are
    matched to the storage's own as rosbags matches them, by topic, type, serialization and digest)."""
    return {
        x.id
        for x in storage.connections
        for y in connections
        if y.topic == x.topic
        and y.msgtype == x.msgtype
        and y.ext == x.ext
        and (not x.digest or not y.digest or y.digest == x.digest)
    }


def topic_ids(storage, connections) -> dict[int, str]:
    """The storage's id -> topic of each of ``connections`` (:func:`channel_ids`)."""
    return {i: c.topic for c in connections for i in channel_ids(storage, [c])}


__all__ = ["channel_ids", "one_storage", "topic_ids"]
