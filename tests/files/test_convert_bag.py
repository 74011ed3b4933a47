"""A bag rewritten as another kind (ROS 1, ROS 2 folder, bare MCAP) keeps every message: ROS 1 to a bare MCAP file
and back gives the same bytes (headers with seq 0, which ROS 2 does not carry), the MCAP file read by the MCAP
project's own reader; the same kind, a damaged bag and a folder that is no bag are refused in one line, nothing
written."""

from __future__ import annotations

import numpy as np
import pytest

from gyrocomp import read
from gyrocomp.errors import InputError
from gyrocomp.files.convert_bag import convert_bag

from ..conftest import run
from tests.io.log_writers import write_bag

pytest.importorskip("rosbags", reason="bags need the [ros] extra (rosbags)")
from rosbags.highlevel import AnyReader  # noqa: E402


def _messages(bag) -> list:
    with AnyReader([bag]) as reader:
        return [(c.topic, c.msgtype, t, bytes(raw)) for c, t, raw in reader.messages()]


def test_ros1_to_a_bare_mcap_file_and_back_keeps_every_message(tmp_path):
    source = tmp_path / "in.bag"
    write_bag(source, ros2=False, n=120, imu_topics=("/imu_a", "/imu_b"))
    before = source.read_bytes()
    done = convert_bag(source, tmp_path / "mid.mcap")
    assert (done.kind, done.from_kind) == ("mcap", "ros1") and (tmp_path / "mid.mcap").is_file()
    reader = pytest.importorskip("mcap.reader", reason="the mcap library reads the file back")
    with open(tmp_path / "mid.mcap", "rb") as f:
        topics = [(channel.topic, schema.name) for schema, channel, _ in reader.make_reader(f).iter_messages()]
    assert topics == [(topic, kind) for topic, kind, _, _ in _messages(source)]
    convert_bag(tmp_path / "mid.mcap", tmp_path / "back.bag")
    assert _messages(tmp_path / "back.bag") == _messages(source)
    assert source.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["back.bag", "in.bag", "mid.mcap"]  # no temporary left


def test_ros1_to_a_ros2_folder_reads_as_the_same_recording(tmp_path):
    source = tmp_path / "in.bag"
    write_bag(source, ros2=False, n=200)
    done = run("convert", source, tmp_path / "out")
    assert done.returncode == 0, done.stderr
    assert "a folder (a ROS 2 bag), every message of" in done.stdout
    a, b = read(source), read(tmp_path / "out")
    np.testing.assert_array_equal(a.gyro_dps, b.gyro_dps)
    np.testing.assert_array_equal(a.temperature_degc, b.temperature_degc)


def test_the_same_kind_a_damaged_bag_and_a_folder_that_is_no_bag_are_refused(tmp_path):
    source = tmp_path / "in.bag"
    write_bag(source, ros2=False, n=300)
    with pytest.raises(
        InputError,
        match=r"output: .*again\.bag: the input is already a \.bag file \(a ROS 1 bag\); "
        r"name a folder \(a ROS 2 bag\) or a \.mcap file",
    ):
        convert_bag(source, tmp_path / "again.bag")
    notes = tmp_path / "notes"
    notes.mkdir()
    with pytest.raises(InputError, match=r"output: .*notes: is a folder that is not a ROS 2 bag"):
        convert_bag(source, notes)
    cut = tmp_path / "cut.bag"
    cut.write_bytes(source.read_bytes()[: source.stat().st_size * 2 // 3])
    done = run("convert", cut, tmp_path / "cut.mcap")
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert "cut.bag" in done.stderr and "Traceback" not in done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cut.bag", "in.bag", "notes"]
