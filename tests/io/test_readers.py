"""Log readers: real PX4, ArduPilot and NetCDF samples, files written here, unit conversions, bad input."""

from __future__ import annotations

import math
import re
import warnings

import h5py
import numpy as np
import pytest

from gyrocomp.errors import DataQualityWarning, InputError, MissingDependencyError
from gyrocomp.io import READERS, TableLayout, detect_format, read, sniff_format
from gyrocomp.io.log_samples import match_by_time, order_by_time

from ..conftest import run, shared_dataset
from tests.io.log_writers import write_bag, write_dataflash, write_recording_bag, write_ulog

RAD_TO_DEG = 180.0 / math.pi
G = 9.80665

pyulog = pytest.importorskip("pyulog", reason="the [ulog] extra (pyulog) is not installed")
pytest.importorskip("pymavlink", reason="the [dataflash] extra (pymavlink) is not installed")
pytest.importorskip("rosbags", reason="the [ros] extra (rosbags) is not installed")


# -- PX4 ULog -----------------------------------------------------------------------------------------
def test_ulog_real_sample_instances_units_and_times():
    path = shared_dataset("px4-pyulog-samples") / "sample_log_small.ulg"
    raw = {
        d.multi_id: d.data
        for d in pyulog.ULog(str(path), ["sensor_gyro", "sensor_accel"]).data_list
        if d.name == "sensor_gyro"
    }
    with pytest.warns(DataQualityWarning, match=r"3 sensor_gyro instances \(0, 1, 2\); read instance 0"):
        first = read(path)
    for instance, (low, high) in {0: (40.0, 40.4), 1: (28.2, 28.4), 2: (29.4, 29.7)}.items():
        rec = read(path, instance=instance) if instance else first
        assert rec.n_samples == 6
        assert low - 0.05 <= rec.temperature_degc.min() and rec.temperature_degc.max() <= high + 0.05
        np.testing.assert_allclose(rec.gyro_dps[:, 2], raw[instance]["z"] * RAD_TO_DEG, rtol=1e-6)
        np.testing.assert_allclose(rec.time_s, raw[instance]["timestamp_sample"] * 1e-6)
        # a board lying still: gravity, in g, along -z
        assert np.allclose(np.linalg.norm(rec.accel_g, axis=1), 1.0, atol=0.03)
    assert first.metadata["device_id"] == 2424842
    by_id = read(path, device_id=int(raw[2]["device_id"][0]))
    assert by_id.metadata["instance"] == 2


def test_ulog_without_sensor_gyro_falls_back_to_sensor_combined_and_says_temperature_is_missing():
    path = shared_dataset("px4-pyulog-samples") / "sample.ulg"
    with pytest.warns(DataQualityWarning, match="sensor_combined carries no temperature"):
        rec = read(path)
    assert rec.metadata["topic"] == "sensor_combined" and rec.temperature_degc is None
    assert rec.n_samples > 17000 and abs(rec.rate_hz - 250) < 10
    assert np.median(np.linalg.norm(rec.accel_g, axis=1)) == pytest.approx(1.0, abs=0.1)


def _gyro_topic(n=200, rate_hz=50.0, multi_id=0, device_id=7):
    t_us = (1_000_000 + np.arange(n) * 1e6 / rate_hz).astype(np.uint64)
    return ("sensor_gyro", multi_id), {
        "timestamp": ("uint64_t", t_us),
        "device_id": ("uint32_t", np.full(n, device_id, dtype=np.uint32)),
        "x": ("float", np.full(n, 0.01, dtype=np.float32)),
        "y": ("float", np.zeros(n, dtype=np.float32)),
        "z": ("float", np.linspace(-0.02, 0.02, n).astype(np.float32)),
        "temperature": ("float", np.linspace(20, 40, n).astype(np.float32)),
    }


