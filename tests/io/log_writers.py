"""Minimal writers of PX4 ULog and ArduPilot DataFlash files (and ROS bags, with rosbags), for reader tests (formats as documented by
PX4, https://docs.px4.io/main/en/dev_log/ulog_file_format.html, and ArduPilot's AP_Logger)."""

from __future__ import annotations

import struct

import numpy as np

_ULOG_TYPES = {"uint64_t": "Q", "uint32_t": "I", "float": "f", "uint8_t": "B", "int32_t": "i"}


def write_ulog(
    path,
    topics: dict[tuple[str, int], dict[str, tuple[str, np.ndarray]]],
    parameters: dict[str, int | float] | None = None,
) -> None:
    """Write a ULog with one data series per ``(topic, multi_id)``: ``{field: (c_type, values)}``, and
    ``parameters`` (an int is written as int32_t, a float as float) in the definitions section.

    Every topic must have a ``timestamp`` field (uint64_t, microseconds) first.
    """
    out = bytearray(b"ULog\x01\x12\x35" + bytes([1]) + struct.pack("<Q", 0))

    def message(kind: bytes, payload: bytes) -> None:
        out.extend(struct.pack("<HB", len(payload), kind[0]) + payload)

    message(b"B", bytes(8) + bytes(8) + bytes(24))  # flag bits: no incompat flags, no appended data
    formats_done = set()
    for (name, _), fields in topics.items():
        if name in formats_done:
            continue
        formats_done.add(name)
        spec = "".join(f"{ctype} {field};" for field, (ctype, _) in fields.items())
        message(b"F", f"{name}:{spec}".encode())
    for name, value in (parameters or {}).items():
        key = f"{'int32_t' if isinstance(value, int) else 'float'} {name}".encode()
        message(b"P", bytes([len(key)]) + key + struct.pack("<i" if isinstance(value, int) else "<f", value))
    for msg_id, ((name, multi_id), _fields) in enumerate(topics.items()):
        message(b"A", struct.pack("<BH", multi_id, msg_id) + name.encode())
    rows = []
    for msg_id, ((_name, _multi_id), fields) in enumerate(topics.items()):
        codes = "<" + "".join(_ULOG_TYPES[ctype] for ctype, _ in fields.values())
        columns = [values for _, values in fields.values()]
        stamps = np.asarray(fields["timestamp"][1])
        for i in range(stamps.size):
            payload = struct.pack("<H", msg_id) + struct.pack(codes, *(c[i].item() for c in columns))
            rows.append((int(stamps[i]), payload))
    for _, payload in sorted(rows, key=lambda r: r[0]):
        message(b"D", payload)
    with open(path, "wb") as fh:
        fh.write(bytes(out))


_DF_TYPES = {"Q": "Q", "f": "f", "B": "B", "I": "I", "H": "H", "N": "16s"}


def write_dataflash(path, messages: dict[str, tuple[int, list[tuple[str, str]], list[tuple]]], cut: int = 0) -> None:
    """Write a DataFlash log: ``{name: (type_id, [(column, df_format_char)], rows)}``, rows in time order
    per type (all types interleaved by their first column, TimeUS). ``cut`` drops bytes from the end."""
    out = bytearray()
    fmt_struct = struct.Struct("<BB4s16s64s")
    structs = {}
    for name, (type_id, columns, _) in messages.items():
        body = struct.Struct("<" + "".join(_DF_TYPES[c] for _, c in columns))
        structs[name] = body
        out += b"\xa3\x95\x80" + fmt_struct.pack(
            type_id,
            body.size + 3,
            name.encode(),
            "".join(c for _, c in columns).encode(),
            ",".join(n for n, _ in columns).encode(),
        )
    records = []
    for name, (type_id, _, rows) in messages.items():
        for row in rows:
            records.append((row[0], bytes([0xA3, 0x95, type_id]) + structs[name].pack(*row)))
    for _, record in sorted(records, key=lambda r: r[0]):
        out += record
    with open(path, "wb") as fh:
        fh.write(bytes(out[: len(out) - cut]))


