"""Tables in chunks: apply_file writes, chunk by chunk, exactly what the whole-file apply writes (CSV and Parquet,
any chunk size, gaps, dropped rows, a turn-on window that holds output back, a lag model, the accelerometer), says
the same warnings once, names the file's own rows in its errors, and reads a file whole when it cannot stream."""

from __future__ import annotations

import dataclasses
import os
import re
import subprocess
import sys
import warnings

import numpy as np
import pyarrow as pa
import pyarrow.csv as pacsv
import pyarrow.parquet as pq
import pytest
from hypothesis import given, settings as hsettings, strategies as st

from gyrocomp.calibration.compensate import apply
from gyrocomp.files import ChunkSettings, apply_file, convert_file
from gyrocomp.errors import DataQualityWarning, InputError
from gyrocomp.io.atomic import TEMP_PREFIX, write_text_atomic

from ..conftest import SCRIPT
from gyrocomp.io import stream as stream_module
from gyrocomp.io.stream import TableStream
from gyrocomp.io import ReadOptions
from gyrocomp.io.tables import TableLayout, read_table, write_gyro_back, write_recording
from gyrocomp.models.fit import fit_channels
from gyrocomp.simulation import simulate


def _whole(calibration, source, target, **kwargs):
    """The whole-file path: read_table, apply, write_gyro_back."""
    layout = kwargs.pop("layout", None)
    data = read_table(source, layout, drop_nonfinite=kwargs.pop("drop_nonfinite", False))
    write_gyro_back(data, apply(calibration, data.recording, **kwargs).gyro_dps, target)


def _read(path):
    return pq.read_table(path) if str(path).endswith(".parquet") else pacsv.read_csv(path)


@pytest.fixture(scope="module")
def held_out(tmp_path_factory):
    """A held-out run with a 30 s gap and two rows with an empty cell, as CSV and Parquet."""
    rec = simulate("consumer", profile="chamber", rate_hz=2, duration_s=1800, seed=9, unit=3).recording
    keep = np.ones(rec.n_samples, dtype=bool)
    keep[1000:1060] = False
    rec = rec.take(keep)
    folder = tmp_path_factory.mktemp("stream")
    paths = {}
    for suffix in ("csv", "parquet"):
        paths[suffix] = folder / f"run.{suffix}"
        write_recording(rec, paths[suffix], extra_columns={"flag": np.arange(rec.n_samples) % 3})
    text = paths["csv"].read_text().splitlines()
    for row in (500, 2500):
        cells = text[row].split(",")
        cells[2] = ""
        text[row] = ",".join(cells)
    (folder / "holes.csv").write_text("\n".join(text) + "\n")
    paths["holes"] = folder / "holes.csv"
    return paths


@hsettings(max_examples=6, deadline=None)
@given(st.integers(2, 4000), st.sampled_from(["csv", "parquet"]), st.sampled_from([None, 120.0]))
def test_any_chunk_size_writes_what_the_whole_file_gives(
    consumer_model, held_out, tmp_path_factory, chunk_rows, suffix, window
):
    out = tmp_path_factory.mktemp("out")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _whole(consumer_model, held_out[suffix], out / f"whole.{suffix}", turn_on_window_s=window)
        result = apply_file(
            consumer_model,
            held_out[suffix],
            out / f"chunks.{suffix}",
            chunks=ChunkSettings(chunk_rows=chunk_rows),
            turn_on_window_s=window,
        )
    assert result.streamed and result.rows == _read(held_out[suffix]).num_rows
    assert _read(out / f"chunks.{suffix}").equals(_read(out / f"whole.{suffix}"))
    if suffix == "csv":  # the same bytes
        assert (out / f"chunks.{suffix}").read_bytes() == (out / f"whole.{suffix}").read_bytes()


def test_dropped_rows_and_gaps_are_said_once_for_the_whole_file(consumer_model, held_out, tmp_path):
    with pytest.warns(DataQualityWarning) as caught:
        result = apply_file(
            consumer_model,
            held_out["holes"],
            tmp_path / "out.csv",
            options=ReadOptions(drop_nonfinite=True),
            chunks=ChunkSettings(chunk_rows=700),
        )
    said = [str(w.message) for w in caught if issubclass(w.category, DataQualityWarning)]
    assert sum("dropped 2 of 3541 rows" in m for m in said) == 1
    assert sum("1 time gap(s)" in m and "longest 30.5 s after row 1000" in m for m in said) == 1
    assert result.rows == 3539
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _whole(consumer_model, held_out["holes"], tmp_path / "whole.csv", drop_nonfinite=True)
    assert (tmp_path / "out.csv").read_bytes() == (tmp_path / "whole.csv").read_bytes()


