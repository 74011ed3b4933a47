"""The project file (gyrocomp.toml): init guesses a table's layout from its names and magnitudes, every command
reads the file, the command line wins, and a bad file is refused in one line; through the real entry point."""

import json
import os
import subprocess

import h5py
import numpy as np
import pandas as pd
import pytest

from gyrocomp.allan import allan_deviation
from gyrocomp.errors import InputError
from gyrocomp.io.guess import guess_layout

from ..conftest import SCRIPT, run

RAD = np.pi / 180.0


def _init_then_allan_reads(folder, name: str, axis: str, gyro_dps: np.ndarray, rate_hz: float) -> None:
    """``gyrocomp init NAME`` in ``folder``, then ``allan NAME --json`` with the project file it wrote: the curve
    of ``axis`` equals the library's Allan deviation of ``gyro_dps`` [deg/s] at ``rate_hz`` [Hz], the file read as
    mapped."""
    assert run("init", name, cwd=folder).returncode == 0
    allan = run("allan", name, "--json", cwd=folder)
    assert allan.returncode == 0, allan.stderr
    expected = allan_deviation(gyro_dps, rate_hz).deviation
    np.testing.assert_allclose(json.loads(allan.stdout)["axes"][axis]["adev"], expected, rtol=1e-9)


def _log(path, n=4000, rate_hz=100.0, *, names=None, time_unit="us", si=True, sep="\t", seed=0):
    """A chamber log as another project writes it: time in us, gyro in rad/s, accelerometer in m/s^2, the
    temperature rising through 30 degC; gyro bias 0.1 + 0.01 (T - 25) deg/s on each axis."""
    names = names or [
        "timestamp",
        "imu.gyro.x",
        "imu.gyro.y",
        "imu.gyro.z",
        "imu.acc.x",
        "imu.acc.y",
        "imu.acc.z",
        "imu.temperature",
    ]
    rng = np.random.default_rng(seed)
    k = np.arange(n)
    temperature = 20.0 + 30.0 * k / n
    time = 1_700_000_000 + k / rate_hz
    time = time * {"s": 1, "ms": 1e3, "us": 1e6}[time_unit]
    gyro_dps = 0.1 + 0.01 * (temperature - 25.0)[:, None] + 0.002 * rng.standard_normal((n, 3))
    accel_g = np.array([0.0, 0.0, 1.0]) + 0.001 * rng.standard_normal((n, 3))
    gyro, accel = (gyro_dps * RAD, accel_g * 9.80665) if si else (gyro_dps, accel_g)
    rows = [
        sep.join(
            [
                f"{time[i]:.0f}" if time_unit != "s" else f"{time[i]:.3f}",
                *(f"{v:.8g}" for v in gyro[i]),
                *(f"{v:.6g}" for v in accel[i]),
                f"{temperature[i]:.3f}",
            ]
        )
        for i in range(n)
    ]
    path.write_text(sep.join(names) + "\n" + "\n".join(rows) + "\n")
    return path


@pytest.mark.slow
def test_init_then_every_command_without_flags(tmp_path):
    """The issue's log: tab-separated, timestamp in us, imu.gyro.x in rad/s, imu.acc.x in m/s^2: init, then fit,
    show, evaluate, apply and report with no reading option given."""
    _log(tmp_path / "log.tsv")
    first = _log(tmp_path / "other.tsv", seed=1)
    made = run("init", "log.tsv", cwd=tmp_path)
    assert made.returncode == 0, made.stderr
    for said in ("time unit us", "accelerometer in m/s2", "gyro in rad/s", "gyro_x = 'imu.gyro.x'"):
        assert said in made.stdout
    fitted = run("fit", "log.tsv", "-o", "m.json", cwd=tmp_path)
    assert fitted.returncode == 0, fitted.stderr
    model = json.loads((tmp_path / "m.json").read_text())
    # the bias in deg/s: 0.1 at 25 degC, 0.01 deg/s per degC (in rad/s it would be 57 times smaller)
    shown = run("show", "m.json", "--json", cwd=tmp_path)
    assert shown.returncode == 0, shown.stderr
    assert model["axes"]["gyro_x"]["temperature"] is not None
    evaluated = run("evaluate", "m.json", first.name, "--json", cwd=tmp_path)
    assert evaluated.returncode == 0, evaluated.stderr
    axes = json.loads(evaluated.stdout)["runs"][0]["axes"]
    assert axes["gyro_x"]["bias_offset_raw_dps"] > 0.2  # 0.3 deg/s of drift, read in deg/s
    assert axes["gyro_x"]["bias_offset_comp_dps"] < axes["gyro_x"]["bias_offset_raw_dps"] / 5
    applied = run("apply", "m.json", first.name, "-o", "out.tsv", cwd=tmp_path)
    assert applied.returncode == 0, applied.stderr
    reported = run("report", "m.json", first.name, "-o", "r.html", cwd=tmp_path)
    assert reported.returncode == 0 or "matplotlib" in reported.stderr
    # apply's output keeps the input's table format (tabs, its columns and units): every command reads it with
    # the same project file, no flag given (before: comma-separated whatever its name, and the next command read
    # its header as one column)
    out = (tmp_path / "out.tsv").read_text().splitlines()
    assert out[0] == (tmp_path / first.name).read_text().splitlines()[0] and "\t" in out[1] and "," not in out[1]
    for command in (
        ("fit", "out.tsv", "-o", "again.json"),
        ("evaluate", "m.json", "out.tsv", "--json"),
        ("apply", "m.json", "out.tsv", "-o", "twice.tsv"),
        ("report", "m.json", "out.tsv", "-o", "o.html"),
        ("export", "m.json", "-o", "m.parm"),
        ("export", "m.json", "-o", "c"),
    ):  # the format by name
        done = run(*command, cwd=tmp_path)
        assert done.returncode == 0 or (command[0] == "report" and "matplotlib" in done.stderr), (command, done.stderr)
    again = json.loads(run("evaluate", "m.json", "out.tsv", "--json", cwd=tmp_path).stdout)["runs"][0]["axes"]
    assert again["gyro_x"]["bias_offset_raw_dps"] < axes["gyro_x"]["bias_offset_raw_dps"] / 5  # compensated already
    # the command line wins: the same file read as deg/s has 57 times less drift
    overridden = run("evaluate", "m.json", first.name, "--json", "--gyro-unit", "deg/s", cwd=tmp_path)
    raw = json.loads(overridden.stdout)["runs"][0]["axes"]["gyro_x"]["bias_offset_raw_dps"]
    assert raw == pytest.approx(axes["gyro_x"]["bias_offset_raw_dps"] * RAD, rel=1e-6)
    shown = run("config", "show", "--json", cwd=tmp_path)
    assert json.loads(shown.stdout)["read"]["gyro-unit"] == "rad/s"


