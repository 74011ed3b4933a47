"""A ROS bag compensated into a bag of the same kind: ROS 1, ROS 2 in sqlite3 and in MCAP storage; every other
message byte for byte and stamp for stamp as it was, the IMU topic equal to apply on the recording the bag reads
as, a repeated stamp corrected as its twin, messages outside the temperature's span copied and said; through the
command line too, the input never touched."""

from __future__ import annotations

import dataclasses
import hashlib
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from gyrocomp import apply, fit_calibration, read
from gyrocomp.errors import DataQualityWarning, InputError
from gyrocomp.files.apply_bag import apply_bag
from gyrocomp.io.rosbag import any_reader, message_arrays
from gyrocomp.io.stamps import ticks_s
from gyrocomp.io.tables import write_recording
from gyrocomp.simulation import get_profile, simulate

from ..conftest import run
from tests.io.log_writers import write_bag, write_recording_bag

pytest.importorskip("rosbags", reason="bags need the [ros] extra (rosbags)")
from rosbags.highlevel import AnyReader  # noqa: E402

KINDS = {
    "ros1": ({"ros2": False}, "in.bag", "out.bag"),
    "ros2": ({"ros2": True}, "in", "out"),
    "mcap": ({"ros2": True, "mcap": True}, "in", "out"),
    "bare mcap": ({"ros2": True, "mcap": True, "bare": True}, "in.mcap", "out.mcap"),
}


