"""Logs from a serial terminal: no header line, a banner, garbled lines, no time column. Read with the columns'
names in order and a nominal rate; the result must equal the same samples written as an ordinary table with a
time column, in the library, in chunks, and through init, fit and apply on the real entry point."""

import gzip
import json
import os
import pty
import select
import signal

import numpy as np
import pytest

from gyrocomp.errors import DataQualityWarning, InputError
from gyrocomp.io import ReadOptions, read_input
from gyrocomp.io.serial import read_headerless
from gyrocomp.io.stream import TableStream
from gyrocomp.io.tables import TableLayout, read_table

from ..conftest import SCRIPT, run

NAMES = ("gyro_x", "gyro_y", "gyro_z", "temperature")
RATE_HZ = 50.0


def _samples(n=3000, seed=0):
    """(n, 4) samples: three gyro axes [deg/s] whose bias follows the temperature [degC], rising then falling."""
    rng = np.random.default_rng(seed)
    k = np.arange(n)
    temperature = 25.0 + 15.0 * np.sin(np.pi * k / n)
    bias = np.column_stack(
        [0.1 + 0.01 * (temperature - 25), -0.2 + 0.02 * (temperature - 25), 0.05 - 0.015 * (temperature - 25)]
    )
    return np.column_stack([np.round(bias + 0.01 * rng.standard_normal((n, 3)), 5), np.round(temperature, 3)])


def _serial_log(path, samples, *, garbled=(), sep=","):
    """The samples as a serial terminal logs them: a banner, then one line per sample, CRLF; the lines before the
    samples with indices in ``garbled`` are cut short and hold a stray byte (the sample after stays)."""
    lines = [b"MPU6050 ready, 50 Hz"]
    for i, row in enumerate(samples):
        if i in garbled:
            lines.append(b"0.01" + sep.encode() + b"0.0\xff2")
        lines.append(sep.join(f"{v:.6g}" for v in row).encode())
    data = b"\r\n".join(lines) + b"\r\n"
    path.write_bytes(gzip.compress(data) if path.suffix == ".gz" else data)
    return path


def _timed_table(path, samples, garbled=()):
    """The same samples as an ordinary CSV with a header and the time each line of the serial log was at."""
    slots = np.arange(len(samples)) + np.searchsorted(sorted(garbled), np.arange(len(samples)), side="right")
    time_s = slots / RATE_HZ
    header = "time," + ",".join(NAMES)
    path.write_text(
        header
        + "\n"
        + "\n".join(f"{float(t)!r}," + ",".join(f"{v:.6g}" for v in row) for t, row in zip(time_s, samples))
        + "\n"
    )
    return path


@pytest.mark.parametrize("suffix", [".txt", ".txt.gz"])
@pytest.mark.parametrize("sep", [",", " ", "\t", ";"])
def test_banner_and_garbled_lines_are_skipped_and_counted_and_keep_their_place_in_time(tmp_path, suffix, sep):
    samples = _samples(200)
    garbled = (50, 120)
    log = _serial_log(tmp_path / f"serial{suffix}", samples, garbled=garbled, sep=sep)
    with pytest.warns(DataQualityWarning, match=r"skipped 3 line\(s\) that are not 4 numbers .* line 1 'MPU6050"):
        table = read_headerless(log, NAMES, RATE_HZ)
    assert table.column_names == ["time", *NAMES]
    np.testing.assert_array_equal(np.column_stack([table[n].to_numpy() for n in NAMES]), samples)
    time_s = table["time"].to_numpy()
    # the garbled line before sample 50 took a period: sample 50 is at 51 / rate, sample 120 at 122 / rate
    assert time_s[49] == 49 / RATE_HZ and time_s[50] == 51 / RATE_HZ and time_s[120] == 122 / RATE_HZ


def test_the_recording_equals_the_same_samples_with_a_time_column(tmp_path):
    samples = _samples(500)
    garbled = (100,)
    serial = _serial_log(tmp_path / "serial.txt", samples, garbled=garbled)
    timed = _timed_table(tmp_path / "timed.csv", samples, garbled)
    with pytest.warns(DataQualityWarning, match="skipped 2 line"):
        got = read_input(serial, options=ReadOptions(layout=TableLayout(names=NAMES, rate_hz=RATE_HZ))).recording
    want = read_input(timed).recording
    np.testing.assert_array_equal(got.time_s, want.time_s)
    np.testing.assert_array_equal(got.gyro_dps, want.gyro_dps)
    np.testing.assert_array_equal(got.temperature_degc, want.temperature_degc)