def test_defaults_and_command_sections_apply_where_the_option_exists(tmp_path):
    _log(
        tmp_path / "run.csv",
        names=["time", "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z", "temperature"],
        time_unit="s",
        si=False,
        sep=",",
    )
    assert run("fit", "run.csv", "-o", "m.json", cwd=tmp_path).returncode == 0
    (tmp_path / "gyrocomp.toml").write_text("[defaults]\nwindow = 7.5\n\n[evaluate]\nturn-on-window = 20\n")
    evaluated = run("evaluate", "m.json", "run.csv", "--json", cwd=tmp_path)
    assert evaluated.returncode == 0, evaluated.stderr
    assert json.loads(evaluated.stdout)["runs"][0]["window_s"] == 7.5
    elsewhere = tmp_path / "elsewhere.toml"
    elsewhere.write_text("[defaults]\nwindow = 12\n")
    evaluated = run("--config", elsewhere, "evaluate", "m.json", "run.csv", "--json", cwd=tmp_path)
    assert json.loads(evaluated.stdout)["runs"][0]["window_s"] == 12


@pytest.mark.parametrize(
    "text, message",
    [
        ("[read]\ngyro_units = 'rad/s'\n", r"gyrocomp.toml: \[read\] gyro-units: not a reading option"),
        ("[fitt]\norder = 3\n", r"gyrocomp.toml: \[fitt\]: no such command"),
        (
            "[evaluate]\nwindoww = 3\n",
            r"gyrocomp.toml: \[evaluate\] windoww: gyrocomp evaluate has no option --windoww",
        ),
        ("[read\n", r"gyrocomp.toml: not a readable TOML file"),
        ("window = 3\n", r"gyrocomp.toml: window = 3: options go in \[read\], \[defaults\] or a command's section"),
        ("read = 5\n", r"gyrocomp.toml: read = 5: \[read\] is a table of options"),
        ('defaults = "x"\n', r"gyrocomp.toml: defaults = 'x': \[defaults\] is a table of options"),
        ("[defaults]\nwindow = 1e999\n", r"gyrocomp.toml: \[defaults\] window = inf: not a finite number"),
        ("[defaults]\nwindow = nan\n", r"gyrocomp.toml: \[defaults\] window = nan: not a finite number"),
        ("[evaluate]\nwindow = 'long'\n", r"gyrocomp.toml: \[evaluate\] window = 'long': 'long' is not a"),
        ("[evaluate]\nwindow = [1, 2]\n", r"gyrocomp.toml: \[evaluate\] window = \[1, 2\]: --window takes one value"),
        (
            "[defaults]\nrate-schedule = 5\n",
            r"gyrocomp.toml: \[defaults\] rate-schedule = 5: --rate-schedule takes a path, written as a",
        ),
        (
            "[defaults]\ngyro-units = 'rad/s'\n",
            r"gyrocomp.toml: \[defaults\] gyro-units: no command has such an option",
        ),
        ("[read]\ncolumns = 5\n", r"gyrocomp.toml: \[read\] columns = 5: a string CH=COL"),
        ("[defaults]\nwindow = {a = 1}\n", r"gyrocomp.toml: \[defaults\] window: a table; each option is one value"),
        ("[fleet.fit.x]\nseed = 1\n", r"gyrocomp.toml: \[fleet.fit.x\]: no such command"),
        ("x = " + "[" * 3000 + "]" * 3000 + "\n", r"gyrocomp.toml: not a project file: its tables or arrays nest"),
        ("x = " + "{a = " * 500 + "1" + "}" * 500 + "\n", r"gyrocomp.toml: not a project file: its tables or arrays"),
    ],
)
def test_a_bad_project_file_is_refused_in_one_line(tmp_path, text, message):
    import re

    (tmp_path / "gyrocomp.toml").write_text(text)
    result = run("evaluate", "m.json", "run.csv", cwd=tmp_path)
    assert result.returncode == 2 and len(result.stderr.strip().splitlines()) == 1
    assert re.search(message, result.stderr), result.stderr
    missing = run("--config", "nothere.toml", "show", "m.json", cwd=tmp_path)
    assert missing.returncode == 2 and "--config nothere.toml: no such file" in missing.stderr


def test_the_project_file_is_switched_off_by_no_config_and_its_variable(tmp_path):
    (tmp_path / "run.csv").write_text(
        "time,gyro_z,temperature\n" + "".join(f"{k},{0.1 + 0.01 * (k % 5)},{25 + k / 20}\n" for k in range(200))
    )
    (tmp_path / "gyrocomp.toml").write_text("[read]\ncolumns = 'gyro_z=GyrZ'\n")  # wrong for run.csv
    # a table in gyrocomp's own layout that the project file does not describe is read in that layout, said so
    assert "run.csv: read in gyrocomp's own layout" in run("check", "run.csv", cwd=tmp_path).stderr
    for args, env in ((["--no-config"], {}), ([], {"GYROCOMP_NO_CONFIG": "1"})):
        result = subprocess.run(
            [str(SCRIPT), *args, "check", "run.csv"], capture_output=True, text=True, cwd=tmp_path,
            env={**os.environ, **env}, timeout=120,
        )  # fmt: skip
        assert result.returncode == 0 and "gyrocomp.toml" not in result.stderr, result.stderr
    both = run("--config", "gyrocomp.toml", "--no-config", "check", "run.csv", cwd=tmp_path)
    assert both.returncode == 2 and "--config and --no-config: give one of them" in both.stderr
    empty = run("--config", "", "check", "run.csv", cwd=tmp_path)
    assert empty.returncode == 2 and "give --no-config" in empty.stderr


def test_an_option_of_gyrocomp_itself_after_the_command_is_told_where_it_goes(tmp_path):
    result = run("check", "run.csv", "--config", "x.toml", cwd=tmp_path)
    assert result.returncode == 2
    assert "--config is an option of gyrocomp itself: give it before the command" in result.stderr


