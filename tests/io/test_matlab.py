"""MATLAB MAT-files (v5 by scipy, v7.3 as HDF5 behind MATLAB's header) and NumPy .npz archives: written here by
the libraries that write them, read back to the values written; the real MATLAB v7.3 and .npz files in
../shared/datasets read to what h5py and numpy read of them."""

from __future__ import annotations

import json
import math
import re

import h5py
import numpy as np
import pytest
import scipy.io

from gyrocomp.errors import InputError
from gyrocomp.io import TableLayout, detect_format, read
from gyrocomp.io.guess import guess_layout
from gyrocomp.io.matlab import MAT73_MAGIC

from ..conftest import run, shared_dataset

RAD_TO_DEG = 180.0 / math.pi


@pytest.fixture
def imu():
    """(time [s], gyro [rad/s] (n, 3), temperature [degC]) at 50 Hz."""
    rng = np.random.default_rng(7)
    t = np.arange(400) / 50.0
    return t, 0.01 + 0.001 * rng.standard_normal((400, 3)), 20.0 + 0.01 * t


def _gyro_columns(matrix: str, first: int = 0) -> dict[str, str]:
    """gyro_x, gyro_y, gyro_z mapped to columns ``first``, ``first`` + 1, ``first`` + 2 of ``matrix``."""
    return {f"gyro_{a}": f"{matrix}[:, {first + k}]" for k, a in enumerate("xyz")}


def _mat73(path, arrays: dict) -> None:
    """A MATLAB v7.3 file as MATLAB writes one: the 512-byte header, then HDF5 holding each array by columns (a
    MATLAB (n, 3) array is an HDF5 (3, n) dataset) with its MATLAB_class."""
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, values in arrays.items():
            f[name] = np.atleast_2d(values).T if np.ndim(values) == 2 else np.atleast_2d(values)
            f[name].attrs["MATLAB_class"] = np.bytes_(b"double")
        f["label"] = np.frombuffer(b"chamber", dtype=np.uint8)[None, :].astype(np.uint16)
        f["label"].attrs["MATLAB_class"] = np.bytes_(b"char")
    with open(path, "r+b") as fh:
        fh.write(MAT73_MAGIC + b", Platform: GLNXA64, Created on: Fri Nov 27 2026 HDF5 schema 1.00 .".ljust(116))


@pytest.mark.parametrize("kind", ["npz", "mat5", "mat73"])
def test_named_arrays_are_read_as_written(tmp_path, imu, kind):
    """Each format from its library: time, an (n, 3) gyro under a common name, the temperature; MATLAB's row
    vectors one-dimensional; the gyro's unit from the layout; the format told from the file."""
    t, gyro, temperature = imu
    arrays = {"time": t, "angular_velocity": gyro, "temperature": temperature}
    path = tmp_path / ("log.npz" if kind == "npz" else "log.mat")
    if kind == "npz":
        np.savez(path, **arrays, note=np.array(["a string array is left out"]))
    elif kind == "mat5":
        scipy.io.savemat(path, {**arrays, "time": t[None, :], "label": "chamber", "meta": {"rate": 50.0}})
    else:
        _mat73(path, {**arrays, "time": t[None, :]})
    assert detect_format(path) == "mat"
    rec = read(path, TableLayout(gyro_unit="rad/s"))
    np.testing.assert_array_equal(rec.time_s, t)
    np.testing.assert_allclose(rec.gyro_dps, gyro * RAD_TO_DEG, rtol=1e-15)
    np.testing.assert_array_equal(rec.temperature_degc, temperature)
    assert rec.gyro_axes == ("gyro_x", "gyro_y", "gyro_z")


@pytest.mark.parametrize("kind", ["mat5", "mat73"])
def test_a_structures_fields_are_arrays_named_by_their_path(tmp_path, imu, kind):
    """MATLAB's save of a struct imu with fields t and gyro (and a text field, left out): imu/t and imu/gyro, as a
    v7.3 file's HDF5 groups name them."""
    t, gyro, _ = imu
    path = tmp_path / "struct.mat"
    if kind == "mat5":
        scipy.io.savemat(path, {"imu": {"t": t, "gyro": gyro, "label": "chamber"}})
    else:
        _mat73(path, {"imu/t": t[None, :], "imu/gyro": gyro})
    rec = read(path, TableLayout(columns={"time": "imu/t", "gyro": "imu/gyro"}))
    np.testing.assert_array_equal(rec.time_s, t)
    np.testing.assert_array_equal(rec.gyro_dps, gyro)


