"""An MCAP file's messages read chunk by chunk as arrays (gyrocomp.io.mcap_chunks): the same messages in the same
order as rosbags' own MCAP reader, for files written by the mcap library (none, zstd, lz4; CRCs; schema and channel
records inside chunks) and by rosbags, log times out of order within chunks, an index entry that does not hold (the
chunk walked), chunks whose time ranges overlap (left to rosbags); and a bag read through it equals the same bag read
message by message."""

from __future__ import annotations

import struct

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp.io import mcap_chunks, rosbag
from gyrocomp.io.read_options import ReadOptions
from gyrocomp.io.mcap_chunks import mcap_arrays
from gyrocomp.io.rosbag2_storage import channel_ids

pytest.importorskip("rosbags", reason="bags need the [ros] extra (rosbags)")
mcap_writer = pytest.importorskip("mcap.writer", reason="MCAP files need the mcap library")
from rosbags.highlevel import AnyReader  # noqa: E402

from .log_writers import write_bag  # noqa: E402

_COMPRESSIONS = {
    "none": mcap_writer.CompressionType.NONE,
    "zstd": mcap_writer.CompressionType.ZSTD,
    "lz4": mcap_writer.CompressionType.LZ4,
}


def _mcap(path, messages, compression="none", chunk_size=512):
    """An MCAP file (profile ros2) of two std_msgs/String topics, /a and /b: ``messages`` (topic index, log time
    [ns], payload bytes) in that order, in chunks of about ``chunk_size`` bytes with message indexes and CRCs."""
    with open(path, "wb") as stream:
        writer = mcap_writer.Writer(stream, chunk_size=chunk_size, compression=_COMPRESSIONS[compression])
        writer.start(profile="ros2", library="gyrocomp tests")
        schema = writer.register_schema(name="std_msgs/msg/String", encoding="ros2msg", data=b"string data")
        channels = [writer.register_channel(topic, "cdr", schema) for topic in ("/a", "/b")]
        for sequence, (topic, log_time, payload) in enumerate(messages):
            writer.add_message(channels[topic], log_time, payload, log_time, sequence)
        writer.finish()
    return path


def _messages(n=400, every=3):
    """/a's messages of 10 to 70 bytes 10 ms apart, and one of /b in ``every``."""
    out = []
    for i in range(n):
        out.append((0, 1_000_000_000 + 10_000_000 * i, bytes([i % 251]) * (10 + i % 61)))
        if i % every == 0:
            out.append((1, 1_000_000_000 + 10_000_000 * i + 5, b"b%d" % i))
    return out


def _read(path, topic: str, fast: bool):
    """(log time [ns], raw bytes) of ``topic``: through :func:`mcap_arrays` (``fast``) or rosbags' reader."""
    with AnyReader([path]) as reader:
        chosen = [c for c in reader.connections if c.topic == topic]
        if not fast:
            return [(t, bytes(raw)) for _, t, raw in reader.messages(connections=chosen)]
        chunks = mcap_arrays(reader, chosen)
        assert chunks is not None
        return [
            (int(t), found.data[at : at + n].tobytes())
            for found in chunks
            for t, at, n in zip(found.time, found.data_at, found.data_length)
        ]


@pytest.mark.parametrize("compression", list(_COMPRESSIONS))
@pytest.mark.parametrize("topic", ["/a", "/b"])
def test_the_chunk_arrays_are_the_messages_rosbags_reads(compression, topic, tmp_path):
    path = _mcap(tmp_path / "x.mcap", _messages(), compression)
    expected = _read(path, topic, fast=False)
    assert len(expected) == (400 if topic == "/a" else 134)
    assert _read(path, topic, fast=True) == expected


@settings(max_examples=40, deadline=None)
@given(
    steps=st.lists(st.tuples(st.integers(0, 1), st.integers(-30, 100), st.integers(0, 90)), min_size=1, max_size=120),
    chunk_size=st.sampled_from([64, 300, 2000]),
)
def test_log_times_out_of_order_within_chunks_come_out_as_rosbags_orders_them(steps, chunk_size, tmp_path_factory):
    """Log times that go back now and then (within a chunk: sorted there, stably) and repeat; when chunks' time
    ranges overlap the arrays are not offered (rosbags merges them) and rosbags' reading stays."""
    now, messages = 10_000, []
    for topic, step, size in steps:
        now = max(0, now + step)
        messages.append((topic, now, bytes([size]) * size))
    path = _mcap(tmp_path_factory.mktemp("mcap") / "x.mcap", messages, chunk_size=chunk_size)
    with AnyReader([path]) as reader:
        offered = mcap_arrays(reader, list(reader.connections)) is not None
    for topic in ("/a", "/b"):
        expected = _read(path, topic, fast=False)
        assert sorted(expected, key=lambda m: m[0]) == expected
        if offered:
            assert _read(path, topic, fast=True) == expected


