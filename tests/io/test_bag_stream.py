"""A ROS bag read in chunks: the same samples, row numbers and warnings as reading it whole, for ROS 1, ROS 2
(sqlite3) and MCAP storage; and every file command that reads in chunks (apply to a table, allan, evaluate,
convert) gives from a bag in chunks what it gives from the whole recording, a bag whose stamps go back across
chunks read whole instead."""

from __future__ import annotations

import warnings

import numpy as np
import pyarrow.parquet as pq
import pytest

from gyrocomp import apply, fit_calibration, read
from gyrocomp.evaluation import evaluate
from gyrocomp.measures.noise import analyse_noise
from gyrocomp.files import ChunkSettings
from gyrocomp.files.apply import apply_file
from gyrocomp.files.convert import convert_file
from gyrocomp.files.evaluate import evaluate_file
from gyrocomp.files.noise_file import analyse_noise_file
from gyrocomp.io import ReadOptions
from gyrocomp.io.rosbag import BagStream, read_rosbag
from gyrocomp.simulation import get_profile, simulate

from tests.io.log_writers import write_bag, write_recording_bag

pytest.importorskip("rosbags", reason="bags need the [ros] extra (rosbags)")

KINDS = {
    "ros1": ({"ros2": False}, "in.bag"),
    "ros2": ({"ros2": True}, "in"),
    "mcap": ({"ros2": True, "mcap": True}, "in"),
}


def _caught(func):
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        result = func()
    return result, sorted(str(w.message) for w in said)


@pytest.mark.parametrize("kind", list(KINDS))
@pytest.mark.parametrize("chunk_rows", [7, 100, 5000])
def test_a_bag_in_chunks_is_what_reading_it_whole_gives(kind, chunk_rows, tmp_path):
    """With a repeated stamp, a temperature topic that starts late, and a stamp pair out of order."""
    options, name = KINDS[kind]
    path = tmp_path / name
    write_bag(path, n=3000, repeat=7, temperature_from=400, swap=1001, **options)
    stream = BagStream(path, ReadOptions(), chunk_rows=chunk_rows)
    chunks, said = _caught(lambda: [c.recording for c in stream.chunks()] + [stream.warn_summary()])
    whole, said_whole = _caught(lambda: read_rosbag(path))
    chunks = chunks[:-1]
    assert said == said_whole and any("left out" in m for m in said) and any("repeated time stamp" in m for m in said)
    assert all(c.n_samples >= 2 for c in chunks) and (chunk_rows >= 3000 or len(chunks) > 1)
    for field in ("time_s", "gyro_dps", "accel_g", "temperature_degc", "row_numbers"):
        np.testing.assert_array_equal(np.concatenate([getattr(c, field) for c in chunks]), getattr(whole, field))
    assert chunks[0].metadata == whole.metadata


@pytest.mark.parametrize("chunk_rows", [50, 5000])
def test_a_gap_in_the_temperature_topic_is_said_never_bridged(chunk_rows, tmp_path):
    """No temperature from message 1000 to 1500 (10 s at 100 Hz): the IMU samples more than 5 temperature periods
    (0.5 s) from any temperature are left out and counted, in chunks as whole; the rest interpolate exactly."""
    path = tmp_path / "gap.bag"
    write_bag(path, ros2=False, n=3000, temperature_gap=(1000, 1500))
    stream = BagStream(path, ReadOptions(), chunk_rows=chunk_rows)
    chunks, said = _caught(lambda: [c.recording for c in stream.chunks()] + [stream.warn_summary()])
    whole, said_whole = _caught(lambda: read_rosbag(path))
    assert said == said_whole
    assert any(
        "of 3000 gyro samples lie outside the time span of temperature topic /imu/temperature and were left out" in m
        for m in said
    )
    time_s = np.concatenate([c.time_s for c in chunks[:-1]])
    np.testing.assert_array_equal(time_s, whole.time_s)
    inside = (time_s > 100.0 + 990 / 100.0 + 0.5) & (time_s < 100.0 + 1500 / 100.0 - 0.5)
    assert not inside.any()  # nothing matched across the gap
    np.testing.assert_allclose(
        whole.temperature_degc, 20.0 + np.minimum(np.round((whole.time_s - 100.0) * 100), 2990) / 10.0, atol=1e-6
    )


