"""IMU messages decoded and re-encoded a batch at a time: the same numbers as rosbags' own deserializer, for ROS 1
and ROS 2 CDR, every frame_id length (CDR's padding depends on it); a batch that is not of one layout is left to
rosbags."""

from __future__ import annotations

import numpy as np
import pytest

from gyrocomp.io.ros_imu import (
    ANGULAR_VELOCITY,
    LINEAR_ACCELERATION,
    LINEAR_ACCELERATION_COVARIANCE,
    imu_batch,
    imu_fields,
    temperature_fields,
)

pytest.importorskip("rosbags", reason="bags need the [ros] extra (rosbags)")
from rosbags.typesys import Stores, get_typestore  # noqa: E402

IMU = "sensor_msgs/msg/Imu"


def _messages(ros2: bool, frame_id: str, n: int, seed: int):
    store = get_typestore(Stores.ROS2_HUMBLE if ros2 else Stores.ROS1_NOETIC)
    types = store.types
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        stamp = types["builtin_interfaces/msg/Time"](
            sec=int(rng.integers(0, 2**31 - 1)), nanosec=int(rng.integers(0, 10**9))
        )
        header = (
            types["std_msgs/msg/Header"](stamp=stamp, frame_id=frame_id)
            if ros2
            else types["std_msgs/msg/Header"](seq=i, stamp=stamp, frame_id=frame_id)
        )
        v = rng.normal(size=37)
        vector = types["geometry_msgs/msg/Vector3"]
        out.append(
            types[IMU](
                header=header,
                orientation=types["geometry_msgs/msg/Quaternion"](*v[:4]),
                orientation_covariance=v[4:13],
                angular_velocity=vector(*v[13:16]),
                angular_velocity_covariance=v[16:25],
                linear_acceleration=vector(*v[25:28]),
                linear_acceleration_covariance=v[28:37],
            )
        )
    serialize = store.serialize_cdr if ros2 else store.serialize_ros1
    deserialize = store.deserialize_cdr if ros2 else store.deserialize_ros1
    return out, [bytes(serialize(m, IMU)) for m in out], (lambda raw: deserialize(raw, IMU))


def _vector(v) -> tuple[float, float, float]:
    return (v.x, v.y, v.z)


@pytest.mark.parametrize("ros2", [False, True], ids=["ros1", "ros2"])
@pytest.mark.parametrize("frame_id", ["", "i", "im", "imu", "imu_", "imu_link", "base_link/imu0"])
def test_a_batch_reads_what_rosbags_reads(ros2, frame_id):
    messages, raws, _ = _messages(ros2, frame_id, 20, seed=len(frame_id))
    batch = imu_batch(raws, cdr=ros2)
    assert batch is not None
    values = batch.values
    stamps = batch.stamp_s(cdr=ros2)
    for k, msg in enumerate(messages):
        assert stamps[k] == msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        assert tuple(values[k, ANGULAR_VELOCITY : ANGULAR_VELOCITY + 3]) == _vector(msg.angular_velocity)
        assert tuple(values[k, LINEAR_ACCELERATION : LINEAR_ACCELERATION + 3]) == _vector(msg.linear_acceleration)
        assert np.array_equal(values[k, LINEAR_ACCELERATION_COVARIANCE:], msg.linear_acceleration_covariance)


@pytest.mark.parametrize("ros2", [False, True], ids=["ros1", "ros2"])
def test_values_written_into_a_batch_are_what_rosbags_reads_back_and_nothing_else_changes(ros2):
    messages, raws, deserialize = _messages(ros2, "imu_link", 12, seed=3)
    batch = imu_batch(raws, cdr=ros2)
    rows = np.array([0, 3, 4, 11])
    new = np.random.default_rng(4).normal(size=(rows.size, 3))
    written = batch.with_values(ANGULAR_VELOCITY, rows, new)
    for k, msg in enumerate(messages):
        back = deserialize(written.message(k))
        expected = tuple(new[list(rows).index(k)]) if k in rows else _vector(msg.angular_velocity)
        assert _vector(back.angular_velocity) == expected
        assert _vector(back.linear_acceleration) == _vector(msg.linear_acceleration)
        assert back.header.stamp == msg.header.stamp and back.header.frame_id == msg.header.frame_id
        assert np.array_equal(back.angular_velocity_covariance, msg.angular_velocity_covariance)
    untouched = [k for k in range(len(raws)) if k not in rows]
    assert all(written.message(k) == raws[k] for k in untouched)


def test_batches_not_of_one_layout_are_left_to_rosbags():
    _, short, _ = _messages(True, "imu", 3, seed=1)
    _, long, _ = _messages(True, "imu_link", 3, seed=2)
    assert imu_batch(short + long, cdr=True) is None  # two lengths
    store = get_typestore(Stores.ROS2_HUMBLE)
    messages, _, _ = _messages(True, "imu", 2, seed=5)
    big_endian = [bytes(store.serialize_cdr(m, IMU, little_endian=False)) for m in messages]
    assert imu_batch(big_endian, cdr=True) is None
    assert imu_batch([], cdr=False) is None
    # one length, but the frame_id's length field differs (a message cut and padded): rosbags decides
    _, raws, _ = _messages(False, "abcd", 2, seed=6)
    bent = bytearray(raws[1])
    bent[12] = 3
    assert imu_batch([raws[0], bytes(bent)], cdr=False) is None