def test_ulog_written_here_converts_units_and_matches_accel_by_time(tmp_path):
    key, gyro = _gyro_topic()
    n = 100  # accelerometer at half the rate, offset by 3 ms
    t_acc = (1_003_000 + np.arange(n) * 40_000).astype(np.uint64)
    accel = {
        "timestamp": ("uint64_t", t_acc),
        "device_id": ("uint32_t", np.full(n, 9, dtype=np.uint32)),
        "x": ("float", np.zeros(n, np.float32)),
        "y": ("float", np.linspace(0, 1, n).astype(np.float32)),
        "z": ("float", np.full(n, -G, np.float32)),
    }
    path = tmp_path / "log.ulg"
    write_ulog(path, {key: gyro, ("sensor_accel", 0): accel})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DataQualityWarning)  # the last gyro samples lie past the last accel
        rec = read(path)
    assert rec.rate_hz == pytest.approx(50.0)
    assert rec.metadata["device_id"] == 7 and rec.metadata["accel_device_id"] == 9  # each sensor's own id
    np.testing.assert_allclose(rec.gyro_dps[:, 0], 0.01 * RAD_TO_DEG, rtol=1e-6)
    np.testing.assert_allclose(rec.accel_g[:, 2], -1.0, rtol=1e-6)
    expected_y = np.interp(rec.time_s, t_acc * 1e-6, np.linspace(0, 1, n).astype(np.float32)) / G
    np.testing.assert_allclose(rec.accel_g[:, 1], expected_y, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(
        rec.temperature_degc[[0, -1]], [20, np.linspace(20, 40, 200)[rec.n_samples - 1]], rtol=1e-6
    )


def test_ulog_cut_inside_a_message_is_said_and_a_whole_one_is_not(tmp_path):
    key, gyro = _gyro_topic()
    whole = tmp_path / "whole.ulg"
    write_ulog(whole, {key: gyro})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        full = read(whole)
    cut = tmp_path / "cut.ulg"
    cut.write_bytes(whole.read_bytes()[:-5])
    with pytest.warns(
        DataQualityWarning,
        match=r"cut.ulg: the file ends \d+ byte\(s\) short inside its last "
        r"message \(at byte \d+\): a truncated or damaged log",
    ):
        short = read(cut)
    assert short.n_samples == full.n_samples - 1


def test_ulog_drop_nonfinite_drops_the_row_the_refusal_names(tmp_path):
    """The refusal of a NaN sample advises drop_nonfinite; for logs it works as for tables (it was ignored)."""
    key, gyro = _gyro_topic()
    values = gyro["x"][1].copy()
    values[5] = np.nan
    path = tmp_path / "hole.ulg"
    write_ulog(path, {key: {**gyro, "x": ("float", values)}})
    with pytest.raises(
        InputError,
        match=r"hole.ulg: row 6, column 'gyro_x': nan is not a finite number; .* "
        r"\(drop_nonfinite=True\)",
    ):
        read(path)
    with pytest.warns(DataQualityWarning, match=r"hole.ulg: dropped 1 of 200 rows with empty, NaN or infinite"):
        rec = read(path, drop_nonfinite=True)
    assert rec.n_samples == 199 and rec.row_numbers[5] == 7 and rec.metadata["rows_dropped"] == 1


def test_ulog_without_gyro_topics_names_what_it_has(tmp_path):
    path = tmp_path / "baro.ulg"
    t = (np.arange(10) * 1000).astype(np.uint64)
    write_ulog(path, {("sensor_baro", 0): {"timestamp": ("uint64_t", t), "temperature": ("float", np.ones(10))}})
    with pytest.raises(
        InputError,
        match=r"baro.ulg: no gyro topic \(sensor_gyro, vehicle_imu, sensor_combined\) "
        r"in this ULog; it has sensor_baro",
    ):
        read(path)


def test_ulog_instance_and_device_id_that_are_not_there(tmp_path):
    path = tmp_path / "one.ulg"
    write_ulog(path, dict([_gyro_topic()]))
    with pytest.raises(InputError, match=r"instance=3: no sensor_gyro instance 3; the log has instance\(s\) 0"):
        read(path, instance=3)
    with pytest.raises(InputError, match=r"device_id=5: no sensor_gyro with that device id; the log has 7"):
        read(path, device_id=5)


# -- ArduPilot DataFlash ------------------------------------------------------------------------------
_IMU_COLUMNS = [
    ("TimeUS", "Q"),
    ("I", "B"),
    ("GyrX", "f"),
    ("GyrY", "f"),
    ("GyrZ", "f"),
    ("AccX", "f"),
    ("AccY", "f"),
    ("AccZ", "f"),
    ("T", "f"),
]
_TCLR_COLUMNS = [
    ("TimeUS", "Q"),
    ("I", "B"),
    ("SType", "B"),
    ("Temp", "f"),
    ("X", "f"),
    ("Y", "f"),
    ("Z", "f"),
    ("NDone", "I"),
]


def test_dataflash_real_sample_is_read_up_to_its_cut_end():
    path = shared_dataset("ardupilot-pymavlink-sample") / "test.BIN"
    with pytest.warns(DataQualityWarning) as caught:
        imu1 = read(path, instance=0)
    said = " | ".join(str(w.message) for w in caught)
    assert re.search(r"the log ends mid-message \(\d+ bytes after the last whole message", said)
    assert "AHRS_ORIENTATION = 8: the logged IMU axes are the board's" in said
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DataQualityWarning)
        imu2 = read(path, instance=1)
    assert imu1.n_samples == 45 and imu2.n_samples == 45
    assert 44.4 <= imu1.temperature_degc.min() and imu1.temperature_degc.max() <= 44.5
    assert abs(np.mean(imu2.temperature_degc) - 39.9) < 0.1
    # first IMU record, as pymavlink's own message parser reads it
    from pymavlink import DFReader

    log = DFReader.DFReader_binary(str(path))
    try:
        msg = log.recv_match(type="IMU")
    finally:
        log.close()
    assert imu1.time_s[0] == pytest.approx(msg.TimeUS * 1e-6)
    np.testing.assert_allclose(imu1.gyro_dps[0], np.array([msg.GyrX, msg.GyrY, msg.GyrZ]) * RAD_TO_DEG, rtol=1e-6)
    np.testing.assert_allclose(imu1.accel_g[0], np.array([msg.AccX, msg.AccY, msg.AccZ]) / G, rtol=1e-6)


def test_dataflash_instance_field_and_tclr_records(tmp_path):
    n = 60
    imu = [
        (1_000_000 + i * 10_000 + k, k, 0.001 * i, 0.0, -0.002, 0.0, 0.1, -G, 25.0 + 10 * k + 0.01 * i)
        for i in range(n)
        for k in (0, 1)
    ]
    tclr = [(2_000_000 + i * 100_000 + s, 0, s, 20.0 + i, 0.01 * i, 0.0, 0.0, i) for i in range(n) for s in (0, 1)]
    path = tmp_path / "tcal.bin"
    write_dataflash(path, {"IMU": (130, _IMU_COLUMNS, imu), "TCLR": (131, _TCLR_COLUMNS, tclr)})
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a whole log, one instance asked for: nothing to say
        second = read(path, instance=1)
    np.testing.assert_allclose(second.temperature_degc, 35.0 + 0.01 * np.arange(n), rtol=1e-6)
    np.testing.assert_allclose(second.gyro_dps[:, 2], -0.002 * RAD_TO_DEG, rtol=1e-6)
    learned = read(path, record="TCLR")
    # SType 1 is the gyro (rad/s), SType 0 the accelerometer (m/s^2), as ArduPilot's tempcal_IMU.py reads them
    np.testing.assert_allclose(learned.temperature_degc, 20.0 + np.arange(n))
    np.testing.assert_allclose(learned.gyro_dps[:, 0], 0.01 * np.arange(n) * RAD_TO_DEG, rtol=1e-6)
    np.testing.assert_allclose(
        learned.accel_g[:, 0],
        np.interp(learned.time_s, 2.0 + 0.1 * np.arange(n), 0.01 * np.arange(n)) / G,
        rtol=1e-5,
        atol=1e-9,
    )
    with pytest.raises(InputError, match=r"instance=2: no IMU instance 2; the log has 0, 1"):
        read(path, instance=2)
    with pytest.raises(InputError, match=r"record: unknown DataFlash record 'GPS'; use IMU or TCLR"):
        read(path, record="GPS")


def test_dataflash_truncated_mid_message_reads_the_whole_ones(tmp_path):
    rows = [(1_000_000 + i * 10_000, 0, 0.0, 0.0, 0.0, 0.0, 0.0, -G, 30.0) for i in range(20)]
    path = tmp_path / "cut.bin"
    write_dataflash(path, {"IMU": (130, _IMU_COLUMNS, rows)}, cut=7)
    with pytest.warns(DataQualityWarning, match=r"cut.bin: the log ends mid-message \(33 bytes after"):
        rec = read(path)
    assert rec.n_samples == 19


