"""A ROS 2 sqlite3 bag's rows read in batches with their row ids (gyrocomp.io.rosbag2_sqlite): the messages rosbags
reads, in its order (repeated and swapped stamps among them), in batches of any size; no batches for another bag."""

from __future__ import annotations

import pytest

from gyrocomp.io.rosbag import any_reader
from gyrocomp.io.rosbag2_sqlite import sqlite_arrays, sqlite_storage

from .log_writers import write_bag

pytest.importorskip("rosbags", reason="bags need the [ros] extra (rosbags)")


@pytest.mark.parametrize("rows", [1, 7, 65536])
@pytest.mark.parametrize("topics", [("/imu/data",), ("/imu/temperature",), ("/imu/data", "/imu/temperature")])
def test_the_batches_are_the_rows_rosbags_reads_in_its_order(rows, topics, tmp_path):
    write_bag(tmp_path / "bag", ros2=True, n=200, repeat=50, swap=120)
    with any_reader(tmp_path / "bag") as reader:
        chosen = [c for c in reader.connections if c.topic in topics]
        expected = [(c.topic, t, bytes(raw)) for c, t, raw in reader.messages(connections=chosen)]
        storage = sqlite_storage(reader)
        topic_of = {c.id: c.topic for c in storage.connections}
        found, ids = [], []
        for batch in sqlite_arrays(storage, chosen, rows):
            assert batch.conn.size <= rows
            ids += batch.ids.tolist()
            found += [
                (topic_of[int(c)], int(t), batch.data[a : a + n].tobytes())
                for c, t, a, n in zip(batch.conn, batch.time, batch.data_at, batch.data_length)
            ]
    assert found == expected and len(found) >= 20
    assert len(set(ids)) == len(ids)


@pytest.mark.parametrize("options", [{"ros2": False}, {"ros2": True, "mcap": True}], ids=["ros1", "mcap"])
def test_another_bag_has_no_sqlite_storage(options, tmp_path):
    path = tmp_path / ("in.bag" if not options["ros2"] else "bag")
    write_bag(path, n=20, **options)
    with any_reader(path) as reader:
        assert sqlite_storage(reader) is None
