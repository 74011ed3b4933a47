"""The ROS 1 bag reader that reads chunk by chunk: the same connections, message counts and messages as rosbags'
own reader, for uncompressed, bz2 and lz4 chunks, many chunks, a filter on connections and times; and its memory
does not hold an index entry per message."""

from __future__ import annotations

import io
import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp.io import rosbag1_chunks as chunks_module
from gyrocomp.io.rosbag1_chunks import _chunk_messages, chunked_reader1, lean_writer1

pytest.importorskip("rosbags", reason="bags need the [ros] extra (rosbags)")
from rosbags.rosbag1 import Reader, ReaderError, Writer  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

STORE = get_typestore(Stores.ROS1_NOETIC)


def _bag(path, compression=None, n=600, writer_class=Writer, every=3, threshold=4096):
    """Two topics of strings, messages of 40 to 100 bytes on /a and one in ``every`` on /b, chunks of about
    ``threshold`` bytes (many chunks)."""
    writer = writer_class(path)
    if compression:
        writer.set_compression(compression)
    writer.chunk_threshold = threshold
    string = STORE.types["std_msgs/msg/String"]
    with writer:
        a = writer.add_connection("/a", "std_msgs/msg/String", typestore=STORE)
        b = writer.add_connection("/b", "std_msgs/msg/String", typestore=STORE)
        for i in range(n):
            writer.write(
                a,
                1_000_000_000 + 10_000_000 * i,
                STORE.serialize_ros1(string(data="x" * (40 + i % 60)), "std_msgs/msg/String"),
            )
            if i % every == 0:
                writer.write(
                    b,
                    1_000_000_000 + 10_000_000 * i + 5,
                    STORE.serialize_ros1(string(data=str(i)), "std_msgs/msg/String"),
                )
    return path, writer


def _index_entries_at(path, chunk: int, topic: str) -> int:
    """Where in the file the index entries (time sec, nsec, offset: 12 bytes each) of ``topic`` in chunk number
    ``chunk`` start (the chunk's index data records follow it, one per connection in it)."""
    rosbag1 = pytest.importorskip("rosbags.rosbag1.reader")
    with chunked_reader1()(path) as reader:
        (conn,) = [c.id for c in reader.connections if c.topic == topic]
        info = reader.chunk_infos[chunk]
        reader.bio.seek(info.pos)
        found = reader.read_chunk()
        reader.bio.seek(found.datapos + found.datasize)
        for _ in info.connection_counts:
            header = rosbag1.Header.read(reader.bio, rosbag1.RecordType.IDXDATA)
            size, entries = rosbag1.read_uint32(reader.bio), reader.bio.tell()
            if header.get_uint32("conn") == conn:
                return entries
            reader.bio.seek(entries + size)
    raise AssertionError(f"no index entries of {topic} in chunk {chunk}")


def _read(reader_class, path, **kwargs):
    with reader_class(path) as reader:
        connections = [(c.id, c.topic, c.msgtype, c.digest, c.msgcount) for c in reader.connections]
        chosen = [c for c in reader.connections if c.topic in kwargs.pop("topics", (c.topic,))]
        messages = [(c.topic, t, bytes(raw)) for c, t, raw in reader.messages(connections=chosen, **kwargs)]
    return connections, messages


@pytest.mark.parametrize(
    "compression", [None, Writer.CompressionFormat.BZ2, Writer.CompressionFormat.LZ4], ids=["none", "bz2", "lz4"]
)
def test_the_chunked_reader_reads_what_rosbags_reads(compression, tmp_path):
    path, _ = _bag(tmp_path / "in.bag", compression)
    ours, theirs = _read(chunked_reader1(), path), _read(Reader, path)
    assert ours[0] == theirs[0] and ours[0][0][4] == 600 and ours[0][1][4] == 200
    assert ours[1] == theirs[1]  # one chunk after the other is the time order of a bag written in time order
    with chunked_reader1()(path) as reader:
        assert len(reader.chunk_infos) > 20 and not reader.indexes  # many chunks, no index of the messages
    for kwargs in ({"topics": ("/b",)}, {"start": 1_500_000_000, "stop": 3_000_000_000}):
        assert _read(chunked_reader1(), path, **dict(kwargs))[1] == _read(Reader, path, **dict(kwargs))[1]


