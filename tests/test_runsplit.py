"""Cutting a recording into runs (gyrocomp.recording.runsplit, gyrocomp split), selecting by time (--time) and reading a
column of an HDF5 array (NAME[:, k]): on simulated recordings whose pieces are known."""

import numpy as np
import pytest

from gyrocomp import read
from gyrocomp.errors import InputError
from gyrocomp.io import TableLayout
from gyrocomp.io.tables import write_recording
from gyrocomp.recording import Recording
from gyrocomp.recording.runsplit import split_runs
from gyrocomp.simulate import get_profile, simulate

from .conftest import run


def _joined(pieces, gap_s):
    """Recordings one after another, each next one starting gap_s after the previous ended."""
    times, gyro, temps, start = [], [], [], 0.0
    for rec in pieces:
        t = rec.time_s - rec.time_s[0] + start
        times.append(t)
        gyro.append(rec.gyro_dps)
        temps.append(rec.temperature_degc)
        start = t[-1] + gap_s
    return Recording(np.concatenate(times), np.concatenate(gyro), pieces[0].gyro_axes,
                     temperature_degc=np.concatenate(temps), source="joined")


def test_power_on_and_gap_cut_where_the_logger_stopped():
    parts = [simulate("consumer", profile="warmup", duration_s=600, rate_hz=10, seed=s).recording for s in range(3)]
    joined = _joined(parts, 300.0)
    pieces = split_runs(joined, "power-on")
    assert [p.recording.n_samples for p in pieces] == [p.n_samples for p in parts]
    assert [p.start for p in pieces] == [0, parts[0].n_samples, parts[0].n_samples + parts[1].n_samples]
    assert len(split_runs(joined, "power-on", min_gap_s=600.0)) == 1  # the 300 s stops are not power-ons then
    assert len(split_runs(joined, "gap")) == 3


def test_temperature_turn_cuts_at_each_extreme():
    rec = simulate("consumer", profile=get_profile("cycle", set_points_degc=(0.0, 60.0), cycles=2), rate_hz=1,
                   seed=1).recording
    pieces = split_runs(rec, "temperature-turn")
    temperature = rec.temperature_degc
    assert len(pieces) >= 4  # two cycles: up, down, up, down (and the start)
    for piece in pieces[1:]:  # each cut lies on an extreme of the temperature around it
        k = piece.start
        window = temperature[max(k - 60, 0):k + 60]
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
    with pytest.raises(InputError, match=r"by=still: no run of 10 samples or more found"):
        split_runs(rec, "still", min_still_s=1e6)


def test_split_through_the_command_line(tmp_path):
    parts = [simulate("consumer", profile="warmup", duration_s=300, rate_hz=10, seed=s).recording for s in range(2)]
    log = tmp_path / "two.csv"
    write_recording(_joined(parts, 120.0), log)
    result = run("split", log, "-o", tmp_path / "runs", "--by", "power-on")
    assert result.returncode == 0, result.stderr
    assert "wrote 2 run(s)" in result.stdout
    written = sorted((tmp_path / "runs").glob("*.csv"))
    assert [p.name for p in written] == ["two_run1.csv", "two_run2.csv"]
    np.testing.assert_allclose(read(written[1]).gyro_dps, parts[1].gyro_dps, rtol=1e-12)
    again = run("split", log, "-o", tmp_path / "runs", "--by", "power-on")
    assert again.returncode == 2 and "two_run1.csv exists; split into an empty folder" in again.stderr


def test_time_selects_rows_in_every_reading_path(tmp_path):
    """--time A:B keeps [A, B) seconds from the first sample, in convert, apply (whole-file path), allan and
    evaluate; an empty range is refused naming the file's length."""
    rec = simulate("consumer", profile="warmup", duration_s=200, rate_hz=10, seed=3).recording
    path = tmp_path / "r.csv"
    write_recording(rec, path)
    out = tmp_path / "cut.csv"
    assert run("convert", path, out, "--time", "50:100").returncode == 0
    cut = read(out)
    assert cut.n_samples == 500 and cut.time_s[0] == pytest.approx(rec.time_s[0] + 50.0)
    assert read(path, time_range_s=(None, 20.0)).n_samples == 200
    assert run("fit", path, "-o", tmp_path / "m.json", "--temperature", "none").returncode == 0
    applied = run("apply", tmp_path / "m.json", path, "-o", tmp_path / "a.csv", "--time", "150:")
    assert applied.returncode == 0 and read(tmp_path / "a.csv").n_samples == rec.n_samples - 1500
    assert run("allan", path, "--time", ":100").returncode == 0
    empty = run("convert", path, tmp_path / "none.csv", "--time", "500:")
    assert empty.returncode == 2 and "--time 500: holds no sample; the file lasts 200 s" in empty.stderr
    bad = run("convert", path, tmp_path / "none.csv", "--time", "a:b")
    assert bad.returncode == 2 and "--time" in bad.stderr and not (tmp_path / "none.csv").exists()


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