@pytest.mark.slow
def test_init_keeps_an_existing_file_and_refuses_what_it_cannot_read(tmp_path):
    _log(tmp_path / "log.tsv", n=200)
    (tmp_path / "gyrocomp.toml").write_text("# mine\n")
    kept = run("init", "log.tsv", cwd=tmp_path)
    assert kept.returncode == 2 and "gyrocomp.toml: exists; give --force" in kept.stderr
    assert (tmp_path / "gyrocomp.toml").read_text() == "# mine\n"
    assert run("init", "log.tsv", "--force", cwd=tmp_path).returncode == 0
    before = (tmp_path / "log.tsv").read_bytes()
    onto = run("init", "log.tsv", "-o", "log.tsv", "--force", cwd=tmp_path)  # the log is an input
    assert onto.returncode == 2 and "-o log.tsv: this is an input file" in onto.stderr
    assert (tmp_path / "log.tsv").read_bytes() == before
    (tmp_path / "gyrocomp.toml").write_text("[broken\n")  # a file that does not load is replaced, not obeyed
    assert run("init", "log.tsv", "--force", cwd=tmp_path).returncode == 0
    assert run("config", "show", cwd=tmp_path).returncode == 0
    (tmp_path / "flight.ulg").write_bytes(b"ULog\x01\x12\x35\x01" + bytes(8))
    refused = run("init", "flight.ulg", "-o", "x.toml", cwd=tmp_path)
    assert refused.returncode == 2 and "not a CSV/TSV or Parquet table" in refused.stderr


def test_guessing_from_names_and_magnitudes(tmp_path):
    """Units from the magnitudes when the names do not say: ms time at 50 Hz, accelerometer in g, gyro then in
    deg/s; names like GyrZ, Temp; a name that says its unit wins over the magnitudes."""
    path = _log(
        tmp_path / "v.csv",
        names=["Time", "GyrX", "GyrY", "GyrZ", "AccX", "AccY", "AccZ", "Temp"],
        time_unit="ms",
        si=False,
        sep=";",
        rate_hz=50.0,
    )
    guess = guess_layout(path)
    layout = guess.layout
    assert layout.columns == {
        "time": "Time",
        "gyro_x": "GyrX",
        "gyro_y": "GyrY",
        "gyro_z": "GyrZ",
        "accel_x": "AccX",
        "accel_y": "AccY",
        "accel_z": "AccZ",
        "temperature": "Temp",
    }
    # the separator (;) is told from the file by every reader too: the layout does not pin it
    assert (layout.time_unit, layout.accel_unit, layout.gyro_unit, layout.delimiter) == ("ms", "g", "deg/s", None)
    assert any("50 Hz in ms" in r for r in guess.reasons)
    named = _log(
        tmp_path / "n.csv",
        names=["time_s", "gyro_x_rad", "gyro_y_rad", "gyro_z_rad", "ax", "ay", "az", "temperature"],
        time_unit="s",
        si=False,
        sep=",",
    )
    guess = guess_layout(named)
    assert guess.layout.gyro_unit == "rad/s" and guess.layout.time_unit == "s"
    assert guess.unused == () and guess.layout.columns["accel_y"] == "ay"  # a two-letter name: channel and axis
    assert guess.layout.accel_unit == "g"
    (tmp_path / "bad.csv").write_text("a,b\n1,2\n2,1\n3,5\n")
    with pytest.raises(InputError, match=r"bad.csv: no column looks like a gyro axis"):
        guess_layout(tmp_path / "bad.csv")


def test_raw_counts_after_a_preamble_are_guessed_scaled(tmp_path):
    """An Arduino sketch's MPU-6050 log: metadata lines (the rate among them), then ax..gz in raw counts without
    time. The rate is taken from the preamble's Fs line, else asked for. The accelerometer's norm at rest (16384
    counts) is near 1 g in no unit: raw counts, 1/16384 g, an InvenSense part's power-on range, whose gyro then
    counts 131 per deg/s; a norm of no power of two leaves the gyro's scale to the user, in deg/s with a reason that
    says so."""
    rng = np.random.default_rng(1)
    n = 500
    accel = np.array([300.0, -200.0, 16300.0]) + rng.normal(0, 30, (n, 3))
    gyro = np.array([-430.0, 146.0, -66.0]) + rng.normal(0, 12, (n, 3))
    body = "\n".join(",".join(str(int(round(v))) for v in row) for row in np.column_stack([accel, gyro]))
    preamble = "Fs,100\nLogging Type,1\nInitialization time,-1\nWaiting time,-1\n"
    (tmp_path / "mpu.csv").write_text(preamble + "ax,ay,az,gx,gy,gz\n" + body + "\n")
    guess = guess_layout(tmp_path / "mpu.csv")  # the rate the preamble states: Fs,100
    assert guess.layout.rate_hz == 100.0 and "the rate the preamble states, 'Fs,100'" in guess.reasons[0]
    (tmp_path / "unstated.csv").write_text(preamble.replace("Fs,100", "Fs,fast") + "ax,ay,az,gx,gy,gz\n" + body + "\n")
    with pytest.raises(InputError, match=r"no column looks like the time .*\(rate_hz=50\)"):
        guess_layout(tmp_path / "unstated.csv")
    assert guess_layout(tmp_path / "unstated.csv", rate_hz=100.0).layout.rate_hz == 100.0
    assert (guess.layout.accel_unit, guess.layout.gyro_unit) == ("1/16384 g", "1/131 deg/s")
    assert guess.layout.columns == {
        "accel_x": "ax",
        "accel_y": "ay",
        "accel_z": "az",
        "gyro_x": "gx",
        "gyro_y": "gy",
        "gyro_z": "gz",
    }
    assert any("raw counts, 1/16384 g" in r and "check the part's range" in r for r in guess.reasons)
    _init_then_allan_reads(tmp_path, "mpu.csv", "gyro_x", np.round(gyro[:, 0]) / 131.0, 100.0)
    odd_body = "\n".join(",".join(str(int(round(v))) for v in row) for row in np.column_stack([0.75 * accel, gyro]))
    (tmp_path / "odd.csv").write_text(preamble + "ax,ay,az,gx,gy,gz\n" + odd_body + "\n")  # 12,200 per g
    odd = guess_layout(tmp_path / "odd.csv", rate_hz=100.0)
    assert odd.layout.accel_unit == "1/12200 g" and odd.layout.gyro_unit == "deg/s"
    assert any("the gyro's scale cannot be told at rest" in r for r in odd.reasons)