def test_columns_of_one_matrix_and_a_rate_for_a_file_without_time(tmp_path, imu):
    """A MATLAB habit: one (n, 4) matrix [t x y z] mapped column by column (NAME[:, k]); a file with no time
    array is timed by the rate given, and a rate given for a file with time is refused."""
    t, gyro, _ = imu
    path = tmp_path / "buffer.mat"
    scipy.io.savemat(path, {"gyroBuffer": np.column_stack([t, gyro])})
    mapping = {"time": "gyroBuffer[:, 0]", **_gyro_columns("gyroBuffer", first=1)}
    rec = read(path, TableLayout(columns=mapping))
    np.testing.assert_array_equal(rec.gyro_dps, gyro)
    np.testing.assert_array_equal(rec.time_s, t)
    with pytest.raises(InputError, match=r"buffer.mat: rate_hz=50 is for a file without time, and this one has"):
        read(path, TableLayout(columns=mapping, rate_hz=50.0))
    untimed = tmp_path / "untimed.npz"
    np.savez(untimed, data=np.column_stack([gyro, gyro]))
    with pytest.raises(InputError, match=r"untimed.npz: no time dataset \(the file has data\); .*rate_hz=100"):
        read(untimed)
    columns = _gyro_columns("data")
    rec = read(untimed, TableLayout(columns=columns, rate_hz=50.0))
    np.testing.assert_array_equal(rec.time_s, np.arange(400) / 50.0)
    np.testing.assert_array_equal(rec.gyro_dps, gyro)


def test_what_is_no_mat_file_or_holds_no_numbers_is_one_line(tmp_path, imu):
    t, gyro, _ = imu
    ascii_mat = tmp_path / "xsens_gyro.mat"
    np.savetxt(ascii_mat, np.column_stack([t, gyro]))  # MATLAB's save -ascii
    result = run("allan", ascii_mat)
    assert result.returncode == 2 and result.stderr.count("\n") == 1
    assert "a text matrix (MATLAB's save -ascii), not a binary MAT-file" in result.stderr
    assert "--format csv" in result.stderr and "--names time,gyro_x,gyro_y,gyro_z" in result.stderr
    objects = tmp_path / "objects.npz"
    np.savez(objects, meta=np.array([{"rate": 50}], dtype=object))
    with pytest.raises(InputError, match=r"objects.npz: no numeric array of one or two dimensions in the file"):
        read(objects)  # the object array is left unloaded: numpy.load without pickles
    cut = tmp_path / "cut.npz"
    np.savez(cut, time=t, gyro=gyro)
    cut.write_bytes(cut.read_bytes()[:200])
    with pytest.raises(InputError, match=r"cut.npz: not a readable .npz archive"):
        read(cut)
    bad = tmp_path / "bad.mat"
    bad.write_bytes(b"MATLAB 5.0 MAT-file" + bytes(200))
    with pytest.raises(InputError, match=r"bad.mat: not a readable MAT-file \(.*\); is it damaged or cut short\?"):
        read(bad)


def test_a_mat_file_that_crashes_scipys_reader_is_one_line_and_the_command_lives(tmp_path, imu):
    """A byte of the gyro matrix's data type flipped (9, double, to 137: no type) makes scipy's compiled reader
    read past its buffer and kill its process (found by flipping bytes; scipy 1.16): it runs in a process of its
    own, so the command says so in one line and exits 2."""
    t, gyro, _ = imu
    path = tmp_path / "flipped.mat"
    scipy.io.savemat(path, {"time": t, "gyro": gyro})
    data = bytearray(path.read_bytes())
    at = data.index(b"gyro\x09\x00\x00\x00") + 4  # the name, then the real part's tag: miDOUBLE
    data[at] ^= 0x80
    path.write_bytes(bytes(data))
    result = run("allan", path)
    assert result.returncode == 2 and result.stderr.count("\n") == 1, result.stderr
    assert "flipped.mat: not a readable MAT-file (its reader stopped on it); is it damaged" in result.stderr