def test_chunks_whose_time_ranges_overlap_are_left_to_rosbags(tmp_path):
    messages = [(0, 1_000 + 10 * i, b"x" * 40) for i in range(50)] + [(0, 1_005 + 10 * i, b"y" * 40) for i in range(50)]
    path = _mcap(tmp_path / "x.mcap", messages, chunk_size=256)
    with AnyReader([path]) as reader:
        assert mcap_arrays(reader, list(reader.connections)) is None


def _bend_index_entry(path, topic: str, bend: str) -> None:
    """The first message index entry (log time, offset) of ``topic`` in the first chunk made wrong by one: its
    ``time`` or its ``offset``."""
    with AnyReader([path]) as reader:
        storage = mcap_chunks.mcap_storage(reader)
        (cid,) = channel_ids(storage, [c for c in reader.connections if c.topic == topic])
        chunk = min(storage.chunks, key=lambda c: c.chunk_start_offset)
        entry = chunk.message_index_offsets[cid] + 15
    with open(path, "r+b") as stream:
        stream.seek(entry)
        log_time, offset = struct.unpack("<QQ", stream.read(16))
        stream.seek(entry)
        stream.write(struct.pack("<QQ", log_time + (bend == "time"), offset + (bend == "offset")))


@pytest.mark.parametrize("bend", ["offset", "time"])
def test_a_chunk_whose_index_does_not_hold_is_walked(bend, tmp_path, monkeypatch):
    path = _mcap(tmp_path / "x.mcap", _messages(), chunk_size=2048)
    _bend_index_entry(path, "/a", bend)
    expected = _read(path, "/a", fast=False)
    walked = []
    walk = mcap_chunks._walked
    monkeypatch.setattr(mcap_chunks, "_walked", lambda data: walked.append(1) or walk(data))
    assert _read(path, "/a", fast=True) == expected
    assert walked == [1]


@pytest.mark.parametrize("bend", [None, "offset", "time"])
def test_a_sparse_topic_is_read_where_the_index_says(bend, tmp_path, monkeypatch):
    """/b, one message in 40, in uncompressed chunks: its records alone are read (the chunks not read whole), the
    same messages as rosbags reads; an index entry that does not hold: that chunk read whole."""
    path = _mcap(tmp_path / "x.mcap", _messages(n=1200, every=40), chunk_size=2048)
    if bend:
        _bend_index_entry(path, "/b", bend)
    expected = _read(path, "/b", fast=False)
    assert len(expected) == 30
    whole = []
    records = mcap_chunks._chunk_records
    monkeypatch.setattr(mcap_chunks, "_chunk_records", lambda *a: whole.append(1) or records(*a))
    assert _read(path, "/b", fast=True) == expected
    assert len(whole) == (1 if bend else 0)


def test_a_chunk_record_that_disagrees_with_the_chunk_index_is_a_reader_error(tmp_path):
    path = _mcap(tmp_path / "x.mcap", _messages(), chunk_size=2048)
    with AnyReader([path]) as reader:
        chunk = min(mcap_chunks.mcap_storage(reader).chunks, key=lambda c: c.chunk_start_offset)
    with open(path, "r+b") as stream:
        stream.seek(chunk.chunk_start_offset)
        stream.write(b"\x07")
    with pytest.raises(Exception, match=f"chunk at byte {chunk.chunk_start_offset} does not match"):
        _read(path, "/a", fast=True)


@pytest.mark.parametrize("kind", ["bare", "folder"])
def test_an_imu_bag_read_by_its_chunks_equals_the_message_by_message_reading(kind, tmp_path, monkeypatch):
    """IMU messages of two layouts (a longer frame_id now and then) and a temperature topic, in a bare .mcap and in
    a bag folder: the recording read through the chunk arrays is the one read through rosbags."""
    path = tmp_path / ("x.mcap" if kind == "bare" else "bag")
    write_bag(path, ros2=True, n=3000, mcap=True, bare=kind == "bare", long_frame_every=7 if kind == "folder" else None)
    used = []
    arrays = rosbag.mcap_arrays
    monkeypatch.setattr(rosbag, "mcap_arrays", lambda *a: used.append(1) or arrays(*a))
    fast = rosbag.read_rosbag(path, ReadOptions())
    assert len(used) == 2  # the IMU topic and the temperature topic
    monkeypatch.setattr(rosbag, "mcap_arrays", lambda *a: None)
    slow = rosbag.read_rosbag(path, ReadOptions())
    assert fast.n_samples == slow.n_samples == 3000
    for name in ("time_s", "gyro_dps", "accel_g", "temperature_degc"):
        np.testing.assert_array_equal(getattr(fast, name), getattr(slow, name))