def test_an_xsens_export_with_its_comment_lines_and_sample_time_fine(tmp_path):
    """MT Manager's text export: lines of '// ...' (no separator) before a tab-separated header, a 16-bit
    PacketCounter and SampleTimeFine (ticks of a 10 kHz clock). The preamble is skipped, the tab told from the
    header, SampleTimeFine taken as the time in 100 us, the counter left unused; with only a counter, the counter is
    the time and the reason asks for its period."""
    n, rate_hz = 300, 100.0
    rng = np.random.default_rng(2)
    gyro = 0.002 + 0.001 * rng.standard_normal((n, 3))
    rows = [
        "\t".join(
            [f"{k % 65536:05d}", str(16011 + 100 * k), "0.1", "-0.2", "9.81", *(f"{v:.6f}" for v in gyro[k]), "30"]
        )
        for k in range(n)
    ]
    preamble = "// Start Time: Unknown\n// Update Rate: 100.0Hz\n// Firmware Version: 4.3.0\n"
    header = "PacketCounter\tSampleTimeFine\tAcc_X\tAcc_Y\tAcc_Z\tGyr_X\tGyr_Y\tGyr_Z\tTemperature\n"
    (tmp_path / "MT_0001.txt").write_text(preamble + header + "\n".join(rows) + "\n")
    guess = guess_layout(tmp_path / "MT_0001.txt")
    assert guess.layout.columns["time"] == "SampleTimeFine" and guess.layout.time_unit == "100 us"
    assert guess.layout.delimiter is None and guess.unused == ("PacketCounter",)  # the tabs told by the reader
    as_written = np.round(gyro[:, 0], 6) * 180.0 / np.pi  # 6 decimals
    _init_then_allan_reads(tmp_path, "MT_0001.txt", "gyro_x", as_written, rate_hz)
    counted = "\n".join(r.split("\t", 2)[0] + "\t" + r.split("\t", 2)[2] for r in rows)
    header = header.replace("SampleTimeFine\t", "")
    (tmp_path / "counted.txt").write_text(preamble + header + counted + "\n")
    counter = guess_layout(tmp_path / "counted.txt")
    assert counter.layout.columns["time"] == "PacketCounter"
    assert any("a counter, the only column that only increases" in r for r in counter.reasons)


def test_files_of_named_arrays_get_their_layout_guessed_from_the_names(tmp_path):
    """An .npz as a script saves one (t_s, gyro_mrad_s (n, 3), acc_m_s2 (n, 3), temperature_c): each array named
    as a channel, the units from the names; init writes it, and allan then reads the file as mapped. An HDF5 file of
    one array per axis; a file whose arrays name no gyro lists them with their shapes."""
    rng = np.random.default_rng(4)
    n = 2000
    gyro_mrad_s = 0.5 + 0.05 * rng.standard_normal((n, 3))
    arrays = {
        "t_s": np.arange(n) / 50.0,
        "gyro_mrad_s": gyro_mrad_s,
        "acc_m_s2": np.array([0.0, 0.0, 9.81]) + 0.01 * rng.standard_normal((n, 3)),
        "temperature_c": np.linspace(20, 30, n),
    }
    np.savez(tmp_path / "log.npz", **arrays)
    guess = guess_layout(tmp_path / "log.npz")
    assert guess.layout.columns == {
        "time": "t_s",
        "gyro": "gyro_mrad_s",
        "accel": "acc_m_s2",
        "temperature": "temperature_c",
    }
    assert (guess.layout.gyro_unit, guess.layout.accel_unit, guess.layout.time_unit) == ("mrad/s", "m/s2", "s")
    _init_then_allan_reads(tmp_path, "log.npz", "gyro_y", gyro_mrad_s[:, 1] * 0.18 / np.pi, 50.0)
    with h5py.File(tmp_path / "axes.h5", "w") as f:
        f["imu/time"] = arrays["t_s"]
        for k, axis in enumerate("xyz"):
            f[f"imu/gyr_{axis}"] = gyro_mrad_s[:, k] * 0.18 / np.pi
    per_axis = guess_layout(tmp_path / "axes.h5")
    assert per_axis.layout.columns == {
        "time": "imu/time",
        "gyro_x": "imu/gyr_x",
        "gyro_y": "imu/gyr_y",
        "gyro_z": "imu/gyr_z",
    }
    np.savez(tmp_path / "data.npz", data=np.zeros((10, 6)))
    with pytest.raises(InputError, match=r"data.npz: no array looks like the gyro .*its arrays are data \(10, 6\)"):
        guess_layout(tmp_path / "data.npz")


def test_phone_app_exports_phyphox_quoted_names_and_sensor_loggers_bare_axes(tmp_path):
    """phyphox writes quoted names with spaces and units ("Gyroscope x (rad/s)"): a header, not a headerless log.
    Sensor Logger writes one file per sensor, its axes named x, y, z alone and its time in ns: in a file named for
    the gyroscope, they are the gyro's."""
    rng = np.random.default_rng(5)
    n = 500
    t, gyro = np.arange(n) / 100.0, 0.01 + 0.001 * rng.standard_normal((n, 3))
    header = '"Time (s)","Gyroscope x (rad/s)","Gyroscope y (rad/s)","Gyroscope z (rad/s)","Absolute (rad/s)"\n'
    rows = [",".join(f"{v:.9E}" for v in (t[k], *gyro[k], np.linalg.norm(gyro[k]))) for k in range(n)]
    (tmp_path / "Gyroscope.csv").write_text(header + "\n".join(rows) + "\n")
    phyphox = guess_layout(tmp_path / "Gyroscope.csv")
    assert phyphox.layout.columns["gyro_x"] == "Gyroscope x (rad/s)" and phyphox.layout.gyro_unit == "rad/s"
    assert phyphox.layout.columns["time"] == "Time (s)" and phyphox.unused == ("Absolute (rad/s)",)
    rows = [
        ",".join([str(1_700_000_000_000_000_000 + 10_000_000 * k), f"{t[k]:.3f}", *map(str, gyro[k][::-1])])
        for k in range(n)
    ]
    (tmp_path / "Gyroscope_logger.csv").write_text("time,seconds_elapsed,z,y,x\n" + "\n".join(rows) + "\n")
    logger = guess_layout(tmp_path / "Gyroscope_logger.csv")
    assert {c: logger.layout.columns[c] for c in ("gyro_x", "gyro_y", "gyro_z")} == {
        "gyro_x": "x",
        "gyro_y": "y",
        "gyro_z": "z",
    }
    assert logger.layout.columns["time"] == "time" and logger.layout.time_unit == "ns"
    (tmp_path / "Accelerometer.csv").write_text("time,seconds_elapsed,z,y,x\n" + "\n".join(rows) + "\n")
    with pytest.raises(
        InputError,
        match=r"Accelerometer.csv: no column looks like a gyro axis.*; it holds the accelerometer without the gyro "
        r"\(a logger's file per sensor\): gyrocomp reads a log's channels from one file",
    ):
        guess_layout(tmp_path / "Accelerometer.csv")
    np.savez(tmp_path / "sensors.npz", accelBuffer=np.zeros((10, 4)), temperatureBuffer=np.zeros((10, 2)))
    with pytest.raises(
        InputError, match=r"sensors.npz: no array .*; it holds the accelerometer and the temperature without"
    ):
        guess_layout(tmp_path / "sensors.npz")