@pytest.mark.parametrize("ros2", [False, True], ids=["ros1", "ros2"])
@pytest.mark.parametrize("frame_id", ["", "imu", "base_link/imu0"])
def test_fields_read_where_the_messages_lie_are_what_rosbags_reads(ros2, frame_id):
    """Messages at irregular offsets of one byte array (other bytes between them, as in a bag's chunk): the
    stamps and vectors read in place are rosbags' to the bit, and where the float64 values start is the batch's."""
    messages, raws, _ = _messages(ros2, frame_id, 15, seed=7 + len(frame_id))
    gaps = np.random.default_rng(8).integers(0, 40, size=len(raws))
    data, at = bytearray(), []
    for gap, raw in zip(gaps, raws):
        data += bytes(range(int(gap)))
        at.append(len(data))
        data += raw
    fields = imu_fields(np.frombuffer(bytes(data), np.uint8), np.array(at), len(raws[0]), cdr=ros2)
    assert fields is not None and fields.values_at == imu_batch(raws, cdr=ros2).values_at
    for k, msg in enumerate(messages):
        assert fields.stamp_s[k] == msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        assert tuple(fields.angular_velocity[k]) == _vector(msg.angular_velocity)
        assert tuple(fields.linear_acceleration[k]) == _vector(msg.linear_acceleration)


def test_fields_of_messages_not_of_one_layout_or_past_the_bytes_are_not_read():
    _, raws, _ = _messages(False, "abcd", 2, seed=6)
    data = np.frombuffer(raws[0] + raws[1], np.uint8)
    length = len(raws[0])
    assert imu_fields(data, np.array([0, length]), length, cdr=False) is not None
    assert imu_fields(data, np.array([0, length + 1]), length, cdr=False) is None  # past the end
    assert imu_fields(data, np.array([], dtype=np.int64), length, cdr=False) is None
    bent = bytearray(raws[1])
    bent[12] = 3  # the frame_id's length field differs
    assert imu_fields(np.frombuffer(raws[0] + bytes(bent), np.uint8), np.array([0, length]), length, False) is None


def _temperatures(ros2: bool, frame_id: str, n: int, seed: int):
    store = get_typestore(Stores.ROS2_HUMBLE if ros2 else Stores.ROS1_NOETIC)
    types, rng = store.types, np.random.default_rng(seed)
    out = []
    for i in range(n):
        stamp = types["builtin_interfaces/msg/Time"](
            sec=int(rng.integers(0, 2**31 - 1)), nanosec=int(rng.integers(0, 10**9))
        )
        fields = {"stamp": stamp, "frame_id": frame_id} | ({} if ros2 else {"seq": i})
        out.append(
            types[TEMPERATURE](
                header=types["std_msgs/msg/Header"](**fields),
                temperature=float(rng.normal(30, 20)),
                variance=float(rng.random()),
            )
        )
    serialize = store.serialize_cdr if ros2 else store.serialize_ros1
    return out, [bytes(serialize(m, TEMPERATURE)) for m in out]


TEMPERATURE = "sensor_msgs/msg/Temperature"


@pytest.mark.parametrize("ros2", [False, True], ids=["ros1", "ros2"])
@pytest.mark.parametrize("frame_id", ["", "i", "im", "imu", "imu_", "imu_link", "base_link/imu0"])
def test_temperatures_read_at_once_are_what_rosbags_reads(ros2, frame_id):
    messages, raws = _temperatures(ros2, frame_id, 9, seed=len(frame_id))
    stamps, values = temperature_fields(raws, cdr=ros2)
    assert stamps.tolist() == [m.header.stamp.sec + m.header.stamp.nanosec * 1e-9 for m in messages]
    assert values.tolist() == [m.temperature for m in messages]


def test_temperatures_not_of_one_layout_are_left_to_rosbags():
    _, short = _temperatures(True, "t", 2, seed=1)
    _, long = _temperatures(True, "thermo", 2, seed=2)
    assert temperature_fields(short + long, cdr=True) is None  # two lengths
    assert temperature_fields([], cdr=False) is None
    assert temperature_fields([b"\x00" * 20], cdr=False) is None  # too short for a header and two values
    store = get_typestore(Stores.ROS2_HUMBLE)
    messages, _ = _temperatures(True, "t", 2, seed=3)
    big_endian = [bytes(store.serialize_cdr(m, TEMPERATURE, little_endian=False)) for m in messages]
    assert temperature_fields(big_endian, cdr=True) is None
    _, raws = _temperatures(False, "abcd", 2, seed=4)
    bent = bytearray(raws[1])
    bent[12] = 3  # the frame_id's length field differs
    assert temperature_fields([raws[0], bytes(bent)], cdr=False) is None
    # an IMU message is no temperature message: its length does not fit a header and two values
    assert temperature_fields(_messages(False, "abcd", 2, seed=5)[1], cdr=False) is None