@pytest.mark.parametrize("chunk_rows", [2, 7, 64, 10_000])
def test_read_in_chunks_equals_the_whole(tmp_path, chunk_rows):
    serial = _serial_log(tmp_path / "serial.txt", _samples(300), garbled=(10, 11))
    layout = TableLayout(names=NAMES, rate_hz=RATE_HZ)
    with pytest.warns(DataQualityWarning):
        whole = read_table(serial, layout).recording
    with pytest.warns(DataQualityWarning):
        chunks = list(TableStream(serial, layout, chunk_rows=chunk_rows).chunks())
    np.testing.assert_array_equal(np.concatenate([c.recording.time_s for c in chunks]), whole.time_s)
    np.testing.assert_array_equal(np.concatenate([c.recording.gyro_dps for c in chunks]), whole.gyro_dps)


def test_a_table_with_a_header_and_no_time_takes_a_nominal_rate(tmp_path):
    samples = _samples(100)
    path = tmp_path / "notime.csv"
    path.write_text(",".join(NAMES) + "\n" + "\n".join(",".join(f"{v:.6g}" for v in row) for row in samples) + "\n")
    with pytest.raises(InputError, match=r"notime.csv: no 'time' column .* sample rate \(rate_hz=50\)"):
        read_table(path)
    recording = read_table(path, TableLayout(rate_hz=RATE_HZ)).recording
    np.testing.assert_array_equal(recording.time_s, np.arange(100) / RATE_HZ)
    np.testing.assert_array_equal(recording.gyro_dps, samples[:, :3])
    chunks = list(TableStream(path, TableLayout(rate_hz=RATE_HZ), chunk_rows=9).chunks())
    np.testing.assert_array_equal(np.concatenate([c.recording.time_s for c in chunks]), np.arange(100) / RATE_HZ)


def test_what_cannot_be_read_so_is_refused_naming_it(tmp_path):
    serial = _serial_log(tmp_path / "serial.txt", _samples(50))
    with pytest.raises(
        InputError,
        match=r"serial.txt: not a readable CSV table \(CSV parse error: Expected 2 "
        r"columns, got 4.*\); if it has no header line .* names=gyro_x",
    ):
        read_table(serial)  # the banner taken for a header of one column
    bare = tmp_path / "bare.txt"
    bare.write_bytes(serial.read_bytes().split(b"\r\n", 1)[1])
    with pytest.raises(
        InputError,
        match=r"bare.txt: the first line is numbers \(.*\), not the columns' names: a "
        r"table without a header line; give the names in order",
    ):
        read_table(bare)
    with pytest.raises(
        InputError,
        match=r"serial.txt: no line holds 3 numbers, one per name given \(a, b, c\); its "
        r"first line: 'MPU6050 ready, 50 Hz'",
    ):
        read_table(serial, TableLayout(names=("a", "b", "c")))
    with pytest.raises(InputError, match="names: 'gyro_x' given twice"):
        TableLayout(names=("gyro_x", "gyro_x"))
    with pytest.raises(InputError, match="names: 'gyro_x,,t': an empty name"):
        TableLayout(names="gyro_x,,t")
    with pytest.raises(InputError, match="rate_hz: must be a positive number of Hz up to 1e6, got 0"):
        TableLayout(rate_hz=0)
    with pytest.raises(InputError, match="rate_hz: the names include time"):
        TableLayout(names=("time", "gyro_z"), rate_hz=50)
    timed = _timed_table(tmp_path / "timed.csv", _samples(50))
    with pytest.raises(InputError, match=r"timed.csv: rate_hz=50: the file has a time column \('time'\)"):
        read_table(timed, TableLayout(rate_hz=50))
    parquet = tmp_path / "t.parquet"
    read_table(timed).table.to_pandas().to_parquet(parquet)
    with pytest.raises(InputError, match="t.parquet: names: for a text table without a header line"):
        read_table(parquet, TableLayout(names=NAMES))