@pytest.fixture(scope="module")
def model():
    profile = get_profile("cycle", set_points_degc=(15.0, 45.0), cycles=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit_calibration([simulate("consumer", profile=profile, rate_hz=1.0, seed=s).recording for s in (1, 2)])


def _messages(bag: Path) -> list:
    with AnyReader([bag]) as reader:
        return [(c.topic, c.msgtype, t, bytes(raw)) for c, t, raw in reader.messages()]


def _digest(path: Path) -> str:
    files = sorted(path.rglob("*")) if path.is_dir() else [path]
    return hashlib.sha256(b"".join(f.read_bytes() for f in files if f.is_file())).hexdigest()


@pytest.fixture(scope="module")
def model_with_accel():
    """A gyro and accelerometer model (the consumer part's accelerometer tempco): apply changes both."""
    from gyrocomp.models.fit import fit_channels

    profile = get_profile("cycle", set_points_degc=(15.0, 45.0), cycles=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit_channels(
            [simulate("consumer", profile=profile, rate_hz=1.0, seed=s).recording for s in (1, 2)], ("accel", "gyro")
        )


@pytest.mark.parametrize("kind", list(KINDS))
@pytest.mark.parametrize("chunk_rows", [None, 7])
def test_a_bag_out_is_the_bag_in_with_its_imu_topic_compensated(kind, chunk_rows, model, tmp_path):
    """In one batch and in batches of 7 messages (the compensator's state carried from one to the next)."""
    options, name, out_name = KINDS[kind]
    source, output = tmp_path / name, tmp_path / out_name
    write_bag(source, n=300, **options)
    before = _digest(source)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        done = apply_bag(model, source, output, **({"chunk_rows": chunk_rows} if chunk_rows else {}))
        expected = apply(model, read(source)).gyro_dps
        back = read(output)
    assert (done.compensated, done.unchanged, done.accel, done.imu_topic) == (300, 0, False, "/imu/data")
    np.testing.assert_allclose(back.gyro_dps, expected, rtol=0, atol=1e-12)
    ins, outs = _messages(source), _messages(output)
    assert [(topic, kind_, t) for topic, kind_, t, _ in ins] == [(topic, kind_, t) for topic, kind_, t, _ in outs]
    assert [m for m in ins if m[0] != "/imu/data"] == [m for m in outs if m[0] != "/imu/data"]
    assert _digest(source) == before
    if kind == "mcap":
        assert "mcap" in (output / "metadata.yaml").read_text()
    if kind in ("mcap", "bare mcap"):  # the MCAP project's own reader reads the file, with the schemas in it
        assert output.is_file() == (kind == "bare mcap")
        reader = pytest.importorskip("mcap.reader", reason="the mcap library reads the file back")
        with open(output if output.is_file() else next(output.glob("*.mcap")), "rb") as f:
            read_back = [
                (channel.topic, schema.name, message.log_time)
                for schema, channel, message in reader.make_reader(f).iter_messages()
            ]
        assert read_back == [(topic, kind_, t) for topic, kind_, t, _ in ins]


@pytest.mark.parametrize("chunk_rows", [1000, 151, 40])
def test_a_repeated_stamp_is_corrected_as_its_twin_and_uncovered_messages_are_said(chunk_rows, model, tmp_path):
    """In one batch, with the twin the first message of a batch (151), and in batches of 40."""
    source = tmp_path / "in.bag"
    write_bag(source, ros2=False, n=300, repeat=150, temperature_from=100)
    # the first temperature at message 100 (1 s in); reading matches within 5 of its periods (0.5 s): the first
    # 51 messages (the one at 0.5 s too) are outside its span
    with pytest.warns(
        DataQualityWarning,
        match=r"in.bag: 51 message\(s\) of /imu/data are not in the recording the "
        r"bag reads as .* copied uncompensated",
    ):
        done = apply_bag(model, source, tmp_path / "out.bag", chunk_rows=chunk_rows)
    assert (done.compensated, done.unchanged, done.streamed) == (250, 51, True)
    with AnyReader([tmp_path / "out.bag"]) as reader:
        msgs = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages() if c.topic == "/imu/data"]
    first, twin = msgs[150], msgs[151]
    assert first.header.stamp == twin.header.stamp
    # the twin read 0.5 rad/s on y where the first read 0: the same correction leaves that difference
    assert twin.angular_velocity.y - first.angular_velocity.y == pytest.approx(0.5, abs=1e-12)
    assert msgs[0].angular_velocity.z == pytest.approx(-0.01, abs=1e-15)  # before the temperature: as it was


def test_the_command_line_writes_a_bag_of_the_inputs_kind_and_refuses_another(model, tmp_path):
    source = tmp_path / "in.bag"
    write_bag(source, ros2=False, n=200)
    model.save(tmp_path / "m.json")
    done = run("apply", tmp_path / "m.json", source, "-o", tmp_path / "out.bag")
    assert done.returncode == 0, done.stderr
    assert "wrote" in done.stdout and "200 messages of /imu/data compensated" in done.stdout
    folder = run("apply", tmp_path / "m.json", source, "-o", tmp_path / "outdir")
    assert folder.returncode == 2 and folder.stderr.strip().endswith(
        "a compensated bag is written as the input's kind: a .bag file (a ROS 1 bag)"
    )
    assert not (tmp_path / "outdir").exists()
    table = run("apply", tmp_path / "m.json", source, "-o", tmp_path / "out.csv")
    assert table.returncode == 0 and (tmp_path / "out.csv").exists()  # a table out, as before


def test_an_output_folder_that_is_not_a_bag_is_not_replaced(model, tmp_path):
    source = tmp_path / "in"
    write_bag(source, ros2=True, n=100)
    keep = tmp_path / "notes"
    keep.mkdir()
    (keep / "mine.txt").write_text("keep me")
    with pytest.raises(InputError, match=r"output: .*notes: is a folder that is not a ROS 2 bag; name a new path"):
        apply_bag(model, source, keep)
    assert (keep / "mine.txt").read_text() == "keep me"


def test_a_damaged_bag_is_refused_in_one_line_and_nothing_is_written(model, tmp_path):
    source = tmp_path / "in.bag"
    write_bag(source, ros2=False, n=300)
    data = source.read_bytes()
    source.write_bytes(data[: len(data) * 2 // 3])  # cut short: its index and last chunks are gone
    with pytest.raises(InputError, match=r"in.bag: (damaged|not a readable) ROS bag"):
        apply_bag(model, source, tmp_path / "out.bag")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.bag"]  # no output, no temporary left


def test_the_covariances_are_written_from_a_noise_model(model, tmp_path):
    """The noise model's white noise as the variance of one sample at the bag's rate (100 Hz): N^2 rate."""
    import json

    source = tmp_path / "in"
    write_bag(source, ros2=True, n=200)
    noise = tmp_path / "noise.json"
    noise.write_text(
        json.dumps(
            {
                "format": "gyrocomp-noise-model",
                "rate_hz": 100.0,
                "axes": {
                    "gyro_x": {"bound": {"white_noise_density_u_per_sqrt_hz": 0.01}},
                    "gyro_z": {"bound": {"white_noise_density_u_per_sqrt_hz": 0.02}},
                },
            }
        )
    )
    done = apply_bag(model, source, tmp_path / "out", noise=noise)
    assert done.covariances == ("angular_velocity_covariance",)
    with AnyReader([tmp_path / "out"]) as reader:
        msg = next(reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages() if c.topic == "/imu/data")
    expected = np.radians(0.02) ** 2 * 100.0  # the larger gyro density, in rad/s/sqrt(Hz)
    np.testing.assert_allclose(msg.angular_velocity_covariance, np.diag([expected] * 3).ravel(), rtol=1e-9)
    np.testing.assert_array_equal(msg.linear_acceleration_covariance, np.zeros(9))  # as it was
    noise.write_text('{"format": "something else"}')
    with pytest.raises(InputError, match=r"noise.json: not a gyrocomp noise model"):
        apply_bag(model, source, tmp_path / "again", noise=noise)


@pytest.mark.parametrize("chunk_rows", [None, 40, 100])
def test_stamps_out_of_order_are_compensated_as_a_whole_read_gives_them(chunk_rows, model, tmp_path):
    """Messages 99 and 100 carry each other's stamps: within a batch they are sorted (40); across two batches
    (100: the second's first stamp is earlier than the first's last) the bag is compensated from a whole read;
    either way every message gets what apply gives its sample, in the bag's own order."""
    source = tmp_path / "in.bag"
    write_bag(source, ros2=False, n=300, swap=99)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        done = apply_bag(model, source, tmp_path / "out.bag", **({"chunk_rows": chunk_rows} if chunk_rows else {}))
        expected = apply(model, read(source))
    assert (done.compensated, done.unchanged, done.streamed) == (300, 0, chunk_rows != 100)
    with AnyReader([tmp_path / "out.bag"]) as reader:
        msgs = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages() if c.topic == "/imu/data"]
    stamps = np.array([m.header.stamp.sec + m.header.stamp.nanosec * 1e-9 for m in msgs])
    assert stamps[99] > stamps[100]
    gyro = np.array([[m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z] for m in msgs])
    order = np.argsort(stamps, kind="stable")
    np.testing.assert_allclose(np.degrees(gyro[order]), expected.gyro_dps, rtol=0, atol=1e-12)


@pytest.mark.parametrize("chunk_rows", [None, 13])
def test_a_model_with_accelerometer_terms_compensates_the_accelerations_too(chunk_rows, model_with_accel, tmp_path):
    source = tmp_path / "in"
    write_bag(source, ros2=True, n=200)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        done = apply_bag(
            model_with_accel, source, tmp_path / "out", **({"chunk_rows": chunk_rows} if chunk_rows else {})
        )
        expected = apply(model_with_accel, read(source))
        back = read(tmp_path / "out")
    assert done.accel and done.compensated == 200
    assert np.max(np.abs(expected.accel_g - read(source).accel_g)) > 1e-4  # the model does change them
    np.testing.assert_allclose(back.accel_g, expected.accel_g, rtol=0, atol=1e-12)
    np.testing.assert_allclose(back.gyro_dps, expected.gyro_dps, rtol=0, atol=1e-12)


@pytest.mark.slow
@pytest.mark.parametrize("chunk_rows", [None, 30])
def test_each_imu_topic_with_its_own_model_in_one_pass(chunk_rows, model, model_with_accel, tmp_path):
    """Two IMU topics (instances in name order: /imu_a 0, /imu_b 1), each with its model; and through the command
    line with the model files fit --instance all writes, one missing named."""
    from gyrocomp.files.apply_bag import apply_bag_instances

    source = tmp_path / "two.bag"
    write_bag(source, ros2=False, n=200, imu_topics=("/imu_b", "/imu_a"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        done = apply_bag_instances(
            {0: model, 1: model_with_accel},
            source,
            tmp_path / "out.bag",
            **({"chunk_rows": chunk_rows} if chunk_rows else {}),
        )
        for instance, used in ((0, model), (1, model_with_accel)):
            expected = apply(used, read(source, instance=instance))
            back = read(tmp_path / "out.bag", instance=instance)
            np.testing.assert_allclose(back.gyro_dps, expected.gyro_dps, rtol=0, atol=1e-12)
            np.testing.assert_allclose(back.accel_g, expected.accel_g, rtol=0, atol=1e-12)
    assert [(d.imu_topic, d.compensated, d.accel) for d in done] == [("/imu_a", 200, False), ("/imu_b", 200, True)]
    model.save(tmp_path / "m_imu0.json")
    cli = run("apply", tmp_path / "m.json", source, "-o", tmp_path / "cli.bag", "--instance", "all")
    assert cli.returncode == 2 and "no model file" in cli.stderr and "m_imu1.json" in cli.stderr
    assert not (tmp_path / "cli.bag").exists()
    model_with_accel.save(tmp_path / "m_imu1.json")
    cli = run("apply", tmp_path / "m.json", source, "-o", tmp_path / "cli.bag", "--instance", "all")
    assert cli.returncode == 0, cli.stderr
    assert "200 messages of /imu_a compensated (angular velocity); 200 messages of /imu_b compensated" in cli.stdout
    assert _messages(tmp_path / "cli.bag") == _messages(tmp_path / "out.bag")


def test_a_bag_heavy_with_other_topics_is_written_in_windows_of_bytes(model, tmp_path, monkeypatch):
    """Held messages written out once their bytes pass the window (here 3 kB, after 20 IMU samples set the rate):
    the same bag as in one batch."""
    import gyrocomp.files.apply_bag as module

    source = tmp_path / "in.bag"
    write_bag(source, ros2=False, n=300)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        apply_bag(model, source, tmp_path / "one.bag")
        monkeypatch.setattr(module, "WINDOW_BYTES", 3000)
        monkeypatch.setattr(module, "FIRST_SAMPLES", 20)
        done = apply_bag(model, source, tmp_path / "windows.bag")
    assert done.compensated == 300
    assert _messages(tmp_path / "windows.bag") == _messages(tmp_path / "one.bag")


def _imu_bytes(bag: Path) -> tuple[Path, np.ndarray]:
    """The file holding a bag's messages, and where the data of its IMU messages lie in it (a mask of its bytes)."""
    file = next(bag.glob("*.mcap")) if bag.is_dir() else bag
    inside = np.zeros(file.stat().st_size, dtype=bool)
    with any_reader(bag) as reader:
        imu = [c for c in reader.connections if c.topic == "/imu/data"]
        for chunk in message_arrays(reader, imu):
            for at, length in zip(chunk.data_at.tolist(), chunk.data_length.tolist()):
                inside[chunk.data_pos + at : chunk.data_pos + at + length] = True
    return file, inside


@pytest.mark.parametrize("kind", ["ros1", "mcap", "bare mcap", "ros2"])
@pytest.mark.parametrize("chunk_rows", [None, 7])
@pytest.mark.parametrize("window_bytes", [None, 3000])
def test_a_bag_is_compensated_in_place_as_the_writer_would(
    kind, chunk_rows, window_bytes, model_with_accel, tmp_path, monkeypatch
):
    """An uncompressed ROS 1 bag, an MCAP file (a bag folder's, and bare) and a bag folder's sqlite3 file are copied
    with each IMU message's values written in place: a file of chunks has the input's bytes but for those values
    (every record, offset and index as it was), the sqlite3 file its rows but the IMU messages', and the messages
    rosbags reads from it are those of the bag written message by message through rosbags' writer, in batches of 7
    messages and in windows of bytes too (a batch holding a single IMU message among them), and those of one
    batch; a folder keeps its file's name and its metadata.yaml as they were."""
    import gyrocomp.files.apply_bag as module

    options, name, out_name = KINDS[kind]
    source = tmp_path / name
    outputs = {label: tmp_path / f"{label}{Path(out_name).suffix}" for label in ("one", "patched", "written")}
    write_bag(source, n=400, repeat=11, **options)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        apply_bag(model_with_accel, source, outputs["one"])
        if window_bytes:
            monkeypatch.setattr(module, "WINDOW_BYTES", window_bytes)
            monkeypatch.setattr(module, "FIRST_SAMPLES", 20)
        patched = apply_bag(model_with_accel, source, outputs["patched"], chunk_rows=chunk_rows or 100_000)
        monkeypatch.setattr(module, "_patched_bag", lambda *args: False)
        written = apply_bag(model_with_accel, source, outputs["written"], chunk_rows=chunk_rows or 100_000)
    assert patched.compensated == written.compensated == 401 and patched.accel  # 400 and a repeat
    assert _messages(outputs["patched"]) == _messages(outputs["written"]) == _messages(outputs["one"])
    assert _messages(source) != _messages(outputs["patched"])
    if source.is_dir():
        assert (outputs["patched"] / "metadata.yaml").read_bytes() == (source / "metadata.yaml").read_bytes()
        assert sorted(p.name for p in outputs["patched"].iterdir()) == sorted(p.name for p in source.iterdir())
    if kind == "ros2":
        return
    file, inside = _imu_bytes(source)
    before = file.read_bytes()
    after = (
        next(outputs["patched"].glob("*.mcap")) if outputs["patched"].is_dir() else outputs["patched"]
    ).read_bytes()
    assert len(after) == len(before)
    changed = np.flatnonzero(np.frombuffer(before, np.uint8) != np.frombuffer(after, np.uint8))
    assert changed.size
    assert np.all(inside[changed])  # only IMU messages changed: each changed byte lies in an IMU message's data


def _rewritten_with_crcs(source: Path, target: Path) -> Path:
    """An MCAP file's schemas, channels and messages written again by the mcap library with the CRC-32 of each
    chunk and of the data section (rosbags writes none)."""
    mcap_reader = pytest.importorskip("mcap.reader")
    mcap_writer = pytest.importorskip("mcap.writer")
    with open(source, "rb") as f_in, open(target, "wb") as f_out:
        reader = mcap_reader.make_reader(f_in)
        writer = mcap_writer.Writer(
            f_out,
            chunk_size=4096,
            compression=mcap_writer.CompressionType.NONE,
            enable_crcs=True,
            enable_data_crcs=True,
        )
        writer.start(profile="ros2", library="gyrocomp tests")
        schemas, channels = {}, {}
        for schema, channel, message in reader.iter_messages():
            if schema.id not in schemas:
                schemas[schema.id] = writer.register_schema(schema.name, schema.encoding, schema.data)
            if channel.id not in channels:
                channels[channel.id] = writer.register_channel(
                    channel.topic, channel.message_encoding, schemas[schema.id], channel.metadata
                )
            writer.add_message(channels[channel.id], message.log_time, message.data, message.publish_time)
        writer.finish()
    return target


def test_an_mcap_files_crcs_are_written_anew_when_compensated_in_place(model, tmp_path):
    """A patched chunk's CRC-32 and the data section's, where the input has them: the mcap library's reader
    checks both, and the messages are those of the writer's pass."""
    import gyrocomp.files.apply_bag as module

    stream_reader = pytest.importorskip("mcap.stream_reader")
    write_bag(tmp_path / "plain.mcap", n=300, **KINDS["bare mcap"][0])
    source = _rewritten_with_crcs(tmp_path / "plain.mcap", tmp_path / "in.mcap")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        patched = apply_bag(model, source, tmp_path / "patched.mcap")
        with pytest.MonkeyPatch.context() as m:
            m.setattr(module, "_patched_bag", lambda *args: False)
            apply_bag(model, source, tmp_path / "written.mcap")
    assert patched.compensated == 300
    assert (tmp_path / "patched.mcap").stat().st_size == source.stat().st_size
    assert _messages(tmp_path / "patched.mcap") == _messages(tmp_path / "written.mcap") != _messages(source)
    for path in (source, tmp_path / "patched.mcap"):
        with open(path, "rb") as f:
            records = list(stream_reader.StreamReader(f, validate_crcs=True).records)  # every CRC checked
        with open(path, "rb") as f:
            chunks = [r for r in stream_reader.StreamReader(f, emit_chunks=True).records if type(r).__name__ == "Chunk"]
        assert len(chunks) > 3 and all(chunk.uncompressed_crc != 0 for chunk in chunks)
        assert [r.data_section_crc != 0 for r in records if type(r).__name__ == "DataEnd"] == [True]
    data = bytearray((tmp_path / "patched.mcap").read_bytes())
    _, inside = _imu_bytes(tmp_path / "patched.mcap")
    data[int(np.flatnonzero(inside)[-1])] ^= 1  # a bit of a message flipped: the check fails
    (tmp_path / "bent.mcap").write_bytes(bytes(data))
    with open(tmp_path / "bent.mcap", "rb") as f, pytest.raises(Exception, match="(?i)crc"):
        list(stream_reader.StreamReader(f, validate_crcs=True).records)


@pytest.mark.parametrize("chunk_rows", [None, 7])
def test_imu_messages_of_several_layouts_are_compensated_in_place_one_by_one(chunk_rows, model, tmp_path):
    """Every ninth IMU message with a longer frame_id (another length): the batches holding them are compensated
    message by message, still in place; the bag's messages are those of the writer's pass."""
    import gyrocomp.files.apply_bag as module

    source = tmp_path / "in.bag"
    write_bag(source, ros2=False, n=200, long_frame_every=9)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        patched = apply_bag(model, source, tmp_path / "patched.bag", chunk_rows=chunk_rows or 100_000)
        with pytest.MonkeyPatch.context() as m:
            m.setattr(module, "_patched_bag", lambda *args: False)
            written = apply_bag(model, source, tmp_path / "written.bag", chunk_rows=chunk_rows or 100_000)
    assert patched.compensated == written.compensated == 200
    assert _messages(tmp_path / "patched.bag") == _messages(tmp_path / "written.bag")
    assert (tmp_path / "patched.bag").stat().st_size == source.stat().st_size
    assert _messages(tmp_path / "patched.bag") != _messages(source)


@pytest.mark.parametrize("kind", ["ros1", "ros2"])
def test_a_last_batch_of_one_imu_message_is_compensated_as_the_next_sample(kind, model, tmp_path):
    """400 IMU messages in batches of 7: the last batch holds one (a recording needs two rows); it is compensated
    as the next sample of the stream, the bag the same as compensated in one batch."""
    options, name, _ = KINDS[kind]
    source = tmp_path / name
    write_bag(source, n=400, **options)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        one = apply_bag(model, source, tmp_path / ("one.bag" if kind == "ros1" else "one"))
        sevens = apply_bag(model, source, tmp_path / ("sevens.bag" if kind == "ros1" else "sevens"), chunk_rows=7)
    assert 400 % 7 == 1 and one.compensated == sevens.compensated == 400
    assert _messages(Path(sevens.path)) == _messages(Path(one.path))


def test_a_damaged_imu_record_the_reading_passed_over_is_refused_in_one_line(model, tmp_path):
    """The temperature topic is read by the chunks' index (one message in fifty), so a damaged IMU record is first
    met while compensating: one line naming the bag and the topic, exit 2, nothing written."""
    from gyrocomp.io.rosbag1_chunks import chunked_reader1 as reader_class

    profile = get_profile("cycle", set_points_degc=(15.0, 45.0), cycles=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        recording = simulate("consumer", profile=profile, rate_hz=10.0, duration_s=600.0, seed=3).recording
    source = tmp_path / "in.bag"
    write_recording_bag(source, recording, ros2=False, temperature_every=50)
    data = bytearray(source.read_bytes())
    with reader_class()(source) as reader:
        imu = [c for c in reader.connections if c.topic == "/imu/data"]
        chunk = list(reader.message_arrays(connections=imu))[-1]
    at = chunk.data_pos + int(chunk.data_at[5]) - 4  # the data length of an IMU message in the last chunk
    data[at : at + 4] = (10**8).to_bytes(4, "little")
    (tmp_path / "bad.bag").write_bytes(bytes(data))
    model.save(tmp_path / "m.json")
    cli = run("apply", str(tmp_path / "m.json"), str(tmp_path / "bad.bag"), "-o", str(tmp_path / "out.bag"))
    assert cli.returncode == 2 and "Traceback" not in cli.stderr, cli.stderr
    assert "bad.bag: damaged ROS bag: topic /imu/data" in cli.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.bag", "in.bag", "m.json"]


@pytest.mark.parametrize("kind", list(KINDS))
def test_a_bag_with_epoch_stamps_is_compensated_as_the_table_of_its_samples(kind, consumer_model, tmp_path):
    """Stamps at the Unix epoch (1.7e9 s, as every real bag has), spaced as a real clock's (not exactly evenly): apply
    to the bag equals apply on a table of the same samples to 1e-12 deg/s, whether the table's time is in seconds
    or in integer nanoseconds (a float64 keeps 256 ns of an integer nanosecond time at that epoch: read as ticks
    1e-9, the steps and the sample rate taken from them differed from the bag's, and the thermal lag's filter with
    them, by 1.3e-5 deg/s here)."""
    options, name, out_name = KINDS[kind]
    rec = simulate("consumer", profile="chamber", rate_hz=100, duration_s=120, seed=7, unit=3).recording
    epoch_s = rec.time_s + 1_734_567_890.123456  # a logger's float stamps, at the nanosecond in the bag
    whole = np.floor(epoch_s)
    stamps_ns = whole.astype(np.int64) * 10**9 + np.round((epoch_s - whole) * 1e9).astype(np.int64)
    rec = dataclasses.replace(rec, time_s=ticks_s(stamps_ns, 10**9))
    source, output = tmp_path / name, tmp_path / out_name
    folder = tmp_path / "written" if options.get("bare") else source
    write_recording_bag(
        folder, rec, ros2=options["ros2"], mcap=options.get("mcap", False), temperature_every=1, stamps_ns=stamps_ns
    )
    if options.get("bare"):
        next(folder.glob("*.mcap")).rename(source)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        apply_bag(consumer_model, source, output)
        compensated = read(output).gyro_dps
        for unit in ("s", "ns"):
            table = tmp_path / f"samples_{unit}.csv"
            write_recording(rec, table)
            if unit == "ns":  # the time column as the stamps' integer nanoseconds
                frame = pd.read_csv(table)
                frame["time"] = stamps_ns
                frame.to_csv(table, index=False)
            expected = apply(consumer_model, read(table, time_unit=unit)).gyro_dps
            np.testing.assert_allclose(compensated, expected, rtol=0, atol=1e-12, err_msg=unit)


def test_integer_stamps_become_the_seconds_a_bag_stamp_gives():
    ticks = np.array([1_734_567_890_123_456_789, 1_734_567_890_133_456_790, -1, 0, 999_999_999], dtype=np.int64)
    expected = [float(s) + float(n) * 1e-9 for s, n in (divmod(int(t), 10**9) for t in ticks)]
    np.testing.assert_array_equal(ticks_s(ticks, 10**9), expected)
    np.testing.assert_array_equal(ticks_s(ticks // 1000, 10**6), ticks_s(ticks // 1000 * 1000, 10**9))
    assert ticks_s(ticks, 10**9)[1] - ticks_s(ticks, 10**9)[0] == pytest.approx(0.010000001, abs=3e-7)
