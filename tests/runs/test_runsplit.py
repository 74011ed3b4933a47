"""Cutting a recording into runs (gyrocomp.runs.runsplit, gyrocomp split), selecting by time (--time) and reading a
column of an HDF5 array (NAME[:, k]): on simulated recordings whose pieces are known."""

import numpy as np
import pytest

from gyrocomp import read
from gyrocomp.errors import InputError
from gyrocomp.io import TableLayout
from gyrocomp.runs.runsplit import split_runs
from gyrocomp.simulation import get_profile, simulate

from ..conftest import joined_recordings, run


def test_power_on_and_gap_cut_where_the_logger_stopped():
    parts = [simulate("consumer", profile="warmup", duration_s=600, rate_hz=10, seed=s).recording for s in range(3)]
    joined = joined_recordings(parts, 300.0)
    pieces = split_runs(joined, "power-on")
    assert [p.recording.n_samples for p in pieces] == [p.n_samples for p in parts]
    assert [p.start for p in pieces] == [0, parts[0].n_samples, parts[0].n_samples + parts[1].n_samples]
    assert len(split_runs(joined, "power-on", min_gap_s=600.0)) == 1  # the 300 s stops are not power-ons then
    assert len(split_runs(joined, "gap")) == 3


def test_temperature_turn_cuts_at_each_extreme():
    rec = simulate(
        "consumer", profile=get_profile("cycle", set_points_degc=(0.0, 60.0), cycles=2), rate_hz=1, seed=1
    ).recording
    pieces = split_runs(rec, "temperature-turn")
    temperature = rec.temperature_degc
    assert len(pieces) >= 4  # two cycles: up, down, up, down (and the start)
    for piece in pieces[1:]:  # each cut lies on an extreme of the temperature around it
        k = piece.start
        window = temperature[max(k - 60, 0) : k + 60]
        assert temperature[k] in (window.max(), window.min())
    assert sum(p.recording.n_samples for p in pieces) == rec.n_samples


def test_still_finds_the_poses_of_a_tumble():
    rec = simulate("consumer", profile="tumble", rate_hz=50, seed=2).recording
    pieces = split_runs(rec, "still", min_still_s=5.0)
    gravity = [np.argmax(np.abs(p.recording.accel_g.mean(axis=0))) for p in pieces]
    assert len(pieces) >= 6 and set(gravity) == {0, 1, 2}
    for a, b in zip(pieces, pieces[1:]):  # neighbouring poses differ
        assert not np.allclose(a.recording.accel_g.mean(axis=0), b.recording.accel_g.mean(axis=0), atol=0.2)


def test_bad_splits_are_refused():
    rec = simulate("consumer", profile="warmup", duration_s=60, rate_hz=10, seed=0).recording
    with pytest.raises(InputError, match=r"by: 'pose'; use one of power-on, gap, still, temperature-turn"):
        split_runs(rec, "pose")
    with pytest.raises(InputError, match=r"min_gap_s: must be a positive number, got 0"):
        split_runs(rec, "power-on", min_gap_s=0.0)
    # the poses were shorter than asked: said so, with the longest (it said "no run of 10 samples or more")
    with pytest.raises(
        InputError,
        match=r"by=still: no still pose of min_still_s=1e\+06 s or more \(the longest lasts [\d.]+ s\); a shorter",
    ):
        split_runs(rec, "still", min_still_s=1e6)


def test_a_column_of_an_hdf5_array(tmp_path):
    h5py = pytest.importorskip("h5py")
    n = 500
    data = np.column_stack([np.arange(n) / 10.0, 0.1 + np.zeros(n), 0.2 + np.zeros(n), 20 + np.arange(n) / 50])
    with h5py.File(tmp_path / "a.h5", "w") as fh:
        fh["imu"] = data
    layout = TableLayout({"time": "imu[:, 0]", "gyro_x": "imu[:,1]", "gyro_z": "imu[:, 2]", "temperature": "imu[:, 3]"})
    rec = read(tmp_path / "a.h5", layout)
    assert rec.gyro_axes == ("gyro_x", "gyro_z") and rec.n_samples == n
    np.testing.assert_array_equal(rec.gyro_dps[:, 1], data[:, 2])
    np.testing.assert_array_equal(rec.temperature_degc, data[:, 3])
    result = run("allan", tmp_path / "a.h5", "--columns", "time=imu[:, 0],gyro_x=imu[:, 1],temperature=imu[:,3]")
    assert result.returncode == 0, result.stderr
    with pytest.raises(InputError, match=r"imu\[:, 7\]: the dataset has shape \(500, 4\)"):
        read(tmp_path / "a.h5", TableLayout({"time": "imu[:, 0]", "gyro_x": "imu[:, 7]"}))