def test_an_over_long_line_is_skipped_unread(tmp_path):
    path = _serial_log(tmp_path / "serial.txt", _samples(20))
    path.write_bytes(path.read_bytes() + b"1," * 100_000 + b"\r\n" + b"0.1,0.2,0.3,25\r\n")
    with pytest.warns(DataQualityWarning, match=r"skipped 2 line\(s\)"):
        table = read_headerless(path, NAMES, RATE_HZ)
    assert table.num_rows == 21 and table["time"].to_numpy()[-1] == 21 / RATE_HZ


@pytest.mark.slow
def test_init_fit_apply_with_the_names_given_once(tmp_path):
    """The issue's case: a 50 Hz serial log with a banner goes through init (names and rate given once), fit and
    apply with no reading option; the model and the output equal those of the same samples with a time column."""
    samples = _samples(6000)
    garbled = (2000, 4500)
    _serial_log(tmp_path / "serial.txt", samples, garbled=garbled)
    _timed_table(tmp_path / "timed.csv", samples, garbled)
    r = run("init", "serial.txt", cwd=tmp_path)
    assert r.returncode == 2 and r.stderr.count("\n") == 1
    assert "serial.txt: a table without a header line, rows of 4 numbers" in r.stderr and "--names" in r.stderr
    r = run("init", "serial.txt", "--names", ",".join(NAMES), "--rate", "50", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "time: row n at n / 50 s" in r.stdout and "gyro_x = 'gyro_x'" in r.stdout
    r = run("fit", "serial.txt", "-o", "m.json", "--temperature", "poly:2", "--hysteresis", "none", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "gyrocomp.toml sets" in r.stderr and "--names" in r.stderr and "--rate" in r.stderr
    assert "serial.txt: skipped 3 line(s) that are not 4 numbers" in r.stderr
    r = run("apply", "m.json", "serial.txt", "-o", "out.csv", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    (tmp_path / "gyrocomp.toml").unlink()
    for args in (
        ("fit", "timed.csv", "-o", "m_timed.json", "--temperature", "poly:2", "--hysteresis", "none"),
        ("apply", "m_timed.json", "timed.csv", "-o", "out_timed.csv"),
    ):
        r = run(*args, cwd=tmp_path)
        assert r.returncode == 0, r.stderr
    model, timed_model = (json.loads((tmp_path / name).read_text()) for name in ("m.json", "m_timed.json"))
    assert model["axes"] == timed_model["axes"]
    assert (tmp_path / "out.csv").read_text() == (tmp_path / "out_timed.csv").read_text()


def _in_a_terminal(args, answers, cwd) -> tuple[int, str]:
    """Run the command on a pseudo-terminal, typing each answer after the text that asks for it; its status and
    everything it showed."""
    pid, fd = pty.fork()
    if pid == 0:  # the child: the command, with the terminal as its stdin and stdout
        os.chdir(cwd)
        os.execv(str(SCRIPT), [str(SCRIPT), *map(str, args)])
    shown = b""
    pending = list(answers)
    while True:
        ready, _, _ = select.select([fd], [], [], 30)
        if not ready:  # waiting for something not typed: stop it rather than hang
            os.kill(pid, signal.SIGKILL)
            break
        try:
            data = os.read(fd, 4096)
        except OSError:  # the command ended and closed the terminal
            break
        if not data:
            break
        shown += data
        if pending and shown.rstrip().endswith(b":"):
            os.write(fd, pending.pop(0).encode() + b"\n")
    _, status = os.waitpid(pid, 0)
    return os.waitstatus_to_exitcode(status), shown.decode("utf-8", "replace")


def test_init_asks_for_the_names_and_the_rate_in_a_terminal(tmp_path):
    _serial_log(tmp_path / "serial.txt", _samples(200))
    status, shown = _in_a_terminal(["init", "serial.txt"], [",".join(NAMES), "50"], tmp_path)
    assert status == 0, shown
    assert "serial.txt has no header line; its rows hold 4 numbers" in shown
    assert "no time column: the rows' sample rate [Hz]:" in shown
    project = (tmp_path / "gyrocomp.toml").read_text()
    assert 'names = "gyro_x,gyro_y,gyro_z,temperature"' in project and "rate = 50.0" in project