def test_a_command_that_cannot_find_the_columns_points_to_init(tmp_path):
    """Without a mapping, fit on a table whose time and gyro have other names says what it lacks and that init
    guesses the layout; after init, the same command runs."""
    path = _log(tmp_path / "vendor.tsv", n=400)
    refused = run("fit", "vendor.tsv", "-o", "m.json", "--hysteresis", "none", cwd=tmp_path)
    assert refused.returncode == 2 and refused.stderr.count("\n") == 1
    assert "no 'time' column" in refused.stderr
    assert "or let `gyrocomp init vendor.tsv` guess them from the names into a project file" in refused.stderr
    assert run("init", path, cwd=tmp_path).returncode == 0
    fitted = run("fit", "vendor.tsv", "-o", "m.json", "--hysteresis", "none", cwd=tmp_path)
    assert fitted.returncode == 0, fitted.stderr


def test_a_spreadsheet_export_of_a_decimal_comma_locale_in_windows_1252_is_guessed_and_read(tmp_path):
    """A spreadsheet's CSV in a decimal-comma locale (semicolons between fields, commas in the numbers) with names
    holding a degree sign in Windows-1252 (one byte, 0xB0): init takes its first line as the header (a row of
    decimal commas split at every comma looked like ten numbers, and the file like a log without a header), the
    names are read as meant, every command reads it as the same table in UTF-8, and apply writes UTF-8."""
    rng = np.random.default_rng(8)
    n, rate_hz = 3000, 100.0
    gyro = 0.1 + 0.003 * rng.standard_normal((n, 3))
    names = ["time [s]", "gyro x [°/s]", "gyro y [°/s]", "gyro z [°/s]", "temperature [°C]"]
    rows = [
        ";".join(f"{v:.6f}".replace(".", ",") for v in (k / rate_hz, *gyro[k], 20.0 + 10.0 * k / n)) for k in range(n)
    ]
    text = ";".join(names) + "\r\n" + "\r\n".join(rows) + "\r\n"
    (tmp_path / "cp1252.csv").write_bytes(text.encode("cp1252"))
    (tmp_path / "utf8").mkdir()
    (tmp_path / "utf8" / "cp1252.csv").write_bytes(text.encode("utf-8"))
    guessed = guess_layout(tmp_path / "cp1252.csv")
    assert (
        guessed.layout.columns["gyro_z"] == "gyro z [°/s]"
        and guessed.layout.columns["temperature"] == "temperature [°C]"
    )
    for folder in (tmp_path, tmp_path / "utf8"):
        _init_then_allan_reads(folder, "cp1252.csv", "gyro_y", np.round(gyro[:, 1], 6), rate_hz)
    fitted = run("fit", "cp1252.csv", "-o", "m.json", "--temperature", "poly:1", cwd=tmp_path)
    assert fitted.returncode == 0, fitted.stderr
    for folder in (tmp_path, tmp_path / "utf8"):
        applied = run("apply", tmp_path / "m.json", "cp1252.csv", "-o", "out.csv", cwd=folder)
        assert applied.returncode == 0, applied.stderr
    out = (tmp_path / "out.csv").read_bytes()  # a .csv of semicolons stays one (the locale's convention)
    assert (
        out.decode("utf-8").startswith("time [s];gyro x [°/s]") and out == (tmp_path / "utf8" / "out.csv").read_bytes()
    )
    assert run("check", "out.csv", cwd=tmp_path).returncode == 0  # the project file reads its output back


def test_a_log_timed_by_dates_and_times_is_guessed_in_seconds_and_compensated_by_its_project(tmp_path):
    """A logger's time column of dates and times (2024-05-01 12:00:00.010): init says it is read as seconds (not
    ns, as the numbers Arrow keeps would suggest), and with the project file every command reads it: allan's curve
    is that of the samples at 100 Hz, apply writes the rows back with their time as it was read."""
    rng = np.random.default_rng(9)
    n, rate_hz = 2000, 100.0
    gyro = 0.05 + 0.002 * rng.standard_normal((n, 3))
    stamps = pd.Timestamp("2024-05-01 12:00:00") + pd.to_timedelta(np.arange(n) * 10, unit="ms")
    frame = pd.DataFrame({"timestamp": stamps, "gyr_x": gyro[:, 0], "gyr_y": gyro[:, 1], "gyr_z": gyro[:, 2]})
    frame.to_csv(tmp_path / "log.csv", index=False)
    guessed = guess_layout(tmp_path / "log.csv")
    assert guessed.layout.time_unit == "s" and guessed.layout.columns["time"] == "timestamp"
    assert "time unit s: the column holds dates and times, read as seconds" in guessed.reasons
    _init_then_allan_reads(tmp_path, "log.csv", "gyro_z", gyro[:, 2], rate_hz)
    model = tmp_path / "m.json"
    assert run("fit", "log.csv", "-o", model, "--temperature", "none", cwd=tmp_path).returncode == 0
    applied = run("apply", model, "log.csv", "-o", "out.csv", cwd=tmp_path)
    assert applied.returncode == 0, applied.stderr
    out = pd.read_csv(tmp_path / "out.csv", parse_dates=["timestamp"])
    assert (out["timestamp"] == stamps).all() and len(out) == n