def test_a_damaged_or_foreign_file_is_a_reader_error(tmp_path):
    path, _ = _bag(tmp_path / "in.bag")
    data = path.read_bytes()
    (tmp_path / "cut.bag").write_bytes(data[: len(data) // 2])
    (tmp_path / "other.bag").write_bytes(b"#ROSBAG V1.2\n" + data[13:])
    for name, message in (
        ("cut.bag", r"index position .* lies past the end|damaged"),
        ("other.bag", r"magic is invalid or the bag version is not 2\.0"),
    ):
        with pytest.raises(ReaderError, match=message), chunked_reader1()(tmp_path / name) as reader:
            list(reader.messages())


@pytest.mark.parametrize("compression", [None, Writer.CompressionFormat.LZ4], ids=["none", "lz4"])
def test_the_lean_writer_writes_rosbags_bytes_and_keeps_counts_only(compression, tmp_path):
    theirs, _ = _bag(tmp_path / "theirs.bag", compression)
    ours, writer = _bag(tmp_path / "ours.bag", compression, writer_class=lean_writer1())
    assert ours.read_bytes() == theirs.read_bytes()
    written = [c for c in writer.chunks if c.pos != -1]
    assert len(written) > 20 and all(isinstance(entries, range) for c in written for entries in c.connections.values())


def _record(fields: list[tuple[bytes, bytes]], payload: bytes) -> bytes:
    """One ROS 1 record: its header's fields (``name=value``, each after its length), then its data."""
    header = b"".join(struct.pack("<I", len(name) + 1 + len(value)) + name + b"=" + value for name, value in fields)
    return struct.pack("<I", len(header)) + header + struct.pack("<I", len(payload)) + payload


def _message(conn: int, sec: int, nsec: int, payload: bytes, order=(0, 1, 2), extra=()) -> bytes:
    fields = [(b"op", b"\x02"), (b"conn", struct.pack("<I", conn)), (b"time", struct.pack("<II", sec, nsec))]
    return _record([fields[k] for k in order] + list(extra), payload)


@given(
    layouts=st.lists(
        st.tuples(
            st.integers(0, 3),  # connection
            st.integers(0, 2**31),  # seconds
            st.integers(0, 999_999_999),  # nanoseconds
            st.sampled_from([(0, 1, 2), (2, 0, 1), (1, 2, 0)]),  # field order: one header length, other layouts
            st.sampled_from([(), ((b"x", b"ab"),), ((b"x", b"cd"),), ((b"conn", b"\x03\x00\x00\x00"),)]),
            st.binary(max_size=12),
        ),
        max_size=40,
    ),
    wanted=st.sets(st.integers(0, 3)),
)
@settings(max_examples=80, deadline=None)
def test_a_chunks_records_are_read_as_field_by_field_whatever_their_header_layouts(layouts, wanted):
    """Records whose headers share one length but not one layout (fields in another order, an extra field whose
    value changes, a field given twice) are read as rosbags' own header parser reads each record (the last value of a
    field given twice); connection records between them are passed over."""
    reader = pytest.importorskip("rosbags.rosbag1.reader")
    chunk = _record([(b"op", b"\x07"), (b"conn", b"\x00\x00\x00\x00"), (b"topic", b"/t")], b"definition")
    for conn, sec, nsec, order, extra, payload in layouts:
        chunk += _message(conn, sec, nsec, payload, order, extra)
    connmap = {c: f"connection {c}" for c in range(4)}
    ours = [(c, t, bytes(raw)) for c, t, raw in _chunk_messages(reader, chunk, connmap, wanted, (None, None))]
    theirs, source = [], io.BytesIO(chunk)
    while source.tell() < len(chunk):
        header = reader.Header.read(source)
        raw = reader.read_bytes(source, reader.read_uint32(source))
        if header.get_uint8("op") == reader.RecordType.MSGDATA and header.get_uint32("conn") in wanted:
            sec, nsec = struct.unpack("<II", header["time"])
            theirs.append((connmap[header.get_uint32("conn")], sec * 1_000_000_000 + nsec, raw))
    assert ours == theirs


@given(
    layouts=st.lists(
        st.tuples(
            st.integers(0, 3),
            st.integers(0, 2**31),
            st.integers(0, 999_999_999),
            st.sampled_from([(0, 1, 2), (2, 0, 1), (1, 2, 0)]),
            st.sampled_from([(), ((b"x", b"ab"),), ((b"conn", b"\x03\x00\x00\x00"),)]),
            st.binary(max_size=12),
            st.booleans(),  # a connection record before the message
        ),
        min_size=1,
        max_size=30,
    )
)
@settings(max_examples=60, deadline=None)
def test_records_found_by_the_index_are_those_a_walk_finds(layouts):
    """A chunk of messages of several header layouts with connection records between them, and its index data
    (each message's connection, time and offset): the records found where the index says, the connection records
    walked, are the walk's, field for field."""
    import numpy as np

    reader = pytest.importorskip("rosbags.rosbag1.reader")
    chunk, entries = b"", {}
    for conn, sec, nsec, order, extra, payload, connection_first in layouts:
        if connection_first:
            chunk += _record([(b"op", b"\x07"), (b"conn", struct.pack("<I", conn)), (b"topic", b"/t")], b"def")
        effective = 3 if extra and extra[0][0] == b"conn" else conn  # a field given twice: its last value
        entries.setdefault(effective, []).append((sec, nsec, len(chunk)))
        chunk += _message(conn, sec, nsec, payload, order, extra)
    index = [(c, np.array(e, dtype=chunks_module._INDEX_ENTRY)) for c, e in entries.items()]
    located = chunks_module._located(reader, chunk, index)
    records = chunks_module._records(reader, chunk)
    walked = (*records, *chunks_module._header_fields(np.frombuffer(chunk, np.uint8), chunk, *records[:2]))
    assert located is not None
    assert all(np.array_equal(a, b) for a, b in zip(located, walked))


def test_a_message_of_a_connection_the_index_lacks_is_a_reader_error():
    reader = pytest.importorskip("rosbags.rosbag1.reader")
    chunk = _message(0, 1, 0, b"a") + _message(5, 2, 0, b"b")
    with pytest.raises(reader.ReaderError, match=r"A message of connection 5, which the bag's index lacks"):
        list(_chunk_messages(reader, chunk, {0: "connection 0"}, {0}, (None, None)))


@pytest.mark.parametrize(
    "compression", [None, Writer.CompressionFormat.BZ2, Writer.CompressionFormat.LZ4], ids=["none", "bz2", "lz4"]
)
def test_a_sparse_topic_is_read_by_the_chunks_index_as_rosbags_reads_it(compression, tmp_path, monkeypatch):
    """A topic of one message in fifty (a temperature at 1 Hz beside an IMU at 50 Hz, say): an uncompressed chunk's
    messages of it are read where the chunk's index data say (each checked against its entry), the same messages
    as rosbags' reader, with a time filter too; a chunk whose index entry points at another record is walked."""
    path, _ = _bag(tmp_path / "sparse.bag", compression, n=3000, every=50, threshold=16384)
    indexed = []  # what each indexed read of a chunk gave: its messages, or None (the chunk then walked)
    original = chunks_module._indexed_messages
    monkeypatch.setattr(chunks_module, "_indexed_messages", lambda *a: indexed.append(original(*a)) or indexed[-1])
    topic = {"topics": ("/b",)}
    for kwargs in (topic, {**topic, "start": 2 * 10**10, "stop": 4 * 10**10}):
        ours = _read(chunked_reader1(), path, **dict(kwargs))[1]
        assert ours == _read(Reader, path, **dict(kwargs))[1] and ours
    # uncompressed: every chunk read by its index; compressed: none (a chunk is decompressed whole)
    assert (len(indexed) > 10 and all(m is not None for m in indexed)) if compression is None else not indexed
    if compression is None:  # the second chunk's first index entry of the topic given another time
        data = bytearray(path.read_bytes())
        entries = _index_entries_at(path, 1, "/b")
        (sec,) = struct.unpack_from("<I", data, entries)
        data[entries : entries + 4] = struct.pack("<I", sec + 1)
        (tmp_path / "moved.bag").write_bytes(bytes(data))
        indexed.clear()
        assert _read(chunked_reader1(), tmp_path / "moved.bag", **topic)[1] == _read(Reader, path, **topic)[1]
        assert sum(m is None for m in indexed) == 1  # that chunk walked, its messages as the records say


def _arrays(path) -> list:
    """Each chunk's message arrays (connection, time, data start, data length) as lists."""
    with chunked_reader1()(path) as reader:
        return [tuple(a.tolist() for a in (c.conn, c.time, c.data_at, c.data_length)) for c in reader.message_arrays()]


@pytest.mark.parametrize(
    "compression", [None, Writer.CompressionFormat.BZ2, Writer.CompressionFormat.LZ4], ids=["none", "bz2", "lz4"]
)
def test_a_chunks_messages_are_found_where_its_index_says_as_walking_finds_them(compression, tmp_path, monkeypatch):
    """Each chunk's records found by its index data (the connection records between them walked): the same arrays
    as walking every record, compressed or not; a chunk whose index gives a message another time, or two
    messages one offset, is walked, and reads as before."""
    path, _ = _bag(tmp_path / "in.bag", compression, n=1200, every=7)
    located = []
    original = chunks_module._located
    monkeypatch.setattr(chunks_module, "_located", lambda *a: located.append(original(*a)) or located[-1])
    by_index = _arrays(path)
    assert len(located) > 20 and all(found is not None for found in located)
    with monkeypatch.context() as m:
        m.setattr(chunks_module, "_index_entries", lambda *a: None)
        walked = _arrays(path)
    assert by_index == walked and sum(len(chunk[0]) for chunk in walked) == 1200 + 1200 // 7 + 1
    data = bytes(path.read_bytes())
    entries = _index_entries_at(path, 2, "/a")
    for name, at, value in (("time", entries, 1), ("offset", entries + 12 + 8, -1)):
        bent = bytearray(data)
        (field,) = struct.unpack_from("<I", bent, at)
        # a later time; or the second entry's offset that of the first
        new = field + value if value > 0 else struct.unpack_from("<I", bent, entries + 8)[0]
        bent[at : at + 4] = struct.pack("<I", new)
        (tmp_path / f"{name}.bag").write_bytes(bytes(bent))
        located.clear()
        assert _arrays(tmp_path / f"{name}.bag") == walked, name
        assert sum(found is None for found in located) == 1, name