def write_bag(
    path,
    ros2: bool,
    n=100,
    rate_hz=100.0,
    temperature=True,
    imu_topics=("/imu/data",),
    mcap=False,
    repeat: int | None = None,
    temperature_from: int = 0,
    swap: int | None = None,
    bare: bool = False,
    temperature_gap: tuple[int, int] | None = None,
    long_frame_every: int | None = None,
):
    """A bag (ROS 1 ``.bag``, or a ROS 2 folder in sqlite3 or, with ``mcap``, MCAP storage) of ``n`` IMU messages
    per topic at ``rate_hz`` (gyro x ramping, z -0.01 rad/s, 1 g on z) and a temperature message every tenth
    (from message ``temperature_from`` on); ``repeat``: message i written a second time with the same stamp and
    gyro y 0.5 rad/s; ``swap``: messages i and i + 1 written in each other's place (their stamps out of order);
    ``bare`` (with ``mcap``): the MCAP file alone at ``path``, without its folder and ``metadata.yaml``;
    ``temperature_gap`` (i, j): no temperature message from message i to before j; ``long_frame_every`` k: every
    k-th IMU message's ``frame_id`` longer (a message of another length and layout)."""
    if bare:
        import shutil
        from pathlib import Path

        folder = Path(str(path) + ".folder")
        write_bag(
            folder,
            ros2=True,
            n=n,
            rate_hz=rate_hz,
            temperature=temperature,
            imu_topics=imu_topics,
            mcap=True,
            repeat=repeat,
            temperature_from=temperature_from,
            swap=swap,
            temperature_gap=temperature_gap,
        )
        next(folder.glob("*.mcap")).rename(path)
        shutil.rmtree(folder)
        return
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE if ros2 else Stores.ROS1_NOETIC)
    Imu, Temperature = store.types["sensor_msgs/msg/Imu"], store.types["sensor_msgs/msg/Temperature"]
    Header, Time = store.types["std_msgs/msg/Header"], store.types["builtin_interfaces/msg/Time"]
    Vector3, Quaternion = store.types["geometry_msgs/msg/Vector3"], store.types["geometry_msgs/msg/Quaternion"]
    serialize = store.serialize_cdr if ros2 else store.serialize_ros1
    if ros2:
        from rosbags.rosbag2 import StoragePlugin, Writer

        writer = Writer(path, version=9, storage_plugin=StoragePlugin.MCAP if mcap else StoragePlugin.SQLITE3)
    else:
        from rosbags.rosbag1 import Writer

        writer = Writer(path)

    def header(t, frame="imu"):
        sec = int(t)
        stamp = Time(sec=sec, nanosec=int(round((t - sec) * 1e9)))
        return Header(stamp=stamp, frame_id=frame) if ros2 else Header(seq=0, stamp=stamp, frame_id=frame)

    cov = np.zeros(9)
    with writer:
        imus = [writer.add_connection(topic, Imu.__msgtype__, typestore=store) for topic in imu_topics]
        thermo = writer.add_connection("/imu/temperature", Temperature.__msgtype__, typestore=store)
        for i in range(n):
            t = 100.0 + i / rate_hz  # when the message is logged
            stamped = 100.0 + (i + 1 if i == swap else i - 1 if swap is not None and i == swap + 1 else i) / rate_hz
            long = long_frame_every is not None and i % long_frame_every == 0
            msg = Imu(
                header=header(stamped, "imu_link_long" if long else "imu"),
                orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0),
                orientation_covariance=cov,
                angular_velocity=Vector3(x=0.001 * i, y=0.0, z=-0.01),
                angular_velocity_covariance=cov,
                linear_acceleration=Vector3(x=0.0, y=0.0, z=9.80665),
                linear_acceleration_covariance=cov,
            )
            for conn in imus:
                writer.write(conn, int(t * 1e9), serialize(msg, Imu.__msgtype__))
                if i == repeat:
                    twin = Imu(
                        header=msg.header,
                        orientation=msg.orientation,
                        orientation_covariance=cov,
                        angular_velocity=Vector3(x=0.001 * i, y=0.5, z=-0.01),
                        angular_velocity_covariance=cov,
                        linear_acceleration=msg.linear_acceleration,
                        linear_acceleration_covariance=cov,
                    )
                    writer.write(conn, int(t * 1e9) + 1, serialize(twin, Imu.__msgtype__))
            in_gap = temperature_gap is not None and temperature_gap[0] <= i < temperature_gap[1]
            if temperature and i % 10 == 0 and i >= temperature_from and not in_gap:  # 10 Hz temperature
                msg = Temperature(header=header(t), temperature=20.0 + i / 10.0, variance=0.0)
                writer.write(thermo, int(t * 1e9), serialize(msg, Temperature.__msgtype__))


def write_recording_bag(
    path, recording, ros2: bool, mcap: bool = False, temperature_every: int = 10, stamps_ns: np.ndarray | None = None
):
    """A recording [s, deg/s, g, degC] as a bag (ROS 1 ``.bag``, or a ROS 2 folder in sqlite3 or MCAP storage),
    serialized by rosbags: ``/imu/data`` (rad/s, m/s^2) and every ``temperature_every``-th sample's temperature on
    ``/imu/temperature``; ``stamps_ns``: the messages' stamps as integer nanoseconds (default: the recording's time
    rounded to them)."""
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE if ros2 else Stores.ROS1_NOETIC)
    types = store.types
    Imu, Temperature = types["sensor_msgs/msg/Imu"], types["sensor_msgs/msg/Temperature"]
    Vector3, Quaternion = types["geometry_msgs/msg/Vector3"], types["geometry_msgs/msg/Quaternion"]
    serialize = store.serialize_cdr if ros2 else store.serialize_ros1
    if ros2:
        from rosbags.rosbag2 import StoragePlugin, Writer

        writer = Writer(path, version=9, storage_plugin=StoragePlugin.MCAP if mcap else StoragePlugin.SQLITE3)
    else:
        from rosbags.rosbag1 import Writer

        writer = Writer(path)
    gyro = np.radians(recording.gyro_dps)
    accel = recording.accel_g * 9.80665
    cov = np.zeros(9)
    with writer:
        imu = writer.add_connection("/imu/data", Imu.__msgtype__, typestore=store)
        thermo = writer.add_connection("/imu/temperature", Temperature.__msgtype__, typestore=store)
        if stamps_ns is None:
            stamps_ns = [int(t) * 10**9 + int(round((t - int(t)) * 1e9)) for t in recording.time_s]
        for i, ns in enumerate(stamps_ns):
            sec, nanosec = divmod(int(ns), 10**9)
            stamp = types["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec)
            header = (
                types["std_msgs/msg/Header"](stamp=stamp, frame_id="imu_link")
                if ros2
                else types["std_msgs/msg/Header"](seq=i, stamp=stamp, frame_id="imu_link")
            )
            msg = Imu(
                header=header,
                orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0),
                orientation_covariance=cov,
                angular_velocity=Vector3(*gyro[i]),
                angular_velocity_covariance=cov,
                linear_acceleration=Vector3(*accel[i]),
                linear_acceleration_covariance=cov,
            )
            writer.write(imu, int(ns), serialize(msg, Imu.__msgtype__))
            if i % temperature_every == 0:
                writer.write(
                    thermo,
                    int(ns),
                    serialize(
                        Temperature(header=header, temperature=float(recording.temperature_degc[i]), variance=0.0),
                        Temperature.__msgtype__,
                    ),
                )