def test_real_matlab_v73_and_npz_files_read_as_h5py_and_numpy_read_them():
    """../shared/datasets: sunsided's MPU-6050 gyroBuffer, MATLAB v7.3, [t x y z] in deg/s (its README:
    h5py.File(f)['gyroBuffer'][:].T); SMAC's ADIS16405 copy, an .npz whose data holds gyro x, y, z first at 100 Hz
    (fs_hz)."""
    folder = shared_dataset("sunsided-mpu6050-static") / "unmoved-with-x-pointing-forward"
    path = folder / "mpu6050_gyroscope.mat"
    mapping = {"time": "gyroBuffer[:, 0]", **_gyro_columns("gyroBuffer", first=1)}
    with h5py.File(path, "r") as f:
        expected = f["gyroBuffer"][:].T
    rec = read(path, TableLayout(columns=mapping))
    np.testing.assert_array_equal(rec.time_s, expected[:, 0])
    np.testing.assert_array_equal(rec.gyro_dps, expected[:, 1:])
    npz = shared_dataset("smac-imudata-adis16405") / "adis_16405_imu1.npz"
    with np.load(npz) as archive:
        data, rate_hz = archive["data"], float(archive["fs_hz"])
    columns = _gyro_columns("data")
    rec = read(npz, TableLayout(columns=columns, rate_hz=rate_hz))
    np.testing.assert_array_equal(rec.gyro_dps, data[:, :3].astype(float))
    assert rec.n_samples == 1_000_000 and rec.rate_hz == pytest.approx(100.0)


def test_the_layout_guessed_for_a_real_npz_reads_what_its_netcdf_original_holds():
    """../shared's CATS tag: its .npz copy (t_s, gyro_mrad_s, acc_m_s2, temperature_c; float32, its README) read
    with the layout init guesses from those names equals the NetCDF original, whose units are attributes."""
    folder = shared_dataset("skdivemove-cats-tempcal")
    guess = guess_layout(folder / "cats_temperature_calib_1hz.npz")
    assert (guess.layout.gyro_unit, guess.layout.accel_unit) == ("mrad/s", "m/s2")
    copy = read(folder / "cats_temperature_calib_1hz.npz", guess.layout)
    original = read(folder / "cats_temperature_calib.nc")
    np.testing.assert_allclose(copy.gyro_dps, original.gyro_dps, atol=5e-4 * 0.18 / math.pi)
    np.testing.assert_allclose(copy.accel_g, original.accel_g, atol=1e-5)
    np.testing.assert_allclose(copy.temperature_degc, original.temperature_degc, atol=2e-6)


