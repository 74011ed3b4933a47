"""PX4 ULog reader (optional extra ``[ulog]``, pyulog).

Reads ``sensor_gyro`` (rad/s) with its ``temperature`` (degC), and ``sensor_accel`` (m/s^2) of the
same instance matched by time. When a log has no ``sensor_gyro``, falls back to ``vehicle_imu``
(delta angles over their interval) or ``sensor_combined``, which carry no temperature.
Only the topics named are parsed (pyulog's message filter), not the whole log.

Reference: PX4 ULog file format, https://docs.px4.io/main/en/dev_log/ulog_file_format.html;
uORB messages sensor_gyro, sensor_accel, vehicle_imu, sensor_combined.
"""

from __future__ import annotations

import mmap
import struct
import warnings
from pathlib import Path

import numpy as np

from ..errors import DataQualityWarning, InputError, foreign_message, user_stacklevel
from ..recording import Recording
from ..units import unit_factor
from .log_samples import keep_matched, log_recording, match_by_time, order_by_time
from .foreign_libraries import foreign_output, require
from .read_options import ProgressCallback, ReadOptions
from .readers import Reader, check_magic, register_reader

ULOG_MAGIC = b"ULog\x01\x12\x35"
GYRO_TOPICS = ("sensor_gyro", "vehicle_imu", "sensor_combined")
_US = unit_factor("time", "us")
_RAD = unit_factor("gyro", "rad/s")
_MS2 = unit_factor("accel", "m/s2")


_MESSAGE_HEADER = struct.Struct("<HB")  # msg_size (payload bytes), msg_type
_FILE_HEADER_BYTES = 16  # magic (7), version (1), timestamp (8)


def _walk(path: Path, stops: tuple[int, ...] = ()) -> tuple[tuple[int, int] | None, set[int]]:
    """(the cut of :func:`cut_message`, the offsets of ``stops`` at which a message starts)."""
    with open(path, "rb") as fh:
        size = fh.seek(0, 2)
        if size <= _FILE_HEADER_BYTES:
            return None, set()
        wanted, hit = set(stops), set()
        with mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as data:
            pos, unpack = _FILE_HEADER_BYTES, _MESSAGE_HEADER.unpack_from
            while pos + 3 <= size:
                if pos in wanted:
                    hit.add(pos)
                end = pos + 3 + unpack(data, pos)[0]
                if end > size:
                    return (pos, end - size), hit
                pos = end
            return ((pos, 3 - (size - pos)) if pos < size else None), hit


def cut_message(path: Path) -> tuple[int, int] | None:
    """(offset, bytes missing) of a last message the file ends inside of, or None when the ULog's message
    framing ends exactly at the end of the file. pyulog reads a cut log as a shorter one without a word; a
    cut (a log copied while written, a partial download) almost always lands inside a message."""
    return _walk(path)[0]


def appended_offsets(path: Path) -> tuple[int, ...]:
    """The offsets [bytes] at which the ULog's flag-bits message says data were appended (its first
    incompatible flag, DATA_APPENDED), or () when it says none."""
    with open(path, "rb") as fh:
        head = fh.read(_FILE_HEADER_BYTES + 3 + 40)
    if len(head) < _FILE_HEADER_BYTES + 3 + 40:
        return ()
    size, kind = _MESSAGE_HEADER.unpack_from(head, _FILE_HEADER_BYTES)
    payload = _FILE_HEADER_BYTES + 3
    if kind != ord("B") or size < 40 or not head[payload + 8] & 1:
        return ()
    return tuple(o for o in struct.unpack_from("<3Q", head, payload + 16) if o)


def _check_framing(path: Path) -> None:
    """Warn of a cut log; refuse appended-data offsets that fall inside a message (a damaged flag-bits message:
    pyulog would stop reading there and drop what follows without a word); warn of offsets past the end."""
    offsets = appended_offsets(path)
    cut, starts = _walk(path, offsets)
    size = path.stat().st_size
    for offset in offsets:
        if offset >= size:
            warnings.warn(
                f"{path}: the flag bits say data were appended at byte {offset}, past the end of the file "
                f"({size} bytes): none read",
                DataQualityWarning,
                stacklevel=user_stacklevel(),
            )
        elif offset not in starts:
            raise InputError(
                f"{path}: the flag bits say data were appended at byte {offset}, where no message "
                "starts: a damaged log (read on, the data after that byte would be dropped)"
            )
    if cut is not None:
        warnings.warn(
            f"{path}: the file ends {cut[1]} byte(s) short inside its last message (at byte {cut[0]}): "
            "a truncated or damaged log; read up to there",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )


def _time_s(data: dict) -> np.ndarray:
    stamps = data["timestamp_sample"] if "timestamp_sample" in data else data["timestamp"]
    return np.asarray(stamps, dtype=float) * _US