@pytest.fixture(scope="module")
def run_bag(tmp_path_factory):
    """A simulated consumer part's cycle at 20 Hz as a ROS 1 bag, and a model fitted on two other runs."""
    folder = tmp_path_factory.mktemp("bags")
    profile = get_profile("cycle", set_points_degc=(15.0, 45.0), cycles=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = fit_calibration([simulate("consumer", profile=profile, rate_hz=1.0, seed=s).recording for s in (1, 2)])
        run = simulate("consumer", profile=profile, duration_s=900.0, rate_hz=20.0, seed=3).recording
    write_recording_bag(folder / "run.bag", run, ros2=False)
    return folder / "run.bag", model


def test_apply_to_a_table_in_chunks_is_apply_on_the_whole_recording(run_bag, tmp_path):
    path, model = run_bag
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = apply_file(model, path, tmp_path / "out.parquet", chunks=ChunkSettings(chunk_rows=777))
        expected = apply(model, read(path))
    assert result.streamed and result.rows == expected.n_samples
    table = pq.read_table(tmp_path / "out.parquet")
    for j, axis in enumerate(expected.gyro_axes):
        np.testing.assert_array_equal(table[axis].to_numpy(), expected.gyro_dps[:, j])
    np.testing.assert_array_equal(table["time"].to_numpy(), expected.time_s)


def test_allan_and_evaluate_in_chunks_are_the_whole_recordings(run_bag, tmp_path):
    path, model = run_bag
    chunks = ChunkSettings(chunk_rows=1111, memory_bytes=0, scratch_dir=str(tmp_path))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        whole = read(path)
        noise, noise_whole = analyse_noise_file(path, chunks=chunks), analyse_noise(whole)
        judged, judged_whole = evaluate_file(model, path, chunks=chunks), evaluate(model, whole)
    for name, axis in noise.axes.items():
        np.testing.assert_array_equal(axis.allan.tau, noise_whole.axes[name].allan.tau)
        np.testing.assert_allclose(axis.allan.deviation, noise_whole.axes[name].allan.deviation, rtol=1e-8)
    a, b = judged.runs[0], judged_whole.runs[0]
    for key in a.axes:
        for field, value in a.axes[key].to_dict().items():
            assert value == pytest.approx(b.axes[key].to_dict()[field], rel=1e-8), field
    assert not list(tmp_path.iterdir())  # the spilled phases are removed


def test_convert_in_chunks_writes_the_whole_recording(run_bag, tmp_path):
    path, _ = run_bag
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        done = convert_file(path, tmp_path / "out.parquet", chunks=ChunkSettings(chunk_rows=500))
        whole = read(path)
    assert done.rows == whole.n_samples
    back = read(tmp_path / "out.parquet")
    for field in ("time_s", "gyro_dps", "accel_g", "temperature_degc"):
        np.testing.assert_array_equal(getattr(back, field), getattr(whole, field))


def test_stamps_that_go_back_across_chunks_are_read_whole(run_bag, tmp_path):
    """Messages 99 and 100 swapped: in chunks of 100 the second chunk starts before the first ends."""
    path = tmp_path / "swapped.bag"
    write_bag(path, ros2=False, n=300, swap=99)
    _, model = run_bag
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = apply_file(model, path, tmp_path / "out.parquet", chunks=ChunkSettings(chunk_rows=100))
        expected = apply(model, read(path))
    assert not result.streamed
    np.testing.assert_array_equal(pq.read_table(tmp_path / "out.parquet")["gyro_x"].to_numpy(), expected.gyro_dps[:, 0])


def test_a_ros1_bag_whose_imu_messages_change_layout_within_a_chunk_reads_as_rosbags_decodes_them(tmp_path):
    """IMU messages whose frame_id changes length every few messages (no one byte layout in a chunk: decoded
    message by message), in chunks of one layout too: read whole and in chunks, the values rosbags' deserializer
    gives for each message."""
    from rosbags.rosbag1 import Reader, Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC)
    types = store.types
    imu_type = "sensor_msgs/msg/Imu"
    path = tmp_path / "mixed.bag"
    writer = Writer(path)
    writer.chunk_threshold = 8192  # many chunks: those of one frame_id and those of both
    rng = np.random.default_rng(5)
    cov = np.zeros(9)
    with writer:
        connection = writer.add_connection("/imu/data", imu_type, typestore=store)
        for i in range(600):
            t = 100.0 + i * 0.01
            stamp = types["builtin_interfaces/msg/Time"](sec=int(t), nanosec=int(round((t - int(t)) * 1e9)))
            frame = "base_link/imu0" if 200 <= i < 400 and i % 5 == 0 else "imu"
            msg = types[imu_type](
                header=types["std_msgs/msg/Header"](seq=i, stamp=stamp, frame_id=frame),
                orientation=types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
                orientation_covariance=cov,
                angular_velocity=types["geometry_msgs/msg/Vector3"](*rng.normal(size=3)),
                angular_velocity_covariance=cov,
                linear_acceleration=types["geometry_msgs/msg/Vector3"](*rng.normal(size=3)),
                linear_acceleration_covariance=cov,
            )
            writer.write(connection, int(round(t * 1e9)), store.serialize_ros1(msg, imu_type))
    expected = []
    with Reader(path) as reader:
        for _, _, raw in reader.messages():
            msg = store.deserialize_ros1(raw, imu_type)
            w, a = msg.angular_velocity, msg.linear_acceleration
            stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
            expected.append([stamp, w.x, w.y, w.z, a.x, a.y, a.z])
    expected = np.array(expected)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # no temperature topic: said, not the point here
        whole = read_rosbag(path)
        chunks = [c.recording for c in BagStream(path, ReadOptions(), chunk_rows=77).chunks()]
    for recording in (whole, *chunks):
        assert recording.n_samples >= 2
    for got in (whole, chunks):
        recordings = got if isinstance(got, list) else [got]
        time_s = np.concatenate([r.time_s for r in recordings])
        gyro = np.concatenate([r.gyro_dps for r in recordings])
        accel = np.concatenate([r.accel_g for r in recordings])
        np.testing.assert_array_equal(time_s, expected[:, 0])
        np.testing.assert_allclose(gyro, np.degrees(expected[:, 1:4]), rtol=1e-14, atol=0)
        np.testing.assert_allclose(accel, expected[:, 4:7] / 9.80665, rtol=1e-14, atol=0)


@pytest.mark.parametrize("read_chunks", [True, False])
def test_a_bag_stream_opens_its_bag_once_and_closes_it_read_or_not(read_chunks, tmp_path, monkeypatch):
    """The reader that found the topics and read the temperature reads the chunks too (rosbags' sqlite3 storage
    counts every topic's messages when it opens: seconds an hour at 1 kHz); closed when the chunks are read, or
    when a stream is dropped unread."""
    import gc

    from rosbags.rosbag2.reader import DirectoryReader

    write_bag(tmp_path / "in", n=300, ros2=True)
    opened = []
    open_folder = DirectoryReader.open
    monkeypatch.setattr(DirectoryReader, "open", lambda self: opened.append(1) or open_folder(self))
    stream = BagStream(tmp_path / "in", chunk_rows=50)
    reader = stream._reader
    if read_chunks:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            assert sum(chunk.recording.n_samples for chunk in stream.chunks()) == 300
    else:
        del stream
        gc.collect()
    assert len(opened) == 1
    with pytest.raises(Exception, match="not open"):
        next(reader.messages())