def test_init_reads_a_line_of_units_under_the_header_and_refuses_a_chosen_column_of_text(tmp_path):
    """Data acquisition tools write a line of units under the header: init reads the units from it (ms, rad/s,
    m/s^2 here) and every command skips it, counting lines past it; a chosen column that holds text (not a line of
    units: the same in every row) is one line naming it and its first value (it was an internal error), exit 2."""
    rng = np.random.default_rng(15)
    n = 2000
    gyro_rad_s = np.radians(0.2 + 0.01 * rng.standard_normal((n, 3)))
    rows = "".join(
        f"{10 * k},{g[0]!r},{g[1]!r},{g[2]!r},0.01,-0.02,9.81,25.0\n" for k, g in enumerate(gyro_rad_s.tolist())
    )
    header = "time,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z,temperature\n"
    (tmp_path / "daq.csv").write_text(header + "ms,rad/s,rad/s,rad/s,m/s^2,m/s^2,m/s^2,degC\n" + rows)
    guess = guess_layout(tmp_path / "daq.csv")
    assert (guess.layout.time_unit, guess.layout.gyro_unit, guess.layout.accel_unit) == ("ms", "rad/s", "m/s2")
    assert any(r.startswith("a line of units under the header (ms, rad/s") for r in guess.reasons), guess.reasons
    _init_then_allan_reads(tmp_path, "daq.csv", "gyro_y", np.degrees(gyro_rad_s[:, 1]), 100.0)
    (tmp_path / "text.csv").write_text("t,gyro_z\n" + "".join(f"{k},off\n" for k in range(50)))
    result = run("init", "text.csv", "-o", "text.toml", cwd=tmp_path)
    assert result.returncode == 2 and not (tmp_path / "text.toml").exists()
    assert result.stderr.strip().splitlines() == [
        "gyrocomp: error: text.csv: column 'gyro_z' (gyro_z) holds text, not numbers (its first value 'off'): a line "
        "of units under the header, or a column of another kind? Remove the line, or map the channel to another column"
    ]


def test_a_table_of_aligned_columns_goes_through_init_fit_and_apply(tmp_path):
    """A text table whose columns are aligned by runs of spaces (Fortran's, MATLAB's save -ascii with a header
    line added, many instruments'): the commands tell its separator (init need not write it), `--delimiter space` names
    it, and apply writes the rows back separated by spaces, its values those of the same rows as a CSV."""
    rng = np.random.default_rng(12)
    n = 1500
    temperature = np.linspace(20.0, 40.0, n)
    gyro = 0.2 + 0.01 * (temperature - 30.0)[:, None] + 0.002 * rng.standard_normal((n, 3))
    rows = np.column_stack([np.arange(n) / 10.0, gyro, temperature]).tolist()
    names = ["time", "gyro_x", "gyro_y", "gyro_z", "temperature"]
    (tmp_path / "run.dat").write_text(
        "".join(f"{name:>24}" for name in names) + "\n" + "".join("".join(f"{v!r:>24}" for v in r) + "\n" for r in rows)
    )
    (tmp_path / "csv").mkdir()
    (tmp_path / "csv" / "run.csv").write_text(
        ",".join(names) + "\n" + "".join(",".join(map(repr, r)) + "\n" for r in rows)
    )
    assert run("init", "run.dat", cwd=tmp_path).returncode == 0
    assert "delimiter" not in (tmp_path / "gyrocomp.toml").read_text()  # the reader tells the spaces itself
    fitted = run("fit", "run.dat", "-o", "m.json", "--temperature", "poly:1", cwd=tmp_path)
    assert fitted.returncode == 0, fitted.stderr
    applied = run("apply", "m.json", "run.dat", "-o", "out.dat", cwd=tmp_path)
    assert applied.returncode == 0, applied.stderr
    again = run("apply", tmp_path / "m.json", "run.csv", "-o", "out.csv", cwd=tmp_path / "csv")
    assert again.returncode == 0, again.stderr
    spaced = (tmp_path / "out.dat").read_text()
    assert spaced.startswith("time gyro_x gyro_y gyro_z temperature\n")
    assert spaced.replace(" ", ",") == (tmp_path / "csv" / "out.csv").read_text()
    named = run("check", tmp_path / "run.dat", "--delimiter", "space", cwd=tmp_path / "csv")  # no project file there
    assert named.returncode == 0, named.stderr


def test_init_reads_a_text_matrix_named_mat_with_the_format_given_and_the_project_keeps_it(tmp_path):
    """imu_tk's logs are text matrices named .mat: init refuses them with the way (the format and the names, in
    the command line's words), takes them with --format csv --names, and writes the format into the project file,
    so that every command then reads the file as that table."""
    rng = np.random.default_rng(13)
    n, rate_hz = 3000, 100.0
    gyro = 0.1 + 0.002 * rng.standard_normal((n, 3))
    (tmp_path / "gyro.mat").write_text(
        "".join(f"{k / rate_hz:.4f}   " + "   ".join(f"{v:.8f}" for v in gyro[k]) + "\n" for k in range(n))
    )
    refused = run("init", "gyro.mat", cwd=tmp_path)
    assert refused.returncode == 2 and not (tmp_path / "gyrocomp.toml").exists()
    assert (
        "not a binary MAT-file: read it as a table without a header line, --format csv with the columns' names in order (--names time,gyro_x,gyro_y,gyro_z)"
        in refused.stderr
    )
    made = run("init", "gyro.mat", "--format", "csv", "--names", "time,gyro_x,gyro_y,gyro_z", cwd=tmp_path)
    assert made.returncode == 0, made.stderr
    assert 'format = "csv"' in (tmp_path / "gyrocomp.toml").read_text()
    allan = run("allan", "gyro.mat", "--json", cwd=tmp_path)
    assert allan.returncode == 0, allan.stderr
    expected = allan_deviation(np.round(gyro[:, 0], 8), rate_hz).deviation
    np.testing.assert_allclose(json.loads(allan.stdout)["axes"]["gyro_x"]["adev"], expected, rtol=1e-9)


