"""``gyrocomp convert`` through the real entry point: any table to the canonical one, rows selected by time."""

from __future__ import annotations

import os
import pty
import subprocess
import sys
import warnings

import pytest

from gyrocomp import read
from gyrocomp.files.chunks import ChunkSettings
from gyrocomp.files.convert import convert_file
from gyrocomp.io.tables import write_recording
from gyrocomp.simulation import simulate

from ..conftest import SCRIPT, run


@pytest.mark.slow
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


@pytest.mark.parametrize("suffix", [".tsv", ".dat", ".txt"])
def test_every_suffix_of_a_delimited_table_is_read(tmp_path, suffix):
    path = tmp_path / f"log{suffix}"
    path.write_text("time\tgyro_z\ttemperature\n" + "".join(f"{t}\t0.5\t{20 + t / 10}\n" for t in range(50)))
    rec = read(path)
    assert rec.n_samples == 50 and rec.gyro_axes == ("gyro_z",)
    result = run("convert", path, tmp_path / "out.csv")
    assert result.returncode == 0, result.stderr


@pytest.mark.slow
def test_progress_bar_on_a_terminal_only(report_files):
    d = report_files
    cmd = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "gyrocomp"]

    def stderr_of(*extra):
        master, slave = pty.openpty()
        done = subprocess.run(
            [*cmd, *extra, "convert", str(d / "run2.csv"), str(d / "tty.parquet")],
            stdout=subprocess.PIPE,
            stderr=slave,
            timeout=300,
        )
        os.close(slave)
        chunks = []
        while True:
            try:
                chunk = os.read(master, 65536)
            except OSError:
                break
            if not chunk:
                break
            chunks.append(chunk)
        os.close(master)
        assert done.returncode == 0
        return b"".join(chunks)

    bar = b"\xe2\x94\x81"  # the bar's glyph
    shown = stderr_of()
    assert b"reading run2.csv" in shown and bar in shown
    assert bar not in stderr_of("--quiet")
    piped = run("convert", d / "run2.csv", d / "piped.parquet")
    assert bar.decode() not in piped.stderr  # not a terminal: no bar


def _implausible_table(path):
    lines = [f"{i * 0.1:.1f},{0.01 * i:.3f},25.0" for i in range(3000)]
    lines[1200] = "120.0,0.1,400.0"
    lines[2200] = "220.0,0.2,450.0"
    lines[2500] = "250.0,6000.0,25.0"
    path.write_text("time,gyro_z,temperature\n" + "\n".join(lines) + "\n")


@pytest.mark.parametrize("selected", [[], ["--time", "0:"]])
def test_convert_says_what_is_implausible_in_what_it_converts_once_per_kind(tmp_path, selected):
    """A converted file is read again later: a temperature no sensor reaches and a rate beyond any gyro's range
    are said now, once each with the first row, in the chunked and (rows selected by time) the whole-file path;
    the file is still written (nothing is impossible, only implausible)."""
    _implausible_table(tmp_path / "in.csv")
    r = run("convert", tmp_path / "in.csv", tmp_path / "out.parquet", *selected)
    warned = [line for line in r.stderr.splitlines() if "warning" in line]
    assert r.returncode == 0 and (tmp_path / "out.parquet").exists(), r.stderr
    assert len(warned) == 2, r.stderr
    assert "row 1201: temperature 400 degC, beyond any sensor's range" in warned[0] + warned[1]
    assert "gyro values up to 6000 deg/s, beyond any MEMS gyro's range" in warned[0] + warned[1]


def test_convert_in_many_chunks_says_each_kind_once(tmp_path):
    _implausible_table(tmp_path / "in.csv")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        convert_file(tmp_path / "in.csv", tmp_path / "out.csv", chunks=ChunkSettings(chunk_rows=1000))
    said = [str(w.message) for w in caught]
    assert len(said) == 2 and "row 1201: temperature 400 degC" in said[0] and "6000 deg/s" in said[1], said