def test_errors_name_the_rows_of_the_file(consumer_model, held_out, tmp_path):
    with pytest.raises(InputError, match=r"holes.csv: row 500, column 'gyro_y': nan is not a finite number"):
        apply_file(consumer_model, held_out["holes"], tmp_path / "out.csv", chunks=ChunkSettings(chunk_rows=300))
    assert not (tmp_path / "out.csv").exists() and not list(tmp_path.iterdir())  # nothing left behind
    lines = held_out["csv"].read_text().splitlines()
    lines[400], lines[399] = lines[399], lines[400]  # rows 399 and 400 swapped, across the chunk boundary
    (tmp_path / "swapped.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"swapped.csv: row 400: time .* does not increase \(row 399"):
        apply_file(consumer_model, tmp_path / "swapped.csv", tmp_path / "out.csv", chunks=ChunkSettings(chunk_rows=399))
    with pytest.raises(InputError, match="chunk_rows: a whole number of at least 2"):
        TableStream(held_out["csv"], chunk_rows=1)


def test_a_csv_whose_column_type_changes_is_read_whole(consumer_model, held_out, tmp_path, monkeypatch):
    """A column of whole numbers in the first block and decimals later cannot be streamed with the first block's
    types: the file is read whole, with the same result."""
    lines = held_out["csv"].read_text().splitlines()
    head = lines[0].split(",")
    flag = head.index("flag")
    cells = lines[3000].split(",")
    cells[flag] = "0.5"
    lines[3000] = ",".join(cells)
    (tmp_path / "mixed.csv").write_text("\n".join(lines) + "\n")
    monkeypatch.setattr(stream_module, "CSV_BLOCK_BYTES", 4096)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = apply_file(
            consumer_model, tmp_path / "mixed.csv", tmp_path / "out.csv", chunks=ChunkSettings(chunk_rows=500)
        )
        _whole(consumer_model, tmp_path / "mixed.csv", tmp_path / "whole.csv")
    assert not result.streamed
    assert (tmp_path / "out.csv").read_bytes() == (tmp_path / "whole.csv").read_bytes()


def test_units_and_mapped_columns_stream_too(consumer_model, held_out, tmp_path):
    """A file in rad/s and milliseconds with its own column names: the output keeps them, in its units."""
    table = pacsv.read_csv(held_out["csv"])
    table = table.rename_columns(
        ["t_ms" if n == "time" else n.upper() if n.startswith("gyro") else n for n in table.column_names]
    )
    table = table.set_column(0, "t_ms", pa.array(table.column("t_ms").to_numpy() * 1000.0))
    for axis in ("GYRO_X", "GYRO_Y", "GYRO_Z"):
        i = table.column_names.index(axis)
        table = table.set_column(i, axis, pa.array(table.column(axis).to_numpy() * np.pi / 180))
    pq.write_table(table, tmp_path / "own.parquet")
    layout = TableLayout(
        columns={"time": "t_ms", "gyro_x": "GYRO_X", "gyro_y": "GYRO_Y", "gyro_z": "GYRO_Z"},
        gyro_unit="rad/s",
        time_unit="ms",
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        apply_file(
            consumer_model,
            tmp_path / "own.parquet",
            tmp_path / "out.parquet",
            options=ReadOptions(layout=layout),
            chunks=ChunkSettings(chunk_rows=333),
        )
        _whole(consumer_model, tmp_path / "own.parquet", tmp_path / "whole.parquet", layout=layout)
    out = pq.read_table(tmp_path / "out.parquet")
    assert out.column_names == table.column_names
    assert out.equals(pq.read_table(tmp_path / "whole.parquet"))


def test_a_model_with_the_accelerometer_streams_its_columns_too(held_out, tmp_path):
    """Accelerometer temperature models: the accel columns are replaced chunk by chunk as in the whole-file path;
    with a turn-on window (which holds the gyro back, not the accelerometer) the file is read whole."""
    runs = [
        simulate("consumer", profile="chamber", rate_hz=2, duration_s=3600, seed=s, unit=3).recording for s in range(2)
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = fit_channels(runs, ("gyro", "accel"))
        assert model.accel_axes
        for window in (None, 60.0):
            result = apply_file(
                model,
                held_out["parquet"],
                tmp_path / "out.parquet",
                chunks=ChunkSettings(chunk_rows=250),
                turn_on_window_s=window,
            )
            data = read_table(held_out["parquet"])
            done = apply(model, data.recording, turn_on_window_s=window)
            write_gyro_back(data, done.gyro_dps, tmp_path / "whole.parquet", accel_g=done.accel_g)
            assert result.streamed == (window is None)
            assert "accel_x" in result.axes
            assert pq.read_table(tmp_path / "out.parquet").equals(pq.read_table(tmp_path / "whole.parquet"))


@pytest.mark.parametrize("suffix,out_suffix", [("csv", "parquet"), ("parquet", "csv"), ("holes", "csv")])
def test_convert_in_chunks_writes_what_the_whole_file_gives(held_out, tmp_path, suffix, out_suffix):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = convert_file(
            held_out[suffix],
            tmp_path / f"chunks.{out_suffix}",
            options=ReadOptions(drop_nonfinite=True),
            chunks=ChunkSettings(chunk_rows=777),
        )
        write_recording(read_table(held_out[suffix], drop_nonfinite=True).recording, tmp_path / f"whole.{out_suffix}")
    assert _read(tmp_path / f"chunks.{out_suffix}").equals(_read(tmp_path / f"whole.{out_suffix}"))
    assert result.gaps == 1 and result.rate_hz == 2.0 and result.channels[:3] == ("gyro_x", "gyro_y", "gyro_z")
    assert result.rows == _read(tmp_path / f"whole.{out_suffix}").num_rows


def test_temporary_outputs_a_killed_process_left_are_removed_and_a_live_one_s_kept(tmp_path):
    done = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    dead = int(done.stdout)  # that process has exited
    stale = tmp_path / f"{TEMP_PREFIX}{dead}-out.csv.abc123.tmp"
    stale.write_bytes(b"x" * 1000)
    live = tmp_path / f"{TEMP_PREFIX}{os.getpid()}-out.csv.def456.tmp"
    live.write_bytes(b"y")
    other = tmp_path / f"{TEMP_PREFIX}{dead}-other.csv.abc123.tmp"  # another target's: not this write's business
    other.write_bytes(b"z")
    write_text_atomic(tmp_path / "out.csv", "a,b\n")
    assert not stale.exists() and live.exists() and other.exists()
    assert (tmp_path / "out.csv").read_text() == "a,b\n"


def test_any_file_name_the_os_allows(tmp_path):
    """A name that is not valid UTF-8 (legal on Linux; Python keeps the bytes as surrogate escapes) reads and
    writes through every table path: whole, in chunks, Parquet and CSV."""
    name = os.fsdecode(b"run\xff")
    csv = tmp_path / f"{name}.csv"
    write_text_atomic(
        csv, "time,gyro_z,temperature\n" + "".join(f"{t},{0.01 * t},{20 + 0.01 * t}\n" for t in range(2000))
    )
    for args, out in (
        (("convert", csv, tmp_path / f"{name}.parquet"), f"{name}.parquet"),
        (("fit", csv, "-o", tmp_path / f"{name}.json", "--temperature", "poly:1"), f"{name}.json"),
        (
            ("apply", tmp_path / f"{name}.json", tmp_path / f"{name}.parquet", "-o", tmp_path / f"{name}-comp.csv"),
            f"{name}-comp.csv",
        ),
    ):
        result = _run_bytes(*args)  # the names come back as the bytes they are
        assert result.returncode == 0, result.stderr
        assert (tmp_path / out).exists()
    assert _run_bytes("allan", tmp_path / f"{name}.parquet").returncode == 0


def _run_bytes(*args) -> subprocess.CompletedProcess:
    """The command line with output kept as bytes (a file name that is not UTF-8 is printed as its bytes)."""
    cmd = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "gyrocomp"]
    return subprocess.run([*cmd, *map(os.fspath, args)], capture_output=True, timeout=300)


WHOLE = ReadOptions(time_range_s=(None, 1e6))


def test_apply_names_a_dead_or_doubled_axis_and_temperature_spikes_streamed_or_whole(consumer_model, tmp_path):
    """Issue #74, item 7: what the data check names in a run is named by apply too (the samples are checked as
    they are compensated), the same whether the table is read in chunks or whole; a sound run is named by none."""
    run = simulate("consumer", profile="chamber", rate_hz=2, duration_s=1800, seed=5, unit=3).recording
    sound = tmp_path / "sound.csv"
    write_recording(run, sound)
    temperature = np.array(run.temperature_degc, dtype=float)
    temperature[[100, 1500, 2900, 3300]] = -40.0  # read errors, one of them across a chunk boundary
    gyro = run.gyro_dps.copy()
    gyro[:, 1] = 0.0  # an axis that says nothing
    gyro[:, 2] = gyro[:, 0]  # one column mapped twice
    bad = tmp_path / "bad.csv"
    write_recording(dataclasses.replace(run, gyro_dps=gyro, temperature_degc=temperature), bad)
    said = {}
    # in chunks of 1500 rows, or whole (a table whose rows are selected by time is read whole)
    for name, how in (("streamed", {"chunks": ChunkSettings(chunk_rows=1500)}), ("whole", {"options": WHOLE})):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            result = apply_file(consumer_model, bad, tmp_path / f"{name}.csv", **how)
            clean = apply_file(consumer_model, sound, tmp_path / f"clean-{name}.csv", **how)
        assert result.streamed == clean.streamed == (name == "streamed")
        said[name] = sorted(str(w.message) for w in caught if "(data check '" in str(w.message))
    assert said["streamed"] == said["whole"]
    text = "\n".join(said["whole"])
    assert len(said["whole"]) == 3 and "sound.csv" not in text, said["whole"]
    assert "gyro_y (0 deg/s): every sample the same value" in text
    assert "gyro_x and gyro_z hold the same samples in every row" in text
    assert re.search(r"bad\.csv: 4 temperature sample\(s\) jump 2 degC or more .*\(rows 101, 1501, 2901, \.\.\.;", text)
    assert text.count("the output compensates those samples as they are") == 3