def test_an_array_of_two_triads_gives_its_first_and_an_index_for_a_time_is_pointed_out(tmp_path):
    """Android keeps the calibrated and the uncalibrated gyro side by side ((n, 6), as scikit-diveMove's Galaxy S5
    recording does): init maps the first triad by its columns and says so; an HDF5 reader then reads those columns
    even though the whole array's name is one it would take for the gyro. A time of 0, 1, 2, ... is pointed out as
    a sample index as often; with its period as the unit the curve is the samples' at 10 Hz."""
    rng = np.random.default_rng(14)
    n = 3000
    calibrated, raw = 0.001 * rng.standard_normal((n, 3)), 0.02 + 0.001 * rng.standard_normal((n, 3))
    with h5py.File(tmp_path / "phone.nc", "w") as f:
        f["timestamp"] = np.arange(n, dtype=float)
        f["angular_velocity"] = np.hstack([calibrated, raw])
        f["acceleration"] = np.array([0.0, 0.2, 9.8]) + 0.01 * rng.standard_normal((n, 3))
    guess = guess_layout(tmp_path / "phone.nc")
    assert {c: guess.layout.columns[c] for c in ("gyro_x", "gyro_y", "gyro_z")} == {
        f"gyro_{a}": f"angular_velocity[:, {k}]" for k, a in enumerate("xyz")
    }
    assert any("an (n, 6) array of 2 triads, the first taken" in r for r in guess.reasons), guess.reasons
    assert any("whole numbers counting by one are a sample index as often" in r for r in guess.reasons)
    assert run("init", "phone.nc", cwd=tmp_path).returncode == 0
    project = tmp_path / "gyrocomp.toml"
    project.write_text(project.read_text().replace('time-unit = "s"', 'time-unit = "100 ms"'))
    allan = run("allan", "phone.nc", "--json", cwd=tmp_path)
    assert allan.returncode == 0, allan.stderr
    assert json.loads(allan.stdout)["rate_hz"] == pytest.approx(10.0)
    expected = allan_deviation(np.degrees(calibrated[:, 2]), 10.0).deviation
    np.testing.assert_allclose(json.loads(allan.stdout)["axes"]["gyro_z"]["adev"], expected, rtol=1e-9)


def test_a_sample_index_for_a_time_is_timed_by_the_rate_the_file_states(tmp_path):
    """scikit-diveMove's NetCDF states each array's rate (``sampling_rate = 10``, ``sampling_rate_units = "Hz"``)
    beside a time of 0, 1, 2, ...: init reads that index in periods of the stated rate; a rate attribute in
    another unit is not taken."""
    rng = np.random.default_rng(15)
    n = 3000
    gyro = 0.001 * rng.standard_normal((n, 3))
    for units, expected in (("Hz", "1/10 s"), ("kHz", "s")):
        path = tmp_path / f"stated_{units}.nc"
        with h5py.File(path, "w") as f:
            f["timestamp"] = np.arange(n, dtype=float)
            f["angular_velocity"] = gyro
            f["angular_velocity"].attrs["sampling_rate"] = np.array([10])
            f["angular_velocity"].attrs["sampling_rate_units"] = np.bytes_(units)
        guess = guess_layout(path)
        assert guess.layout.time_unit == expected, guess.reasons
    assert any(
        r.startswith(
            "time unit 1/10 s: the time steps by one (a sample index as often as seconds) and the file's "
            "angular_velocity@sampling_rate says 10 Hz"
        )
        for r in guess_layout(tmp_path / "stated_Hz.nc").reasons
    )
    assert run("init", "stated_Hz.nc", cwd=tmp_path).returncode == 0
    allan = run("allan", "stated_Hz.nc", "--json", cwd=tmp_path)
    assert allan.returncode == 0, allan.stderr
    assert json.loads(allan.stdout)["rate_hz"] == pytest.approx(10.0)


def test_pandas_index_column_is_left_unused_and_said_so(tmp_path):
    """pandas' to_csv writes its index as a first column with an empty name: init leaves it unused and says so
    visibly, and apply writes it back as it was."""
    n = 300
    frame = pd.DataFrame(
        {
            "time": np.arange(n) / 100.0,
            "gyro_z": 0.1 + 0.01 * np.sin(np.arange(n) / 7.0),
            "temperature": np.linspace(20, 30, n),
        }
    )
    frame.to_csv(tmp_path / "df.csv")
    made = run("init", "df.csv", cwd=tmp_path)
    assert made.returncode == 0, made.stderr
    assert "  columns not used: '' (unnamed)" in made.stdout.splitlines()
    assert run("fit", "df.csv", "-o", "m.json", "--temperature", "poly:1", cwd=tmp_path).returncode == 0
    applied = run("apply", "m.json", "df.csv", "-o", "out.csv", cwd=tmp_path)
    assert applied.returncode == 0, applied.stderr
    assert (tmp_path / "out.csv").read_text().splitlines()[:2][0] == ",time,gyro_z,temperature"
    assert pd.read_csv(tmp_path / "out.csv", index_col=0).index.tolist() == list(range(n))