def _choose(path: Path, topic: str, datasets: list, options: ReadOptions, id_field: str = "device_id"):
    """The instance of ``topic`` asked for (by ``--instance`` or ``--device-id``), or instance 0."""
    found = {d.multi_id: d for d in datasets if d.name == topic}
    if options.device_id is not None:
        for dataset in found.values():
            ids = np.unique(dataset.data.get(id_field, []))
            if options.device_id in ids:
                return dataset
        available = sorted({int(i) for d in found.values() for i in np.unique(d.data.get(id_field, []))})
        raise InputError(
            f"{path}: device_id={options.device_id}: no {topic} with that device id; "
            f"the log has {', '.join(map(str, available)) or 'none'}"
        )
    instance = 0 if options.instance is None else options.instance
    if instance not in found:
        raise InputError(
            f"{path}: instance={instance}: no {topic} instance {instance}; "
            f"the log has instance(s) {', '.join(map(str, sorted(found)))}"
        )
    if options.instance is None and len(found) > 1:
        warnings.warn(
            f"{path}: {len(found)} {topic} instances ({', '.join(map(str, sorted(found)))}); read instance 0, "
            "choose another with instance= or device_id=",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
    return found[instance]


def _from_sensor_gyro(path: Path, datasets: list, options: ReadOptions, metadata: dict):
    """(time, gyro, accel, temperature) from ``sensor_gyro`` and the ``sensor_accel`` of its instance."""
    gyro_set = _choose(path, "sensor_gyro", datasets, options)
    data = gyro_set.data
    time_s = _time_s(data)
    gyro = np.column_stack([data[a] for a in "xyz"]).astype(float) * _RAD
    temperature = np.asarray(data["temperature"], dtype=float) if "temperature" in data else None
    if temperature is not None and not np.isfinite(temperature).any():
        temperature = None
    metadata.update(
        topic="sensor_gyro",
        instance=int(gyro_set.multi_id),
        device_id=int(data["device_id"][0]) if "device_id" in data else None,
    )
    accel = None
    time_s, gyro, temperature = order_by_time(str(path), time_s, gyro, temperature)
    accel_sets = [d for d in datasets if d.name == "sensor_accel" and d.multi_id == gyro_set.multi_id]
    if accel_sets:
        adata = accel_sets[0].data
        if "device_id" in adata:  # a separate die (BMI055, SCHA63T) has an id of its own
            metadata["accel_device_id"] = int(adata["device_id"][0])
        what = f"sensor_accel instance {gyro_set.multi_id}"
        a_time, a_values = order_by_time(
            str(path), _time_s(adata), np.column_stack([adata[a] for a in "xyz"]).astype(float) * _MS2
        )
        accel, ok = match_by_time(str(path), what, time_s, a_time, a_values)
        keep = keep_matched(str(path), what, ok)
        time_s, gyro, accel = time_s[keep], gyro[keep], accel[keep]
        temperature = None if temperature is None else temperature[keep]
    return time_s, gyro, accel, temperature


def _from_vehicle_imu(path: Path, datasets: list, options: ReadOptions, metadata: dict):
    """(time, gyro, accel, None) from ``vehicle_imu``'s delta angles and velocities over their intervals."""
    imu = _choose(path, "vehicle_imu", datasets, options, id_field="gyro_device_id").data
    dt_s = np.asarray(imu["delta_angle_dt"], dtype=float) * _US
    good = dt_s > 0
    time_s = _time_s(imu)[good]
    gyro = np.column_stack([imu[f"delta_angle[{i}]"] for i in range(3)])[good] / dt_s[good, None] * _RAD
    dv_dt = np.asarray(imu["delta_velocity_dt"], dtype=float)[good] * _US
    accel = np.column_stack([imu[f"delta_velocity[{i}]"] for i in range(3)])[good] / dv_dt[:, None] * _MS2
    metadata.update(topic="vehicle_imu")
    return (*order_by_time(str(path), time_s, gyro, accel), None)


def _from_sensor_combined(path: Path, datasets: list, options: ReadOptions, metadata: dict):
    """(time, gyro, accel, None) from ``sensor_combined``."""
    combined = [d for d in datasets if d.name == "sensor_combined"][0].data
    time_s = _time_s(combined)
    gyro = np.column_stack([combined[f"gyro_rad[{i}]"] for i in range(3)]).astype(float) * _RAD
    accel = np.column_stack([combined[f"accelerometer_m_s2[{i}]"] for i in range(3)]).astype(float) * _MS2
    metadata.update(topic="sensor_combined")
    return (*order_by_time(str(path), time_s, gyro, accel), None)


#: the gyro topics in order of preference, each with the function that reads it
_TOPIC_READERS = {
    "sensor_gyro": _from_sensor_gyro,
    "vehicle_imu": _from_vehicle_imu,
    "sensor_combined": _from_sensor_combined,
}


def _warn_if_corrected(path: Path, topic: str, parameters: dict, metadata: dict) -> None:
    """PX4 applies its thermal compensation (``TC_G_ENABLE = 1``) in the sensors module, after ``sensor_gyro``:
    that topic is raw, ``vehicle_imu`` and ``sensor_combined`` are corrected. Fitting or applying a model to
    corrected data would correct twice."""
    enabled = int(parameters.get("TC_G_ENABLE", 0)) == 1
    metadata["px4_thermal_compensation"] = enabled
    # the installed thermal calibration, to judge it (gyrocomp.export.installed_calibration)
    metadata["autopilot_parameters"] = {k: float(v) for k, v in parameters.items() if k.startswith("TC_G")}
    metadata["corrected_onboard"] = enabled and topic != "sensor_gyro"
    if metadata["corrected_onboard"]:
        warnings.warn(
            f"{path}: TC_G_ENABLE = 1: {topic} is already corrected by PX4's thermal compensation; a "
            "model fitted or applied on it would correct twice (log sensor_gyro, the raw topic, or "
            "disable TC_G_ENABLE)",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )


def ulog_instances(path) -> tuple[int, ...]:
    """The uORB instances (``multi_id``) of the gyro topic :func:`read_ulog` reads in a ULog, sorted."""
    path = Path(path)
    check_magic(path, ULOG_MAGIC, "PX4 ULog", "name its real format with fmt=")
    pyulog = require("pyulog", "ulog", "reading PX4 ULog files")
    try:
        with foreign_output(str(path), "pyulog"):
            ulog = pyulog.ULog(str(path), list(GYRO_TOPICS), parse_header_only=False)
    except Exception as exc:  # pyulog raises bare Exceptions on corrupt files
        raise InputError(f"{path}: not a readable ULog ({foreign_message(exc)})") from None
    names = {d.name for d in ulog.data_list}
    topic = next((t for t in GYRO_TOPICS if t in names), None)
    if topic is None:
        raise InputError(f"{path}: no gyro topic ({', '.join(GYRO_TOPICS)}) in this ULog")
    return tuple(sorted({int(d.multi_id) for d in ulog.data_list if d.name == topic}))


def read_ulog(path, options: ReadOptions | None = None, progress: ProgressCallback | None = None) -> Recording:
    """Read a PX4 ULog into a :class:`Recording` [s, deg/s, g, degC].

    Parameters
    ----------
    path : path
        The ``.ulg`` file.
    options : ReadOptions, optional
        ``instance`` (uORB multi-instance, default 0) or ``device_id`` choose the sensor.
    progress : callable, optional
        Called with the fraction done.
    """
    options = options or ReadOptions()
    path = Path(path)
    check_magic(
        path, ULOG_MAGIC, "PX4 ULog", "name its real format with fmt=, or leave fmt= out to have it told from the file"
    )
    pyulog = require("pyulog", "ulog", "reading PX4 ULog files")
    if progress:
        progress(0.0)
    try:
        with foreign_output(str(path), "pyulog"):
            ulog = pyulog.ULog(str(path), list(GYRO_TOPICS) + ["sensor_accel"], parse_header_only=False)
    except Exception as exc:  # pyulog raises bare Exceptions on corrupt files
        raise InputError(f"{path}: not a readable ULog ({foreign_message(exc)})") from None
    _check_framing(path)
    if progress:
        progress(0.8)
    names = {d.name for d in ulog.data_list}
    topic = next((t for t in GYRO_TOPICS if t in names), None)
    if topic is None:
        with foreign_output(str(path), "pyulog"):
            topics = sorted({d.name for d in pyulog.ULog(str(path), parse_header_only=False).data_list})
        raise InputError(
            f"{path}: no gyro topic ({', '.join(GYRO_TOPICS)}) in this ULog; it has {', '.join(topics) or 'no data'}"
        )
    metadata = {"path": str(path), "format": "ulog", "autopilot": "px4"}
    time_s, gyro, accel, temperature = _TOPIC_READERS[topic](path, ulog.data_list, options, metadata)
    _warn_if_corrected(path, topic, ulog.initial_parameters, metadata)
    if temperature is None:
        warnings.warn(
            f"{path}: {metadata['topic']} carries no temperature; log sensor_gyro for temperature calibration "
            "(only noise analysis works without it)",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
    if progress:
        progress(1.0)
    return log_recording(path, options, time_s, gyro, accel, temperature, metadata)


register_reader(
    Reader(
        "ulog",
        "PX4 ULog, extra [ulog]",
        read_ulog,
        suffixes=(".ulg",),
        magic=(ULOG_MAGIC,),
        aliases=("ulg", "px4"),
        instances=ulog_instances,
    )
)
