"""The ROS 1 bag reader that reads chunk by chunk: the same connections, message counts and messages as rosbags'
own reader, for uncompressed, bz2 and lz4 chunks, many chunks, a filter on connections and times; and its memory
does not hold an index entry per message."""

from __future__ import annotations

import pytest

from gyrocomp.io.rosbag1_chunks import chunked_reader1, lean_writer1

pytest.importorskip("rosbags", reason="bags need the [ros] extra (rosbags)")
from rosbags.rosbag1 import Reader, ReaderError, Writer  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

STORE = get_typestore(Stores.ROS1_NOETIC)


def _bag(path, compression=None, n=600, writer_class=Writer):
    """Two topics of strings, messages of 40 to 100 bytes, chunks of about 4 kB (many chunks)."""
    writer = writer_class(path)
    if compression:
        writer.set_compression(compression)
    writer.chunk_threshold = 4096
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
            if i % 3 == 0:
                writer.write(
                    b,
                    1_000_000_000 + 10_000_000 * i + 5,
                    STORE.serialize_ros1(string(data=str(i)), "std_msgs/msg/String"),
                )
    return path, writer


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