def test_init_on_a_log_without_a_temperature_points_to_noise_not_fit(tmp_path):
    (tmp_path / "still.csv").write_text("time,gyro_z\n" + "".join(f"{k / 10},{0.01 * (k % 7)}\n" for k in range(100)))
    result = run("init", "still.csv", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "gyrocomp fit" not in result.stdout and "gyrocomp noise still.csv" in result.stdout


def test_init_states_the_units_an_arrays_units_attribute_gives(tmp_path):
    """Issue #72, item 5: a NetCDF-like HDF5 file whose gyro array says ``mrad/s`` in its units attribute (as the
    CATS recording's does): init says mrad/s, from the attribute, and writes it; it said rad/s (guessed from the
    accelerometer's m/s2) while the reader used the attribute."""
    n = 600
    rng = np.random.default_rng(2)
    with h5py.File(tmp_path / "tag.nc", "w") as f:
        f["timestamp_utc"] = np.arange(n, dtype=float)
        f["timestamp_utc"].attrs["units"] = np.bytes_(b"seconds since 2021-09-20 08:52:00")
        f["angular_velocity"] = 3.0 + 0.1 * rng.standard_normal((n, 3))
        f["angular_velocity"].attrs["units"] = np.bytes_(b"mrad/s")
        f["acceleration"] = np.array([0.0, 0.0, 9.81]) + 0.01 * rng.standard_normal((n, 3))
        f["acceleration"].attrs["units"] = np.bytes_(b"m/s2")
        f["temperature"] = np.linspace(20.0, 30.0, n)
        f["temperature"].attrs["units"] = np.bytes_(b"C")
    done = run("init", "tag.nc", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "gyro in mrad/s: its array's units attribute says so" in done.stdout
    assert "gyro in rad/s" not in done.stdout
    assert 'gyro-unit = "mrad/s"' in (tmp_path / "gyrocomp.toml").read_text()


def test_runs_over_less_than_a_degree_get_their_constants_and_the_fit_says_why(tmp_path):
    """Issue #72, item 7: a hold whose temperature wanders 0.9 degC while the bias walks: the default fit said
    nothing of the span and fitted poly + branch terms to the drift, while `check` promised that the automatic
    choice fits a constant. Now both say the span, and the fit keeps the constants."""
    rng = np.random.default_rng(0)
    n = 18000
    t = np.arange(n) / 10.0
    walk = np.cumsum(rng.normal(0.0, 1.0, (n, 3)), axis=0) * 2e-4
    gyro = 0.01 + walk + rng.normal(0.0, 0.005 * np.sqrt(10.0), (n, 3))
    table = {"time": t, **{f"gyro_{a}": gyro[:, k] for k, a in enumerate("xyz")}}
    pd.DataFrame({**table, "temperature": 25.0 + 0.46 * np.sin(t / 300.0)}).to_csv(tmp_path / "hold.csv", index=False)
    checked = run("check", "hold.csv", cwd=tmp_path)
    assert "span 0.92 degC, less than 1 degC" in checked.stdout + checked.stderr
    assert "the automatic choice fits a constant bias" in checked.stdout + checked.stderr
    done = run("fit", "hold.csv", "-o", "m.json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "the runs span 0.92 degC, less than 1 degC" in done.stderr
    assert "fits each run's constant alone" in done.stderr
    model = json.loads((tmp_path / "m.json").read_text())
    assert all(ax["temperature"] is None and ax["hysteresis"] is None for ax in model["axes"].values())
    asked = run("fit", "hold.csv", "--temperature", "poly:2", "-o", "asked.json", cwd=tmp_path)
    assert asked.returncode == 2 and "accept" in asked.stderr and "temperature-span" in asked.stderr


def test_apply_to_a_csv_name_writes_commas_after_init_on_a_tab_separated_log(tmp_path):
    """Issue #72, item 8: init on a tab-separated .txt log pinned ``delimiter = "tab"`` in the project file, and
    ``apply -o out.csv`` then wrote tabs into out.csv. The reader tells the tabs itself, so init writes no separator,
    and a .csv output is written with commas (a separator given by hand still carries to the output)."""
    n = 3000
    t = np.arange(n) / 10.0
    temperature = 20.0 + 30.0 * np.sin(t / 100.0)
    rng = np.random.default_rng(3)
    frame = pd.DataFrame(
        {
            "Time (s)": t,
            **{f"Gyro {a.upper()} (dps)": 0.01 * temperature + 0.01 * rng.standard_normal(n) for a in "xyz"},
            "Temp (C)": temperature,
        }
    )
    frame.to_csv(tmp_path / "log.txt", sep="\t", index=False)
    assert run("init", "log.txt", cwd=tmp_path).returncode == 0
    assert "delimiter" not in (tmp_path / "gyrocomp.toml").read_text()
    assert run("fit", "log.txt", "-o", "m.json", cwd=tmp_path).returncode == 0
    done = run("apply", "m.json", "log.txt", "-o", "out.csv", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out.csv").read_text().splitlines()[0].startswith("Time (s),Gyro X (dps),")
    again = run("apply", "m.json", "out.csv", "-o", "twice.tsv", cwd=tmp_path)  # the project reads its own output
    assert again.returncode == 0, again.stderr
    given = run("apply", "m.json", "log.txt", "-o", "given.csv", "--delimiter", "tab", cwd=tmp_path)
    assert given.returncode == 0, given.stderr
    assert "\t" in (tmp_path / "given.csv").read_text().splitlines()[0]


def test_split_then_fit_after_init_on_a_log_in_its_own_layout(tmp_path):
    """Issue #72, item 4: after init on a NetCDF log (its arrays and units in gyrocomp.toml), split writes gyrocomp's
    own tables, and fit on them failed on the project file's mapping ('accel=acceleration: a table has one column
    per axis'). A table the project file does not describe but gyrocomp's names do is read in gyrocomp's layout,
    said in a note; one of the project's columns is read with them; one that neither describes gets the error."""
    n = 4000
    rng = np.random.default_rng(5)
    temperature = np.concatenate([np.linspace(10.0, 30.0, n // 2), np.linspace(30.0, 10.0, n - n // 2)])
    with h5py.File(tmp_path / "tag.nc", "w") as f:
        f["timestamp_utc"] = np.arange(n, dtype=float)
        f["timestamp_utc"].attrs["units"] = np.bytes_(b"seconds since 2021-09-20 08:52:00")
        gyro = 2.0 + 0.05 * (temperature - 20.0)[:, None] + 0.1 * rng.standard_normal((n, 3))
        f["angular_velocity"] = gyro  # mrad/s
        f["angular_velocity"].attrs["units"] = np.bytes_(b"mrad/s")
        f["acceleration"] = np.array([0.0, 0.0, 9.81]) + 0.01 * rng.standard_normal((n, 3))
        f["acceleration"].attrs["units"] = np.bytes_(b"m/s2")
        f["temperature"] = temperature
        f["temperature"].attrs["units"] = np.bytes_(b"C")
    assert run("init", "tag.nc", cwd=tmp_path).returncode == 0
    split = run("split", "tag.nc", "--by", "temperature-turn", "-o", "parts", cwd=tmp_path)
    assert split.returncode == 0, split.stderr
    parts = sorted(p.name for p in (tmp_path / "parts").iterdir())
    done = run("fit", *[f"parts/{p}" for p in parts], "-o", "m.json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert f"parts/{parts[0]}: read in gyrocomp's own layout" in done.stderr
    model = json.loads((tmp_path / "m.json").read_text())
    assert model["units"]["gyro"] == "deg/s"
    # the log itself is still read through the project file, without a note
    again = run("check", "tag.nc", cwd=tmp_path)
    assert again.returncode == 0 and "gyrocomp's own layout" not in again.stderr
    # a table neither the project's mapping nor gyrocomp's names describe: the project's error stands
    pd.DataFrame({"a": [1.0, 2.0], "b": [3.0, 4.0]}).to_csv(tmp_path / "other.csv", index=False)
    refused = run("check", "other.csv", cwd=tmp_path)
    assert refused.returncode == 1 and "refused" in refused.stdout and "own layout" not in refused.stderr