def test_dataflash_garbage_chatter_of_pymavlink_is_one_warning(tmp_path, capfd):
    """pymavlink (and its C indexer) print a line per bad byte; gyrocomp says it once and reads what is whole."""
    rows = [(1_000_000 + i * 10_000, 0, 0.0, 0.0, 0.0, 0.0, 0.0, -G, 30.0) for i in range(50)]
    path = tmp_path / "noisy.bin"
    write_dataflash(path, {"IMU": (130, _IMU_COLUMNS, rows)})
    data = bytearray(path.read_bytes())
    data[len(data) // 2 : len(data) // 2] = bytes(range(40))  # 40 bytes of garbage between two messages
    path.write_bytes(bytes(data))
    capfd.readouterr()
    with pytest.warns(
        DataQualityWarning,
        match=r"noisy.bin: pymavlink reported \d+ line\(s\) while reading, the "
        r"first: .*; the log is probably damaged in places",
    ) as record:
        rec = read(path)
    assert rec.n_samples == 50 and len(record) == 1
    assert capfd.readouterr() == ("", "")  # nothing printed past gyrocomp


@pytest.mark.parametrize("fast_index", ["0", "1"])
def test_dataflash_fmt_record_shorter_than_a_header_is_refused_not_parsed_for_ever(tmp_path, monkeypatch, fast_index):
    """A FMT record of length 0 (a zeroed stretch of a damaged card) made pymavlink read one message for ever, with
    its C indexer and without: refused in one line now."""
    monkeypatch.setenv("PYMAVLINK_FAST_INDEX", fast_index)
    rows = [(1_000_000 + i * 10_000, 0, 0.0, 0.0, 0.0, 0.0, 0.0, -G, 30.0) for i in range(50)]
    path = tmp_path / "zeroed.bin"
    write_dataflash(path, {"IMU": (130, _IMU_COLUMNS, rows)})
    data = bytearray(path.read_bytes())
    boundary = 89 + 40 * 25  # after the FMT record and 25 IMU records of 40 bytes
    data[boundary:boundary] = b"\xa3\x95\x80" + bytes([200, 0]) + bytes(84) + b"\xa3\x95\xc8"
    path.write_bytes(bytes(data))
    with pytest.raises(
        InputError,
        match=r"zeroed.bin: not a readable DataFlash log: a FMT record defines message type 200 \(''\) with a "
        r"length of 0 bytes, under its 3-byte header \(a corrupt log\)",
    ):
        read(path)


def test_dataflash_imu_format_without_its_fields_or_of_another_length_is_refused(tmp_path):
    rows = [(1_000_000 + i * 10_000, 0, 0.0, 0.0, 0.0, 0.0, 0.0, -G, 30.0) for i in range(20)]
    renamed = [("GyrQ", c) if n == "GyrY" else (n, c) for n, c in _IMU_COLUMNS]
    path = tmp_path / "renamed.bin"
    write_dataflash(path, {"IMU": (130, renamed, rows)})
    with pytest.raises(
        InputError,
        match=r"renamed.bin: the log's format of IMU messages has no field GyrY \(fields TimeUS, I, GyrX, GyrQ,",
    ):
        read(path)
    path = tmp_path / "longer.bin"
    write_dataflash(path, {"IMU": (130, _IMU_COLUMNS, rows)})
    data = bytearray(path.read_bytes())
    data[4] = 44  # the FMT record's Length: 44 bytes for a message of 40
    path.write_bytes(bytes(data))
    with pytest.raises(InputError, match=r"longer.bin: the log's format of IMU messages has 44 bytes for fields of 40"):
        read(path)


def test_dataflash_tclr_asked_for_but_absent(tmp_path):
    path = tmp_path / "imu.bin"
    write_dataflash(path, {"IMU": (130, _IMU_COLUMNS, [(1000 * i, 0, 0, 0, 0, 0, 0, -G, 30.0) for i in range(5)])})
    with pytest.raises(InputError, match=r"record=TCLR: no TCLR records in this log"):
        read(path, record="TCLR")


# -- ROS bags -------------------------------------------------------------------------------------------
@pytest.mark.parametrize("ros2", [False, True], ids=["ros1", "ros2"])
def test_rosbag_imu_and_temperature_matched_by_time(tmp_path, ros2):
    path = tmp_path / ("bag" if ros2 else "imu.bag")
    write_bag(path, ros2)
    rec = read(path)
    assert rec.metadata["imu_topic"] == "/imu/data" and rec.metadata["temperature_topic"] == "/imu/temperature"
    assert rec.rate_hz == pytest.approx(100.0)
    np.testing.assert_allclose(rec.time_s, 100.0 + np.arange(rec.n_samples) / 100.0, atol=1e-9)
    np.testing.assert_allclose(rec.gyro_dps[:, 0], 0.001 * np.arange(rec.n_samples) * RAD_TO_DEG, rtol=1e-12)
    np.testing.assert_allclose(rec.accel_g[:, 2], 1.0, rtol=1e-12)
    # temperature rises 1 degC per 10 samples: linear interpolation is exact; the last 9 IMU samples,
    # within 5 temperature periods of the last temperature, hold its value
    np.testing.assert_allclose(rec.temperature_degc, 20.0 + np.minimum(np.arange(rec.n_samples), 90) / 10.0, atol=1e-9)
    assert rec.n_samples == 100
    assert detect_format(path) == "rosbag"


def test_a_bag_is_read_from_its_own_files_and_type_names_only(tmp_path):
    """A ROS 1 connection whose message type is Python rather than a ROS name is refused before rosbags makes
    code of it; a ROS 2 bag folder whose storage file links out of the folder is refused, naming the link."""
    from rosbags.rosbag1 import Writer

    marker = tmp_path / "ran"
    hostile = f"x/msg/A': (), **__import__('os').system('touch {marker}') and {{}}, 'b"
    with Writer(tmp_path / "hostile.bag") as writer:
        connection = writer.add_connection("/evil", hostile, msgdef="int32 a", md5sum="0" * 32)
        writer.write(connection, 1, b"\x01\x00\x00\x00")
    with pytest.raises(InputError, match=r"hostile.bag: topic '/evil' has the message type .*, not a ROS type name"):
        read(tmp_path / "hostile.bag")
    assert not marker.exists()
    folder = tmp_path / "bag"
    write_bag(folder, ros2=True)
    storage = next(f for f in folder.iterdir() if f.name != "metadata.yaml")
    elsewhere = tmp_path / "elsewhere" / storage.name
    elsewhere.parent.mkdir()
    storage.rename(elsewhere)
    storage.symlink_to(elsewhere)
    with pytest.raises(
        InputError,
        match=rf"bag: {re.escape(storage.name)} links to .*elsewhere.*, outside the bag "
        r"folder; gyrocomp reads only the bag's own files",
    ):
        read(folder)
    result = run("convert", folder, tmp_path / "out.csv")
    assert result.returncode == 2 and "outside the bag folder" in result.stderr and not (tmp_path / "out.csv").exists()


@pytest.mark.parametrize("mcap", [False, True], ids=["sqlite3", "mcap"])
def test_a_ros2_folders_type_names_are_checked_from_its_metadata_before_its_storage_is_opened(
    mcap, tmp_path, monkeypatch
):
    """A ROS 2 bag folder's topic types (rosbags takes its connections from ``metadata.yaml``) are checked there,
    without opening the storage (rosbags' sqlite3 storage counts every topic's messages when it opens): a hostile
    type name is refused before rosbags makes code of it, and a bag that reads is opened once."""
    from rosbags.rosbag2.reader import DirectoryReader

    folder = tmp_path / "bag"
    write_bag(folder, ros2=True, mcap=mcap)
    opened = []
    open_folder = DirectoryReader.open
    monkeypatch.setattr(DirectoryReader, "open", lambda self: opened.append(1) or open_folder(self))
    assert read(folder).n_samples == 100
    assert len(opened) == 1
    marker = tmp_path / "ran"
    hostile = f"x/msg/A': (), **__import__('os').system('touch {marker}') and {{}}, 'b"
    yaml = (folder / "metadata.yaml").read_text()
    assert "type: sensor_msgs/msg/Temperature" in yaml
    (folder / "metadata.yaml").write_text(yaml.replace("type: sensor_msgs/msg/Temperature", f'type: "{hostile}"'))
    opened.clear()
    with pytest.raises(InputError, match=r"bag: topic '/imu/temperature' has the message type .*, not a ROS type name"):
        read(folder)
    assert not marker.exists() and not opened


def _ulog_with_appended_offset(tmp_path, name: str, offset_of):
    import struct

    n = 200
    fields = {
        "timestamp": ("uint64_t", (1_000_000 + np.arange(n) * 10_000).astype(np.uint64)),
        **{a: ("float", np.zeros(n, np.float32)) for a in "xyz"},
        "temperature": ("float", np.full(n, 30.0, np.float32)),
    }
    write_ulog(tmp_path / "plain.ulg", {("sensor_gyro", 0): fields})
    data = bytearray((tmp_path / "plain.ulg").read_bytes())
    payload = 16 + 3  # the flag-bits message is the first: incompat flags at +8, appended offsets at +16
    data[payload + 8] = 1  # DATA_APPENDED
    data[payload + 16 : payload + 24] = struct.pack("<Q", offset_of(len(data)))
    (tmp_path / name).write_bytes(bytes(data))
    return tmp_path / name


def test_ulog_appended_data_offsets_are_checked(tmp_path):
    """The flag bits' appended-data offset inside a message (pyulog would stop there and drop the rest without a
    word) is refused naming the byte; one past the end is a warning, and the log is read whole."""
    inside = _ulog_with_appended_offset(tmp_path, "inside.ulg", lambda size: size // 2 + 1)
    with pytest.raises(
        InputError,
        match=r"inside.ulg: the flag bits say data were appended at byte \d+, where no "
        r"message starts: a damaged log",
    ):
        read(inside)
    past = _ulog_with_appended_offset(tmp_path, "past.ulg", lambda size: 10**12)
    with pytest.warns(
        DataQualityWarning,
        match=r"past.ulg: the flag bits say data were appended at byte "
        r"1000000000000, past the end of the file \(\d+ bytes\): none read",
    ):
        rec = read(past)
    assert rec.n_samples == 200


def test_compressed_tables_are_streamed_and_archives_refused(tmp_path):
    """A gzip CSV reads as the plain one; a zip archive (which may hold several tables) is refused in one line; a
    gzip bomb (400 MB of one line in 0.4 MB) is refused by the chunked reader, not read into memory."""
    import gzip
    import zipfile

    text = "time,gyro_x,temperature\n" + "".join(f"{k},{0.01 * k},{20 + 0.1 * k}\n" for k in range(50))
    (tmp_path / "t.csv").write_text(text)
    with gzip.open(tmp_path / "t.csv.gz", "wt") as fh:
        fh.write(text)
    plain, packed = read(tmp_path / "t.csv"), read(tmp_path / "t.csv.gz")
    np.testing.assert_array_equal(plain.gyro_dps, packed.gyro_dps)
    with zipfile.ZipFile(tmp_path / "t.zip", "w") as archive:
        archive.writestr("a.csv", text)
        archive.writestr("b.csv", text)
    result = run("convert", tmp_path / "t.zip", tmp_path / "out.csv")
    assert result.returncode == 2 and len(result.stderr.strip().splitlines()) == 1 and "t.zip" in result.stderr
    with gzip.open(tmp_path / "bomb.csv.gz", "wb", compresslevel=1) as fh:
        fh.write(b"time,gyro_x,temperature\n")
        for _ in range(40):
            fh.write(b"1" * 10_000_000)
    result = run("convert", tmp_path / "bomb.csv.gz", tmp_path / "bomb.csv")
    assert result.returncode == 2 and "bomb.csv.gz: a line over 1 MB long, which no row of a table is" in result.stderr
    assert not (tmp_path / "bomb.csv").exists()


def test_rosbag_topic_choices_and_missing_topics(tmp_path):
    path = tmp_path / "two.bag"
    write_bag(path, ros2=False, temperature=False, imu_topics=("/imu0", "/imu1"))
    with pytest.raises(InputError, match=r"2 sensor_msgs/msg/Imu topics \(/imu0, /imu1\); choose one with imu_topic="):
        read(path)
    with pytest.raises(
        InputError,
        match=r"imu_topic=/imu9: no such topic in the bag; its sensor_msgs/msg/Imu "
        r"topics are /imu0, /imu1; its sensor_msgs/msg/Temperature topics are none$",
    ):
        read(path, imu_topic="/imu9")
    with_temperature = tmp_path / "one.bag"
    write_bag(with_temperature, ros2=False)
    with pytest.raises(
        InputError,
        match=r"temperature_topic=/t: no such topic in the bag; its sensor_msgs/msg/Imu "
        r"topics are /imu/data; its sensor_msgs/msg/Temperature topics are "
        r"/imu/temperature$",
    ):
        read(with_temperature, temperature_topic="/t")
    with pytest.raises(InputError, match=r"temperature_topic=/imu1: the topic has type sensor_msgs/msg/Imu"):
        read(path, imu_topic="/imu0", temperature_topic="/imu1")
    with pytest.warns(DataQualityWarning, match="no sensor_msgs/msg/Temperature topic"):
        rec = read(path, imu_topic="/imu1")
    assert rec.temperature_degc is None and rec.n_samples == 100


# -- HDF5 / NetCDF-4 --------------------------------------------------------------------------------------
def test_netcdf_cats_file_reads_without_options_and_matches_the_npz_copy():
    folder = shared_dataset("skdivemove-cats-tempcal")
    rec = read(folder / "cats_temperature_calib.nc")
    npz = np.load(folder / "cats_temperature_calib_1hz.npz")
    assert rec.n_samples == 268081 and rec.rate_hz == 1.0
    # the npz is a float32 copy: gyro within 5e-4 mrad/s, temperature within 1e-6 degC (its README)
    np.testing.assert_allclose(rec.gyro_dps, npz["gyro_mrad_s"] * 0.18 / math.pi, atol=5e-4 * 0.18 / math.pi)
    np.testing.assert_allclose(rec.accel_g, npz["acc_m_s2"] / G, atol=1e-5)
    np.testing.assert_allclose(rec.temperature_degc, npz["temperature_c"], atol=2e-6)
    np.testing.assert_allclose(rec.time_s - rec.time_s[0], npz["t_s"] - npz["t_s"][0])


def test_hdf5_of_strings_and_damaged_hdf5_are_refused_in_one_line(tmp_path):
    strings = tmp_path / "strings.h5"
    with h5py.File(strings, "w") as f:
        f["time"] = np.array([b"a", b"b", b"c"])
        f["gyro_z"] = np.array([b"1", b"2", b"3"])
    with pytest.raises(InputError, match=r"strings.h5: dataset '/time' holds \|S1 values, not numbers"):
        read(strings)
    whole = tmp_path / "whole.h5"
    with h5py.File(whole, "w") as f:
        f["time"], f["gyro_z"] = np.arange(100.0), np.zeros(100)
    cut = tmp_path / "cut.h5"
    cut.write_bytes(whole.read_bytes()[: whole.stat().st_size // 2])
    with pytest.raises(InputError, match=r"cut.h5: not a readable HDF5 file \(.*truncated file.*\); is it damaged"):
        read(cut)
    result = run("allan", cut)
    assert result.returncode == 2 and result.stderr.count("\n") == 1 and "not a readable HDF5 file" in result.stderr


def test_hdf5_rows_dropped_for_non_finite_values_are_said(tmp_path):
    path = tmp_path / "holes.h5"
    gyro = np.zeros(50)
    gyro[7] = np.nan
    with h5py.File(path, "w") as f:
        f["time"], f["gyro_z"], f["temperature"] = np.arange(50.0), gyro, np.linspace(20, 30, 50)
    with pytest.raises(InputError, match=r"holes.h5: row 8, column 'gyro_z': nan is not a finite number"):
        read(path)
    with pytest.warns(DataQualityWarning, match=r"holes.h5: dropped 1 of 50 rows with empty, NaN or infinite values"):
        rec = read(path, drop_nonfinite=True)
    assert rec.n_samples == 49 and rec.row_numbers[7] == 9 and rec.temperature_degc.shape == (49,)


def test_hdf5_with_a_column_mapping_and_units_attributes(tmp_path):
    path = tmp_path / "log.h5"
    n = 50
    with h5py.File(path, "w") as f:
        f["imu/t_ms"] = np.arange(n) * 10.0
        f["imu/wz"] = np.full(n, 2.0)
        f["imu/wz"].attrs["units"] = "rad/s"
        f["imu/acc"] = np.tile([0.0, 0.0, -G], (n, 1))
        f["imu/acc"].attrs["units"] = "m/s^2"
        f["imu/temp_k"] = np.full(n, 300.0)
        f["imu/temp_k"].attrs["units"] = "K"
    layout = TableLayout(
        columns={"time": "imu/t_ms", "gyro_z": "imu/wz", "accel": "imu/acc", "temperature": "imu/temp_k"},
        time_unit="ms",
    )
    rec = read(path, layout)
    assert rec.gyro_axes == ("gyro_z",) and rec.rate_hz == pytest.approx(100.0)
    np.testing.assert_allclose(rec.gyro_dps[:, 0], 2.0 * RAD_TO_DEG)
    np.testing.assert_allclose(rec.accel_g[:, 2], -1.0)
    np.testing.assert_allclose(rec.temperature_degc, 26.85)
    with pytest.raises(InputError, match=r"columns={'gyro_z': 'wz'}: no dataset 'wz'; the file has imu/acc"):
        read(path, TableLayout(columns={"time": "imu/t_ms", "gyro_z": "wz"}))
    with pytest.raises(InputError, match=r"no time dataset \(the file has imu/acc, .*\); map one with columns="):
        read(path)
    # a units attribute gyrocomp does not know is said, not read silently as deg/s
    with h5py.File(path, "a") as f:
        f["imu/wz"].attrs["units"] = "furlongs/fortnight"
    with pytest.warns(
        DataQualityWarning,
        match=r"dataset /imu/wz has units 'furlongs/fortnight', which gyrocomp "
        r"does not know; read as deg/s \(set gyro_unit= if that is wrong\)",
    ):
        read(path, TableLayout(columns={"time": "imu/t_ms", "gyro_z": "imu/wz"}, time_unit="ms"))


def test_hdf5_reads_only_the_file_it_is_given(tmp_path):
    """External storage, virtual datasets and external links would copy another local file's bytes into the
    output as gyro values: each is refused in one line naming the dataset; the other file is never read."""
    secret = tmp_path / "secret.bin"
    secret.write_bytes(np.arange(100.0).tobytes())
    outside = tmp_path / "outside.h5"
    with h5py.File(outside, "w") as f:
        f["gyro_z"] = np.arange(100.0)
    cases = {}
    path = cases["is stored in external files"] = tmp_path / "external.h5"
    with h5py.File(path, "w") as f:
        f["time"] = np.arange(100.0)
        f.create_dataset("gyro_z", shape=(100,), dtype="<f8", external=[(str(secret), 0, 800)])
    path = cases["is a virtual dataset mapped onto other files"] = tmp_path / "virtual.h5"
    with h5py.File(path, "w") as f:
        f["time"] = np.arange(100.0)
        layout = h5py.VirtualLayout(shape=(100,), dtype="<f8")
        layout[:] = h5py.VirtualSource(str(outside), "gyro_z", shape=(100,))
        f.create_virtual_dataset("gyro_z", layout)
    path = cases["lies in another file, .*outside.h5.* \\(an external link\\)"] = tmp_path / "link.h5"
    with h5py.File(path, "w") as f:
        f["time"] = np.arange(100.0)
        f["gyro_z"] = h5py.ExternalLink(str(outside), "gyro_z")
    for how, path in cases.items():
        with pytest.raises(InputError, match=rf"{path.name}: dataset '/gyro_z' {how}; gyrocomp reads only the file"):
            read(path)
        result = run("convert", path, tmp_path / "out.csv")
        assert result.returncode == 2 and result.stderr.count("\n") == 1 and "reads only the file" in result.stderr
        assert not (tmp_path / "out.csv").exists()


# -- format detection and helpers ------------------------------------------------------------------------
def test_formats_are_told_from_the_first_bytes_not_only_the_suffix(tmp_path):
    assert sniff_format(b"ULog\x01\x12\x35\x01") == "ulog"
    assert sniff_format(b"\x89HDF\r\n\x1a\n") == "hdf5"
    assert sniff_format(b"#ROSBAG V2.0\n") == "rosbag"
    assert sniff_format(b"PAR1") == "parquet"
    assert sniff_format(b"time,gyro_z\n") is None
    disguised = tmp_path / "flight.dat"
    write_ulog(disguised, dict([_gyro_topic()]))
    assert detect_format(disguised) == "ulog"
    assert detect_format(tmp_path / "later.BIN") == "dataflash"  # not there yet: the suffix decides
    with pytest.raises(InputError, match=rf"fmt: unknown format 'xls'; use one of {', '.join(READERS)}$"):
        detect_format(disguised, "xls")
    assert detect_format(disguised, "px4") == "ulog"


def test_a_file_that_is_not_the_named_format_says_what_it_looks_like(tmp_path):
    csv = tmp_path / "run.csv"
    csv.write_text("time,gyro_z\n0,1\n1,2\n")
    with pytest.raises(InputError, match=r"run.csv: not a PX4 ULog file \(it starts with b'time,gyr'\)"):
        read(csv, fmt="ulog")
    ulog = tmp_path / "x.ulg"
    write_ulog(ulog, dict([_gyro_topic()]))
    with pytest.raises(InputError, match=r"x.ulg: not a ArduPilot DataFlash file \(it looks like ulog\)"):
        read(ulog, fmt="dataflash")
    with pytest.raises(InputError, match=r"x.ulg: not a HDF5/NetCDF-4 file \(it looks like ulog\)"):
        read(ulog, fmt="hdf5")
    with pytest.raises(InputError, match=r"x.ulg: not a readable ROS bag"):
        read(ulog, fmt="rosbag")


def test_missing_extra_is_named_in_one_line(monkeypatch, tmp_path):
    import sys

    monkeypatch.setitem(sys.modules, "pyulog", None)  # makes "import pyulog" fail as if it were not installed
    path = tmp_path / "x.ulg"
    write_ulog(path, dict([_gyro_topic()]))
    with pytest.raises(
        MissingDependencyError,
        match=r"^reading PX4 ULog files needs the optional package pyulog; "
        r"install it with: pip install 'gyrocomp\[ulog\]' \(from a clone of the "
        r"repository: pip install -e '\.\[ulog\]'\)$",
    ):
        read(path)


def test_order_by_time_sorts_and_drops_repeats():
    with pytest.warns(DataQualityWarning, match=r"1 sample\(s\) out of time order were sorted|2 sample"):
        t, v = order_by_time("f", np.array([0.0, 2.0, 1.0, 2.0, 3.0]), np.arange(5.0))
    np.testing.assert_array_equal(t, [0, 1, 2, 3])
    np.testing.assert_array_equal(v, [0, 2, 1, 4])


def test_match_by_time_interpolates_and_marks_what_is_too_far():
    target = np.array([0.5, 1.5, 2.5, 50.0])
    values, ok = match_by_time("f", "temperature", target, np.array([0.0, 1.0, 2.0, 3.0]), np.array([0.0, 10, 20, 30]))
    np.testing.assert_allclose(values[:3], [5, 15, 25])
    assert ok.tolist() == [True, True, True, False] and np.isnan(values[3])
    with pytest.raises(InputError, match=r"f: temperature has 1 sample\(s\); at least 2 are needed"):
        match_by_time("f", "temperature", target, np.array([0.0]), np.array([1.0]))


# -- through the command line ------------------------------------------------------------------------------
def test_cli_fits_applies_and_converts_a_ulog_directly(tmp_path):
    n, rate_hz = 3000, 10.0
    temperature = np.linspace(10, 50, n)
    bias_rad_s = 1e-3 * (temperature - 30) + 2e-5 * (temperature - 30) ** 2
    rng = np.random.default_rng(0)
    t_us = (1_000_000 + np.arange(n) * 1e6 / rate_hz).astype(np.uint64)
    fields = {"timestamp": ("uint64_t", t_us), "device_id": ("uint32_t", np.full(n, 7, np.uint32))}
    for axis in "xyz":
        fields[axis] = ("float", (bias_rad_s + 1e-5 * rng.standard_normal(n)).astype(np.float32))
    fields["temperature"] = ("float", temperature.astype(np.float32))
    log = tmp_path / "cal.ulg"
    write_ulog(log, {("sensor_gyro", 0): fields})
    r = run("fit", log, "-o", tmp_path / "model.json", "--temperature", "poly:2", "--hysteresis", "none")
    assert r.returncode == 0, r.stderr
    r = run("apply", tmp_path / "model.json", log, "-o", tmp_path / "out.csv")
    assert r.returncode == 0, r.stderr
    import pandas as pd

    out = pd.read_csv(tmp_path / "out.csv")
    assert list(out.columns) == ["time", "gyro_x", "gyro_y", "gyro_z", "temperature"]
    raw_dps = bias_rad_s * RAD_TO_DEG
    assert np.std(out["gyro_z"]) < 0.02 * np.std(raw_dps)  # the quadratic drift is gone
    r = run("convert", log, tmp_path / "log.parquet")
    assert r.returncode == 0 and "wrote" in r.stdout and "3000 rows" in r.stdout, r.stderr
    back = pd.read_parquet(tmp_path / "log.parquet")
    np.testing.assert_allclose(back["gyro_x"], fields["x"][1] * RAD_TO_DEG, rtol=1e-6)


@pytest.mark.parametrize("case", ["not-the-format", "no-gyro-topic", "no-such-bag-topic", "output-format"])
def test_cli_bad_logs_give_one_line_and_status_2(tmp_path, case):
    if case == "not-the-format":
        path = tmp_path / "run.csv"
        path.write_text("time,gyro_z\n0,1\n1,2\n")
        args, expected = ["convert", path, tmp_path / "o.csv", "--format", "ulog"], "run.csv: not a PX4 ULog file"
    elif case == "no-gyro-topic":
        path = tmp_path / "baro.ulg"
        t = (np.arange(10) * 1000).astype(np.uint64)
        write_ulog(path, {("sensor_baro", 0): {"timestamp": ("uint64_t", t), "temperature": ("float", np.ones(10))}})
        args, expected = ["allan", path], "baro.ulg: no gyro topic"
    elif case == "no-such-bag-topic":
        path = tmp_path / "imu.bag"
        write_bag(path, ros2=False)
        args, expected = (
            ["convert", path, tmp_path / "o.csv", "--imu-topic", "/gyro"],
            "--imu-topic /gyro: no such topic",
        )
    else:
        path = tmp_path / "x.ulg"
        write_ulog(path, dict([_gyro_topic()]))
        args, expected = (
            ["convert", path, tmp_path / "o.ulg"],
            "OUT " + str(tmp_path / "o.ulg") + ": gyrocomp writes CSV",
        )
    r = run(*args)
    assert r.returncode == 2
    errors = [line for line in r.stderr.splitlines() if line.startswith("gyrocomp: error")]
    assert len(errors) == 1 and expected in errors[0], r.stderr
    assert "Traceback" not in r.stderr


def _drifting_gyro(multi_id: int, slope_rad_s_per_degc: float, n: int = 3000, rate_hz: float = 10.0):
    """A sensor_gyro instance whose bias is linear in temperature (10 -> 50 degC) with the given slope."""
    temperature = np.linspace(10, 50, n)
    t_us = (1_000_000 + np.arange(n) * 1e6 / rate_hz).astype(np.uint64)
    rng = np.random.default_rng(multi_id)
    fields = {
        "timestamp": ("uint64_t", t_us),
        "device_id": ("uint32_t", np.full(n, 7 + multi_id, np.uint32)),
        "temperature": ("float", temperature.astype(np.float32)),
    }
    for axis in "xyz":
        rate = slope_rad_s_per_degc * (temperature - 30) + 1e-5 * rng.standard_normal(n)
        fields[axis] = ("float", rate.astype(np.float32))
    return ("sensor_gyro", multi_id), fields


def _slopes_dps_per_degc(path) -> list[float]:
    from gyrocomp.calibration import Calibration

    model = Calibration.load(path)
    return [float(np.diff(axis.shape_dps(np.array([29.5, 30.5])))[0]) for axis in model.axes.values()]


def test_fit_every_instance_of_a_px4_and_an_ardupilot_log(tmp_path):
    """--instance all: one model file per IMU, each with its own IMU's temperature slope."""
    ulog = tmp_path / "two.ulg"
    write_ulog(ulog, dict([_drifting_gyro(0, 1e-3), _drifting_gyro(1, -2e-3)]))
    r = run("fit", ulog, "-o", tmp_path / "px4.json", "--instance", "all", "--hysteresis", "none")
    assert r.returncode == 0, r.stderr
    assert _slopes_dps_per_degc(tmp_path / "px4_imu0.json") == pytest.approx([np.degrees(1e-3)] * 3, rel=0.01)
    assert _slopes_dps_per_degc(tmp_path / "px4_imu1.json") == pytest.approx([np.degrees(-2e-3)] * 3, rel=0.01)
    assert not (tmp_path / "px4.json").exists()
    n = 3000
    temperature = np.linspace(10, 50, n)
    rows = [
        (
            1_000_000 + i * 100_000,
            k,
            s * (temperature[i] - 30),
            s * (temperature[i] - 30),
            s * (temperature[i] - 30),
            0.0,
            0.0,
            -G,
            temperature[i],
        )
        for i in range(n)
        for k, s in ((0, 5e-4), (1, 1.5e-3))
    ]
    dataflash = tmp_path / "two.bin"
    write_dataflash(dataflash, {"IMU": (130, _IMU_COLUMNS, rows)})
    r = run("fit", dataflash, "-o", tmp_path / "ap.json", "--instance", "all", "--hysteresis", "none")
    assert r.returncode == 0, r.stderr
    assert _slopes_dps_per_degc(tmp_path / "ap_imu0.json") == pytest.approx([np.degrees(5e-4)] * 3, rel=0.01)
    assert _slopes_dps_per_degc(tmp_path / "ap_imu1.json") == pytest.approx([np.degrees(1.5e-3)] * 3, rel=0.01)
    # a run without one of the instances the others have is refused, nothing written
    single = tmp_path / "one.ulg"
    write_ulog(single, dict([_drifting_gyro(0, 1e-3)]))
    r = run("fit", ulog, single, "-o", tmp_path / "mixed.json", "--instance", "all")
    assert r.returncode == 2 and "one.ulg: no instance 1 (it has 0); --instance all fits each instance" in r.stderr
    assert not list(tmp_path.glob("mixed*"))
    r = run("apply", tmp_path / "px4_imu0.json", ulog, "-o", tmp_path / "o.csv", "--instance", "all")
    assert r.returncode == 2 and "--instance: all is for gyrocomp fit" in r.stderr


def test_a_px4_log_already_corrected_onboard_is_recognized(tmp_path):
    """With TC_G_ENABLE = 1, PX4's sensor_gyro is still raw (the correction is applied after it), but
    sensor_combined is corrected: reading it warns that a model would correct twice."""
    key, gyro = _gyro_topic()
    raw_log = tmp_path / "raw.ulg"
    write_ulog(raw_log, {key: gyro}, parameters={"TC_G_ENABLE": 1})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        raw = read(raw_log)
    assert raw.metadata["px4_thermal_compensation"] and not raw.metadata["corrected_onboard"]
    n = 100
    combined = {
        "timestamp": ("uint64_t", (1_000_000 + np.arange(n) * 20_000).astype(np.uint64)),
        **{f"gyro_rad[{i}]": ("float", np.zeros(n, np.float32)) for i in range(3)},
        **{f"accelerometer_m_s2[{i}]": ("float", np.full(n, -G if i == 2 else 0.0, np.float32)) for i in range(3)},
    }
    corrected_log = tmp_path / "corrected.ulg"
    write_ulog(corrected_log, {("sensor_combined", 0): combined}, parameters={"TC_G_ENABLE": 1})
    with pytest.warns(
        DataQualityWarning,
        match=r"TC_G_ENABLE = 1: sensor_combined is already corrected by PX4's "
        r"thermal compensation; a model fitted or applied on it would correct "
        r"twice",
    ):
        corrected = read(corrected_log)
    assert corrected.metadata["corrected_onboard"]
    write_ulog(tmp_path / "off.ulg", {("sensor_combined", 0): combined}, parameters={"TC_G_ENABLE": 0})
    assert not read(tmp_path / "off.ulg").metadata["corrected_onboard"]


def test_a_bags_imu_topics_are_its_instances(tmp_path):
    """Several IMUs in one bag: each sensor_msgs/Imu topic an instance, in name order, as the autopilots' sensors;
    instance= reads one, fit --instance all fits each."""
    from gyrocomp.io import instances

    path = tmp_path / "two.bag"
    write_bag(path, ros2=False, imu_topics=("/imu_b", "/imu_a"))
    assert instances(path) == (0, 1)
    assert read(path, instance=0).metadata["imu_topic"] == "/imu_a"
    assert read(path, instance=1).metadata["imu_topic"] == "/imu_b"
    with pytest.raises(
        InputError,
        match=r"instance=2: the bag has 2 sensor_msgs/msg/Imu topic\(s\) \(/imu_a, /imu_b\), "
        r"instances 0 to 1",
    ):
        read(path, instance=2)
    with pytest.raises(InputError, match=r"choose one with imu_topic= or instance= \(their index"):
        read(path)
    one = tmp_path / "one.bag"
    write_bag(one, ros2=False)
    assert instances(one) == (0,)


def test_the_command_line_reads_a_bags_instance(tmp_path):
    path = tmp_path / "two.bag"
    write_bag(path, ros2=False, temperature=False, imu_topics=("/imu_b", "/imu_a"))
    done = run("convert", path, tmp_path / "b.csv", "--instance", 1)
    assert done.returncode == 0, done.stderr
    assert read(tmp_path / "b.csv").n_samples == 100
    wrong = run("convert", path, tmp_path / "c.csv", "--instance", 5)
    assert wrong.returncode == 2 and wrong.stderr.strip().endswith(
        "two.bag: --instance 5: the bag has 2 sensor_msgs/msg/Imu topic(s) (/imu_a, /imu_b), instances 0 to 1"
    )
    assert not (tmp_path / "c.csv").exists()


def test_layout_options_a_log_does_not_read_are_said_not_used(tmp_path):
    """A ROS bag's fields, units and time stamps are its own: a column mapping or a rate given for it (on the
    command line, or by a project file written for the folder's tables) changes nothing, and is said so, once, on
    the whole read and on the chunked one; without them nothing is said, and a table reads them as ever."""
    from gyrocomp.errors import UnusedOptionWarning

    from gyrocomp.simulation import simulate

    rec = simulate("consumer", profile="static", duration_s=60.0, rate_hz=50.0, seed=1).recording
    bag = tmp_path / "still.bag"
    write_recording_bag(bag, rec, ros2=False)
    with pytest.warns(
        UnusedOptionWarning,
        match=r"still.bag: columns=, rate_hz= not used: they are for tables and files of named arrays, and a "
        r"rosbag file's fields, units and time stamps are its own$",
    ):
        read(bag, TableLayout({"time": ""}, rate_hz=100.0))
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnusedOptionWarning)
        plain = read(bag)
    with pytest.warns(UnusedOptionWarning, match=r"still.bag: gyro_unit= not used"):
        np.testing.assert_array_equal(read(bag, gyro_unit="rad/s").gyro_dps, plain.gyro_dps)
    said = run("allan", bag, "--gyro-unit", "rad/s")
    assert said.returncode == 0 and said.stderr.count("--gyro-unit not used") == 1, said.stderr
    assert "not used" not in run("allan", bag).stderr


def test_a_bag_whose_schema_text_is_damaged_is_refused_in_one_line(tmp_path):
    """rosbags' parse error quotes the whole damaged message definition, newlines and all: cut and escaped."""
    write_bag(tmp_path / "bag", ros2=True, n=50, mcap=True)
    inner = next((tmp_path / "bag").glob("*.mcap"))
    rule = b"\n" + b"=" * 80 + b"\nMSG: geometry_msgs/Quaternion"
    inner.write_bytes(inner.read_bytes().replace(rule, rule[:16] + b"U" + rule[17:]))  # the schema and its copy
    with pytest.raises(
        InputError, match=r"bag: not a readable ROS bag \(AnyReaderError: Could not parse:\\n.MSG: sensor_msgs"
    ) as caught:
        read(tmp_path / "bag")
    assert "\n" not in str(caught.value) and len(str(caught.value)) < len(str(tmp_path)) + 260