def test_a_matrix_named_by_a_list_of_column_names_is_mapped_column_by_column(tmp_path, imu):
    """MATLAB importdata's struct (data and colheaders) and numpy's data beside columns: each column is a channel by
    its label (data[:, k]), its unit from the label; a single number named for the rate times a file without time."""
    t, gyro, temperature = imu
    path = tmp_path / "imported.mat"
    data = np.column_stack([t, gyro, temperature])
    scipy.io.savemat(path, {"imp": {"data": data, "colheaders": ["Time", "GyrX", "GyrY", "GyrZ", "Temp"]}})
    guess = guess_layout(path)
    assert guess.layout.columns == {
        "time": "imp/data[:, 0]",
        "gyro_x": "imp/data[:, 1]",
        "gyro_y": "imp/data[:, 2]",
        "gyro_z": "imp/data[:, 3]",
        "temperature": "imp/data[:, 4]",
    }
    rec = read(path, guess.layout)
    np.testing.assert_array_equal(rec.gyro_dps, gyro)
    np.testing.assert_array_equal(rec.temperature_degc, temperature)
    archive = tmp_path / "untimed.npz"
    np.savez(archive, data=gyro, columns=np.array(["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]), fs_hz=50.0)
    untimed = guess_layout(archive)
    assert untimed.layout.rate_hz == 50.0 and untimed.layout.gyro_unit == "rad/s"
    assert untimed.reasons[0] == "time: sample n at n / 50 s (the file's fs_hz = 50; no time array)"
    np.testing.assert_allclose(read(archive, untimed.layout).gyro_dps, gyro * RAD_TO_DEG, rtol=1e-15)


def test_the_layout_guessed_for_smacs_npz_reads_its_columns_at_its_rate():
    """../shared's SMAC ADIS16405 copy: data (1e6, 6) with columns gyro_x_dps .. acc_z_g and fs_hz = 100 (its
    README); init needs no option."""
    path = shared_dataset("smac-imudata-adis16405") / "adis_16405_imu1.npz"
    guess = guess_layout(path)
    assert guess.layout.rate_hz == 100.0 and (guess.layout.gyro_unit, guess.layout.accel_unit) == ("deg/s", "g")
    with np.load(path) as archive:
        data = archive["data"].astype(float)
    rec = read(path, guess.layout)
    np.testing.assert_array_equal(rec.gyro_dps, data[:, :3])
    np.testing.assert_array_equal(rec.accel_g, data[:, 3:])


def test_a_time_then_axes_array_is_guessed_by_its_columns_and_its_time_can_be_left_unread(tmp_path, imu):
    """An (n, 4) gyro array of [t x y z] (MATLAB logs keep a sensor's buffer so): init maps its columns, the first
    the time; an (n, 4) array whose first column falls is not taken for one. With the time left unread
    (``columns={'time': ''}``) and a rate, the samples are at n / rate."""
    t, gyro, _ = imu
    path = tmp_path / "buffer.npz"
    np.savez(path, gyroBuffer=np.column_stack([t, gyro]))
    guess = guess_layout(path)
    assert guess.layout.columns == {"time": "gyroBuffer[:, 0]", **_gyro_columns("gyroBuffer", first=1)}
    rec = read(path, guess.layout)
    np.testing.assert_array_equal(rec.time_s, t)
    np.testing.assert_array_equal(rec.gyro_dps, gyro)
    untimed = read(path, TableLayout({**_gyro_columns("gyroBuffer", first=1), "time": ""}, rate_hz=25.0))
    np.testing.assert_array_equal(untimed.time_s, np.arange(t.size) / 25.0)
    np.testing.assert_array_equal(untimed.gyro_dps, gyro)
    with pytest.raises(
        InputError,
        match=r"buffer.npz: rate_hz=25 is for a file without time, and this one has 'gyroBuffer\[:, 0\]'; to read "
        r"the samples at it instead, leave the time unread \(columns=\{'time': ''\}\)",
    ):
        read(path, TableLayout({"time": "gyroBuffer[:, 0]", **_gyro_columns("gyroBuffer", first=1)}, rate_hz=25.0))
    np.savez(path, gyroBuffer=np.column_stack([t[::-1], gyro]))
    with pytest.raises(InputError, match=r"no array looks like the gyro .*an \(n, 4\) one of the time then x, y, z"):
        guess_layout(path)


def test_sunsideds_burst_stamped_mpu6050_log_from_init_to_its_allan_deviation(tmp_path):
    """../shared's sunsided MPU-6050 log (gyroBuffer, [t x y z], its README; stamps in bursts, 99.3 Hz on
    average): init guesses its columns; allan then says the stamps come in bursts and refuses the gaps; with the
    time left unread at the mean rate it says, the first Allan deviation of each axis is within 10 % of the
    standard deviation the dataset's README gives (0.126, 0.091, 0.113 deg/s: white noise, whose deviation at
    one sample is the standard deviation)."""
    source = shared_dataset("sunsided-mpu6050-static") / "unmoved-with-x-pointing-forward-10min"
    path = source / "mpu6050_gyroscope.mat"
    made = run("init", path, cwd=tmp_path)
    assert made.returncode == 0, made.stderr
    assert 'time = "gyroBuffer[:, 0]"' in (tmp_path / "gyrocomp.toml").read_text()
    said = run("allan", path, cwd=tmp_path)
    assert said.returncode == 2 and "(check 'time-bursts')" in said.stderr, said.stderr
    assert "the stamps come in bursts, so the stretches between them hold 3.9 samples" in said.stderr
    assert "--split-gaps" not in said.stderr  # pooling stretches of four samples would be no Allan deviation
    rate = re.search(r"\(--columns time= and --rate ([\d.]+)\)", said.stderr).group(1)
    assert 99.0 < float(rate) < 99.6  # the README's 99.3 Hz on average
    columns = ",".join(f"{k}={v}" for k, v in _gyro_columns("gyroBuffer", first=1).items()) + ",time="
    done = run("allan", path, "--columns", columns, "--rate", rate, "--json", cwd=tmp_path)
    assert done.returncode == 0 and "time-bursts" not in done.stderr, done.stderr
    axes = json.loads(done.stdout)["axes"]
    for axis, std_dps in zip(("gyro_x", "gyro_y", "gyro_z"), (0.126, 0.091, 0.113)):
        assert axes[axis]["adev"][0] == pytest.approx(std_dps, rel=0.1)
