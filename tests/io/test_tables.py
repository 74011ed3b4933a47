import gzip
import io
import lzma
import math
import os
import re
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp.errors import DataQualityWarning, InputError, TimeOrderError
from gyrocomp.io import (
    TableLayout,
    atomic_path,
    parse_column_mapping,
    read,
    read_table,
    refuse_to_overwrite_inputs,
    write_gyro_back,
    write_recording,
)
from gyrocomp.io.guess import guess_layout
from gyrocomp.io.stream import TableStream, TableWriter
from gyrocomp.io.text_format import SpacedText, TextFormat, preamble_lines, spaced_as_fields, text_encoding, units_line
from gyrocomp.simulation import GyroErrorModel, simulate
from gyrocomp.units import unit_factor

from ..conftest import chamber_run, run, shared_dataset


def write_csv(path, text):
    path.write_text(text)
    return path


def test_default_layout_round_trip_csv_and_parquet(tmp_path):
    sim = simulate(duration_s=10, rate_hz=10, seed=1)
    for name in ("run.csv", "run.parquet"):
        write_recording(sim.recording, tmp_path / name)
        back = read(tmp_path / name)
        assert back.gyro_axes == ("gyro_x", "gyro_y", "gyro_z")
        assert back.accel_axes == ("accel_x", "accel_y", "accel_z")
        np.testing.assert_array_equal(back.gyro_dps, sim.recording.gyro_dps)  # exact: shortest round-trip floats
        np.testing.assert_array_equal(back.temperature_degc, sim.recording.temperature_degc)
        np.testing.assert_array_equal(back.time_s, sim.recording.time_s)


def test_single_axis_without_accel(tmp_path):
    p = write_csv(tmp_path / "z.csv", "time,gyro_z,temperature\n0,0.1,20\n0.5,0.2,20.5\n1.0,0.3,21\n")
    rec = read(p)
    assert rec.gyro_axes == ("gyro_z",)
    assert rec.accel_g is None
    assert rec.rate_hz == 2.0


def test_per_axis_temperatures(tmp_path):
    p = write_csv(tmp_path / "t.csv", "time,gyro_x,gyro_z,temperature_x,temperature_z\n0,1,2,20,30\n1,1,2,21,31\n")
    rec = read(p)
    np.testing.assert_array_equal(rec.temperature_for("gyro_z"), [30, 31])


def test_mapping_and_unit_conversions(tmp_path):
    p = write_csv(
        tmp_path / "vendor.csv",
        "Stamp,GyrZ,AccX,AccY,AccZ,T\n0,3.141592653589793,0,0,9.80665,25\n1000,0,0,9.80665,0,26\n2000,0,0,0,0,27\n",
    )
    layout = TableLayout(
        parse_column_mapping("time=Stamp,gyro_z=GyrZ,accel_x=AccX,accel_y=AccY,accel_z=AccZ,temperature=T"),
        gyro_unit="rad/s",
        accel_unit="m/s2",
        time_unit="ms",
    )
    rec = read(p, layout)
    np.testing.assert_allclose(rec.time_s, [0, 1, 2])
    assert rec.gyro_dps[0, 0] == pytest.approx(180.0)
    np.testing.assert_allclose(rec.accel_g[0], [0, 0, 1])
    np.testing.assert_allclose(rec.accel_g[1], [0, 1, 0])
    np.testing.assert_array_equal(rec.temperature_degc, [25, 26, 27])


@pytest.mark.parametrize("unit,factor", [("mdps", 1e-3), ("deg/s", 1.0), ("rad/s", 180 / math.pi)])
def test_gyro_units(tmp_path, unit, factor):
    p = write_csv(tmp_path / "u.csv", "time,gyro_z\n0,2\n1,4\n")
    rec = read(p, TableLayout(gyro_unit=unit))
    np.testing.assert_allclose(rec.gyro_dps[:, 0], np.array([2, 4]) * factor)


@pytest.mark.parametrize("unit,factor", [("us", 1e-6), ("ns", 1e-9), ("s", 1.0)])
def test_time_units(tmp_path, unit, factor):
    p = write_csv(tmp_path / "t.csv", "time,gyro_z\n0,2\n5000,4\n")
    assert read(p, TableLayout(time_unit=unit)).time_s[1] == pytest.approx(5000 * factor)


@pytest.mark.parametrize(
    "text,message",
    [
        ("", r"e.csv: the file is empty; expected a header"),
        ("\n\n", r"e.csv: the file is empty"),
        ("time,gyro_z,temperature\n", r"e.csv: a header but no data rows"),
        (
            "time,gyro_z,temperature\n0,1,20\n1,abc,21\n2,1,22\n",
            r"e.csv: row 2 \(line 3\), column 'gyro_z': 'abc' is not a number",
        ),
        (
            "time,gyro_z,temperature\n0,1,20\n1,,21\n2,1,22\n",
            r"e.csv: row 2, column 'gyro_z': nan is not a finite number",
        ),
        (
            "time,gyro_z,temperature\n0,1,20\n1,nan,21\n2,1,22\n",
            r"e.csv: row 2, column 'gyro_z': nan is not a finite number",
        ),
        ("time,gyro_z,temperature\n0,1,20\n2,1,21\n1,1,22\n", r"e.csv: row 3: time goes backwards"),
        (
            "t,gyro_z\n0,1\n1,2\n",
            r"e.csv: no 'time' column \(the file has t, gyro_z\); map one with columns=\{'time': 'NAME'\}",
        ),
        ("time,temperature\n0,1\n1,2\n", r"e.csv: no gyro column .*columns=\{'gyro_z': 'NAME'\}"),
    ],
)
def test_bad_csv_messages(tmp_path, text, message):
    p = write_csv(tmp_path / "e.csv", text)
    with pytest.raises(InputError, match=message):
        read(p)


def test_mapping_errors(tmp_path):
    p = write_csv(tmp_path / "m.csv", "time,gyro_z\n0,1\n1,2\n")
    with pytest.raises(InputError, match=r"columns={'gyro_x': 'Nope'}: no column 'Nope'; the file has time, gyro_z"):
        read(p, TableLayout({"gyro_x": "Nope"}))
    with pytest.raises(InputError, match=r"columns: unknown channel 'gyro_w'"):
        TableLayout({"gyro_w": "x"})
    with pytest.raises(InputError, match=r"columns: 'gyro_z' is not CHANNEL=COLUMN"):
        parse_column_mapping("gyro_z")
    with pytest.raises(InputError, match=r"accel_unit: unknown unit 'furlong/s2'"):
        TableLayout(accel_unit="furlong/s2")


def test_missing_file_and_unknown_suffix(tmp_path):
    with pytest.raises(InputError, match=r"nothere.csv: no such file"):
        read(tmp_path / "nothere.csv")
    (tmp_path / "x.log").write_text("time,gyro_z\n0,1\n1,2\n")
    with pytest.raises(
        InputError, match=r"x.log: cannot tell the format from the file or its suffix '.log'; name it with fmt="
    ):
        read(tmp_path / "x.log")
    assert read(tmp_path / "x.log", fmt="csv").n_samples == 2


def test_not_a_parquet_file(tmp_path):
    p = write_csv(tmp_path / "fake.parquet", "time,gyro_z\n0,1\n")
    with pytest.raises(InputError, match=r"fake.parquet: not a readable Parquet file"):
        read(p)


def test_drop_nan_reports_count_and_write_back_leaves_the_dropped_rows_out(tmp_path):
    p = write_csv(
        tmp_path / "n.csv", "time,gyro_z,temperature,note\n0,1,20,a\n1,,21,b\n2,3,22,c\n3,4,inf,d\n4,5,23,e\n"
    )
    with pytest.warns(DataQualityWarning, match=r"n.csv: dropped 2 of 5 rows"):
        data = read_table(p, drop_nonfinite=True)
    assert list(data.recording.row_numbers) == [1, 3, 5]
    write_gyro_back(data, data.recording.gyro_dps * 2, tmp_path / "out.csv")
    out = pd.read_csv(tmp_path / "out.csv")
    assert list(out.columns) == ["time", "gyro_z", "temperature", "note"]
    # the rows read are the rows written: row 4's valid gyro value is not overwritten with NaN
    assert len(out) == 3
    np.testing.assert_array_equal(out["gyro_z"].to_numpy(), [2, 6, 10])
    assert list(out["note"]) == list("ace") and list(out["time"]) == [0, 2, 4]


def test_write_back_converts_to_file_unit(tmp_path):
    p = write_csv(tmp_path / "r.csv", "time,GyrZ\n0,1\n1,2\n")
    data = read_table(p, TableLayout({"gyro_z": "GyrZ"}, gyro_unit="rad/s"))
    write_gyro_back(data, data.recording.gyro_dps, tmp_path / "o.csv")
    out = pd.read_csv(tmp_path / "o.csv")
    np.testing.assert_allclose(out["GyrZ"], [1, 2], rtol=1e-15)


def test_atomic_path_leaves_target_untouched_on_failure(tmp_path):
    target = tmp_path / "out.csv"
    target.write_text("precious")
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_text("half")
            raise RuntimeError("boom")
    assert target.read_text() == "precious"
    assert os.listdir(tmp_path) == ["out.csv"]


def test_atomic_outputs_get_ordinary_permissions(tmp_path):
    """Not the temporary file's private 0o600: a new file gets 0o666 less the umask, an existing one keeps
    its mode."""
    previous = os.umask(0o027)
    try:
        with atomic_path(tmp_path / "new.csv") as tmp:
            tmp.write_text("x")
        assert (tmp_path / "new.csv").stat().st_mode & 0o777 == 0o640
        kept = tmp_path / "kept.csv"
        kept.write_text("old")
        kept.chmod(0o604)
        with atomic_path(kept) as tmp:
            tmp.write_text("new")
        assert kept.stat().st_mode & 0o777 == 0o604 and kept.read_text() == "new"
    finally:
        os.umask(previous)


def test_atomic_path_needs_existing_folder(tmp_path):
    with pytest.raises(InputError, match=r"folder .*nodir does not exist"):
        with atomic_path(tmp_path / "nodir" / "x.csv"):
            pass


def test_refuse_to_overwrite_inputs(tmp_path):
    src = write_csv(tmp_path / "in.csv", "x")
    with pytest.raises(InputError, match=r"-o .*in.csv: this is an input file"):
        refuse_to_overwrite_inputs(src, [src])
    os.link(src, tmp_path / "hard.csv")
    with pytest.raises(InputError, match="this is an input file"):
        refuse_to_overwrite_inputs(tmp_path / "hard.csv", [src])
    refuse_to_overwrite_inputs(tmp_path / "other.csv", [src])


def test_single_axis_simulation_writes_default_layout(tmp_path):
    model = GyroErrorModel(axes=("gyro_z",), temperature_coefficients=((1e-3,),), accelerometer=None)
    write_recording(simulate(model, duration_s=5, rate_hz=10).recording, tmp_path / "s.csv")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert pd.read_csv(tmp_path / "s.csv").columns.tolist() == ["time", "gyro_z", "temperature"]


def test_gaps_are_reported_and_kept(tmp_path):
    rows = [f"{t:.2f},0.1,20" for t in [0, 0.01, 0.02, 0.03, 3.0, 3.01, 3.02, 9.0, 9.01]]
    p = write_csv(tmp_path / "g.csv", "time,gyro_z,temperature\n" + "\n".join(rows) + "\n")
    with pytest.warns(
        DataQualityWarning,
        match=r"g.csv: 2 time gap\(s\) longer than 2 sample periods "
        r"\(longest 5.98 s after row 7\); kept as they are, nothing interpolated",
    ):
        rec = read(p)
    assert rec.n_samples == 9
    assert [g.after_row for g in rec.gaps] == [4, 7]


def test_accel_nan_names_its_column(tmp_path):
    p = write_csv(tmp_path / "a.csv", "time,gyro_z,accel_x,accel_y,accel_z\n0,1,0,0,1\n1,1,0,inf,1\n")
    with pytest.raises(InputError, match=r"a.csv: row 2, column 'accel_y': inf is not a finite number"):
        read(p)


def test_quoted_numbers_are_read(tmp_path):
    p = write_csv(tmp_path / "q.csv", 'time,gyro_z,temperature\n0,"1.5",20\n1,"2.5",21\n')
    np.testing.assert_array_equal(read(p).gyro_dps[:, 0], [1.5, 2.5])


def test_written_csv_headers_are_unquoted_unless_a_name_needs_quotes(tmp_path):
    p = write_csv(tmp_path / "h.csv", 'time,gyro_z,"temp, C"\n0,1,20\n1,2,21\n')
    data = read_table(p, TableLayout({"temperature": "temp, C"}))
    write_gyro_back(data, data.recording.gyro_dps, tmp_path / "o.csv")
    assert (tmp_path / "o.csv").read_text().splitlines()[0] == '"time","gyro_z","temp, C"'
    plain = read_table(write_csv(tmp_path / "p.csv", "time,gyro_z\n0,1\n1,2\n"))
    write_gyro_back(plain, plain.recording.gyro_dps, tmp_path / "q.csv")
    assert (tmp_path / "q.csv").read_text().splitlines()[0] == "time,gyro_z"
    assert list(pd.read_csv(tmp_path / "o.csv").columns) == ["time", "gyro_z", "temp, C"]


def test_a_repeated_column_name_is_refused_in_one_line(tmp_path):
    p = write_csv(tmp_path / "dup.csv", "time,gyro_z,gyro_z,temperature\n0,1,2,20\n1,1,2,21\n")
    with pytest.raises(InputError, match=r"dup.csv: column 'gyro_z' appears 2 times in the header; give each column"):
        read_table(p)


THREE_AXES = "time,gyro_x,gyro_y,gyro_z,temperature\n0,1,2,3,20\n1,1,2,3,21\n"


def test_a_column_read_as_two_channels_is_refused_and_a_swap_is_read(tmp_path):
    p = write_csv(tmp_path / "three.csv", THREE_AXES)
    with pytest.raises(
        InputError,
        match=r"three.csv: column 'gyro_x' would be read as gyro_x and gyro_z "
        r"\(columns=\{'gyro_z': 'gyro_x'\}\); one column feeds one channel",
    ):
        read_table(p, TableLayout(columns={"gyro_z": "gyro_x"}))
    swapped = read_table(p, TableLayout(columns={"gyro_x": "gyro_z", "gyro_z": "gyro_x"})).recording
    np.testing.assert_array_equal(swapped.gyro_dps[0], [3.0, 2.0, 1.0])


def test_a_channels_own_column_left_unread_by_a_mapping_is_said(tmp_path):
    p = write_csv(tmp_path / "alt.csv", "time,gyro_z,gyro_z_filtered,temperature\n0,1,5,20\n1,1,6,21\n")
    with pytest.warns(
        DataQualityWarning,
        match=r"alt.csv: column 'gyro_z' is not read: "
        r"columns=\{'gyro_z': 'gyro_z_filtered'\} reads gyro_z from",
    ):
        data = read_table(p, TableLayout(columns={"gyro_z": "gyro_z_filtered"}))
    np.testing.assert_array_equal(data.recording.gyro_dps[:, 0], [5.0, 6.0])


def test_cli_refuses_a_mapping_that_reads_one_column_twice(tmp_path):
    p = write_csv(tmp_path / "three.csv", THREE_AXES)
    result = run("convert", p, tmp_path / "out.csv", "--columns", "gyro_z=gyro_x")
    assert result.returncode == 2 and not (tmp_path / "out.csv").exists()
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "would be read as gyro_x and gyro_z (--columns gyro_z=gyro_x)" in lines[0], lines


SEMICOLON = "time;gyro_z;temperature\n0;1,5;20,25\n1;2,5;21,5\n2;-0,5;22\n"


@pytest.mark.parametrize(
    "text, layout",
    [
        (SEMICOLON, TableLayout()),  # a spreadsheet in a decimal-comma locale
        (SEMICOLON.replace(";", "\t"), TableLayout()),  # tab-separated
        (SEMICOLON, TableLayout(delimiter=";", decimal=",")),  # said explicitly
        (" Time , GYRO_Z , Temperature\n0,1.5,20.25\n1,2.5,21.5\n2,-0.5,22\n", TableLayout()),  # spaced, capitalized
    ],
)
def test_delimiters_decimal_commas_and_loose_standard_names(tmp_path, text, layout):
    data = read_table(write_csv(tmp_path / "v.csv", text), layout)
    np.testing.assert_array_equal(data.recording.gyro_dps[:, 0], [1.5, 2.5, -0.5])
    np.testing.assert_array_equal(data.recording.temperature_degc, [20.25, 21.5, 22.0])


@pytest.mark.parametrize("codec, suffix", [("gzip", ".gz"), ("bz2", ".bz2"), ("zstd", ".zst"), ("xz", ".xz")])
def test_compressed_csv_by_magic_bytes_and_suffix(tmp_path, codec, suffix):
    raw = b"time,gyro_z,temperature\n0,1,20\n1,2,21\n"
    path = tmp_path / f"r.csv{suffix}"
    if codec == "xz":
        path.write_bytes(lzma.compress(raw))
    else:
        with pa.output_stream(str(path), compression=codec) as out:
            out.write(raw)
    rec = read(path)
    np.testing.assert_array_equal(rec.gyro_dps[:, 0], [1.0, 2.0])
    (tmp_path / f"bad.csv{suffix}").write_bytes(path.read_bytes()[:12])  # cut short
    with pytest.raises(InputError, match=rf"bad.csv{suffix}: "):
        read(tmp_path / f"bad.csv{suffix}")


def test_bad_delimiter_and_decimal_options():
    with pytest.raises(InputError, match=r"delimiter: ';;'; give one character"):
        TableLayout(delimiter=";;")
    with pytest.raises(InputError, match=r"decimal: ':'; use '.' or ','"):
        TableLayout(decimal=":")


@pytest.mark.parametrize("suffix", ["csv", "csv.gz", "parquet"])
def test_reading_only_some_channels(tmp_path, suffix):
    """channels=: only time and those channels' columns are read (the table kept holds only them), with the same
    values as a whole read; a mapped column is found by its channel."""
    rec = simulate("mti10", profile="static", rate_hz=10, duration_s=60, seed=4).recording
    path = tmp_path / f"run.{suffix}"
    if suffix == "csv.gz":
        write_recording(rec, tmp_path / "run.csv")
        path.write_bytes(gzip.compress((tmp_path / "run.csv").read_bytes()))
    else:
        write_recording(rec, path)
    whole = read_table(path)
    some = read_table(path, channels=("gyro_z", "accel_x"))
    assert some.table.column_names == ["time", "gyro_z", "accel_x"]
    assert some.recording.gyro_axes == ("gyro_z",) and some.recording.accel_axes == ("accel_x",)
    assert some.recording.temperature_degc is None
    np.testing.assert_array_equal(some.recording.gyro_dps[:, 0], whole.recording.gyro_dps[:, 2])
    layout = TableLayout(columns={"gyro_x": "gyro_z", "gyro_z": "gyro_x"})  # the file's gyro_z read as gyro_x
    mapped = read_table(path, layout, channels=("gyro_x",))
    assert mapped.table.column_names == ["time", "gyro_z"]
    np.testing.assert_array_equal(mapped.recording.gyro_dps[:, 0], whole.recording.gyro_dps[:, 2])
    with pytest.raises(InputError, match=r"none of the channels read \(accel_x\) is a gyro axis of the file"):
        read_table(path, channels=("accel_x",))


@pytest.mark.parametrize(
    "header, name",
    [("time,Gyro_Z,GYRO_Z,temperature", "gyro_z"), ("time,gyro_z,temperature,Temperature", "temperature")],
)
def test_two_columns_that_match_one_channel_are_refused_naming_both(tmp_path, header, name):
    path = tmp_path / "amb.csv"
    path.write_text(header + "\n" + "\n".join(f"{t},1,2,{20 + t}" for t in range(5)) + "\n")
    first, second = [c for c in header.split(",") if c.strip().lower() == name]
    with pytest.raises(
        InputError,
        match=rf"amb.csv: columns '{first}' and '{second}' would both be read as {name}; "
        rf"say which with columns=",
    ):
        read(path)
    result = run("convert", path, tmp_path / "out.csv")
    assert result.returncode == 2 and result.stderr.count("\n") == 1 and f"--columns {name}={first}" in result.stderr
    assert not (tmp_path / "out.csv").exists()
    rec = read(path, TableLayout(columns={name: second}))  # a mapping says which
    assert rec.n_samples == 5


def test_names_that_say_the_project_units_are_read_without_a_mapping(tmp_path):
    """time_s, gyro_x_dps, accel_x_g, temperature_degc: the names the project itself gives things."""
    path = tmp_path / "units.csv"
    path.write_text(
        "time_s,gyro_x_dps,gyro_z_dps,accel_z_g,temperature_degc\n"
        + "".join(f"{t / 10},0.5,-0.25,1.0,{20 + t / 100}\n" for t in range(50))
    )
    rec = read(path)
    assert rec.gyro_axes == ("gyro_x", "gyro_z") and rec.accel_axes == ("accel_z",)
    np.testing.assert_allclose(rec.time_s[:3], [0.0, 0.1, 0.2])
    np.testing.assert_allclose(rec.gyro_dps[0], [0.5, -0.25])
    assert rec.temperature_degc[1] == pytest.approx(20.01)
    # the plain name wins when both are there: gyro_x is read, gyro_x_dps is another column
    both = tmp_path / "both.csv"
    both.write_text("time,gyro_x,gyro_x_dps\n" + "".join(f"{t},1.0,2.0\n" for t in range(5)))
    np.testing.assert_allclose(read(both).gyro_dps[:, 0], 1.0)


def _mpu_log(path, counts: np.ndarray, preamble: str = "Fs,100\nLogging Type,1\n\nInitialization time,-1\n") -> Path:
    """A raw MPU-6050 log as an Arduino sketch writes it: metadata lines, then ax..gz in counts, no time."""
    body = "\n".join(",".join(str(int(v)) for v in row) for row in counts)
    path.write_text(preamble + "ax,ay,az,gx,gy,gz\n" + body + "\n")
    return path


def test_a_preamble_before_the_header_is_skipped_whole_and_in_chunks_with_raw_counts_scaled(tmp_path):
    """A logger's metadata lines before the header (a different number of fields than the table's) are skipped,
    whole and streamed; raw counts are read in a scaled unit (131 counts per deg/s, 16384 per g); a value that is
    no number names its row and its line in the file; an output written back has no preamble."""
    rng = np.random.default_rng(3)
    counts = np.column_stack(
        [rng.integers(-300, 300, (40, 2)), 16384 + rng.integers(-50, 50, 40), rng.integers(-500, 500, (40, 3))]
    )
    path = _mpu_log(tmp_path / "mpu.csv", counts)
    layout = TableLayout(
        parse_column_mapping("accel_x=ax,accel_y=ay,accel_z=az,gyro_x=gx,gyro_y=gy,gyro_z=gz"),
        gyro_unit="1/131 deg/s",
        accel_unit="1/16384 g",
        rate_hz=100.0,
    )
    data = read_table(path, layout)
    assert data.text_format.preamble_lines == 4  # the header on line 5
    np.testing.assert_array_equal(data.recording.gyro_dps, counts[:, 3:] * (1.0 / 131.0))
    np.testing.assert_array_equal(data.recording.accel_g, counts[:, :3] * (1.0 / 16384.0))
    np.testing.assert_array_equal(data.recording.time_s, np.arange(40) / 100.0)
    chunks = list(TableStream(path, layout, chunk_rows=7).chunks())
    np.testing.assert_array_equal(np.concatenate([c.recording.gyro_dps for c in chunks]), data.recording.gyro_dps)
    np.testing.assert_array_equal(np.concatenate([c.recording.accel_g for c in chunks]), data.recording.accel_g)
    write_gyro_back(data, data.recording.gyro_dps + 1.0, tmp_path / "out.csv")
    assert (tmp_path / "out.csv").read_text().startswith("ax,ay,az,gx,gy,gz\n")
    back = read_table(tmp_path / "out.csv", layout)
    assert back.text_format.preamble_lines == 0
    np.testing.assert_allclose(back.recording.gyro_dps, data.recording.gyro_dps + 1.0, rtol=1e-12)
    # the values quoted, the 30th row's gx not a number: row 30, on line 5 + 30 (whole; streamed, in the fifth chunk)
    lines = path.read_text().splitlines()
    for i in range(5, len(lines)):
        lines[i] = '"' + lines[i].replace(",", '","') + '"'
    lines[4 + 30] = lines[4 + 30].replace(lines[4 + 30].split(",")[3], '"x"', 1)
    path.write_text("\n".join(lines) + "\n")
    for reading in (lambda: read_table(path, layout), lambda: list(TableStream(path, layout, chunk_rows=7).chunks())):
        with pytest.raises(InputError, match=r"mpu.csv: row 30 \(line 35\), column 'gx': 'x' is not a number"):
            reading()


@pytest.mark.parametrize(
    "text,skipped",
    [
        ("time,gyro_z\n0,1\n1,2\n2,3\n", 0),  # no preamble
        ("# logger v2\n# started 12:00\ntime,gyro_z\n0,1\n1,2\n2,3\n", 2),  # comment lines, one field each
        ("Fs;100\n\ntime;gyro_x;gyro_z\n0;1,5;2\n1;2,5;3\n2;3,5;4\n", 2),  # semicolons, a decimal comma
        ("Fs,100\n0,1,2\n1,2,3\n2,3,4\n", 0),  # numbers after the preamble: a log without a header line
        ("device,X\ntime,gyro_z\n0,1\n", 0),  # too few rows to tell: the first line is the header
    ],
)
def test_preamble_lines_are_those_before_the_first_line_that_splits_as_the_table(tmp_path, text, skipped):
    found = TextFormat.found(text.encode(), TableLayout())
    assert preamble_lines(text.encode(), found.delimiter) == skipped == found.preamble_lines
    if skipped and ";" in text:
        assert found.decimal == ","
        rec = read(write_csv(tmp_path / "p.csv", text))
        np.testing.assert_array_equal(rec.gyro_dps, [[1.5, 2], [2.5, 3], [3.5, 4]])


@pytest.mark.parametrize(
    "kind,unit,factor",
    [
        ("gyro", "1/131 deg/s", 1 / 131),
        ("gyro", "0.00875 deg/s", 0.00875),
        ("gyro", "2.5e-2 rad/s", 2.5e-2 * 180 / math.pi),
        ("accel", "1/16384 g", 1 / 16384),
        ("accel", "0.061 mg", 0.061e-3),
        ("time", "10 ms", 0.01),
    ],
)
def test_scaled_units_read_raw_counts(kind, unit, factor):
    assert unit_factor(kind, unit) == pytest.approx(factor, rel=1e-15)


@pytest.mark.parametrize(
    "unit,message",
    [
        ("0 deg/s", r"gyro_unit: '0 deg/s' scales its unit by 0; a scale is a positive number"),
        ("1/0 deg/s", r"gyro_unit: '1/0 deg/s' scales its unit by inf"),
        ("1/131 furlong", r"gyro_unit: unknown unit '1/131 furlong'; use one of .*'1/131 deg/s' \(raw counts\)"),
        ("131", r"gyro_unit: unknown unit '131'"),
    ],
)
def test_a_bad_scaled_unit_is_one_line(tmp_path, unit, message):
    p = write_csv(tmp_path / "u.csv", "time,gyro_z\n0,2\n1,4\n")
    with pytest.raises(InputError, match=message):
        read(p, TableLayout(gyro_unit=unit))


def test_a_real_mpu6050_log_with_its_preamble_is_read_as_its_counts_scaled():
    """../shared/datasets/tomisuarez2-mpu6050 (its README: four metadata lines, the header ax..gz, raw counts at
    100 Hz, 131 counts per deg/s and 16384 per g): the layout gyrocomp init guesses reads the values numpy.loadtxt
    reads with the README's skiprows, times the README's scales."""
    path = shared_dataset("tomisuarez2-mpu6050") / "imu_static_test.csv"
    guess = guess_layout(path)  # the rate from its preamble's Fs,100
    assert (guess.layout.gyro_unit, guess.layout.accel_unit, guess.layout.rate_hz) == (
        "1/131 deg/s",
        "1/16384 g",
        100.0,
    )
    recording = read_table(path, guess.layout).recording
    counts = np.loadtxt(path, delimiter=",", skiprows=5)
    np.testing.assert_array_equal(recording.gyro_dps, counts[:, 3:] * (1.0 / 131.0))
    np.testing.assert_array_equal(recording.accel_g, counts[:, :3] * (1.0 / 16384.0))
    np.testing.assert_array_equal(recording.time_s, np.arange(len(counts)) / 100.0)


def test_a_time_column_left_unread_times_the_rows_at_the_rate_given(tmp_path):
    """``columns={'time': ''}`` (``--columns time=``): the file's time column is not read and the n-th row is at
    n / rate_hz, for stamps that are not the samples' (taken as buffered samples arrived); the other channels read
    as before. Without a rate, or for another channel, it is refused; a rate beside a read time column says how."""
    rows = ["time,gyro_z,temperature"] + [f"{0.05 * (k // 5) + 0.002 * (k % 5):.3f},{k},25" for k in range(50)]
    path = tmp_path / "burst.csv"
    path.write_text("\n".join(rows) + "\n")
    rec = read(path, TableLayout(parse_column_mapping("time="), rate_hz=100.0))
    np.testing.assert_array_equal(rec.time_s, np.arange(50) / 100.0)
    np.testing.assert_array_equal(rec.gyro_dps[:, 0], np.arange(50.0))
    np.testing.assert_array_equal(rec.temperature_degc, np.full(50, 25.0))
    assert parse_column_mapping("gyro_z=G,time=") == {"gyro_z": "G", "time": ""}
    with pytest.raises(
        InputError,
        match=r"^columns: time is left unread \(columns=\{'time': ''\}\): give the samples' rate \(rate_hz=100\)",
    ):
        TableLayout({"time": ""})
    with pytest.raises(InputError, match=r"^columns: gyro_z= names no column; only the time may be left unread"):
        TableLayout({"gyro_z": ""}, rate_hz=100.0)
    with pytest.raises(InputError, match=r"^columns: 'gyro_z=' is not CHANNEL=COLUMN"):
        parse_column_mapping("gyro_z=")
    with pytest.raises(
        InputError,
        match=r"burst.csv: rate_hz=100: the file has a time column \('time'\); a nominal rate is for tables without "
        r"one, or to read the rows at it instead of the file's time leave the time unread \(columns=\{'time': ''\}\)",
    ):
        read(path, TableLayout(rate_hz=100.0))


@pytest.mark.parametrize("line_end", ["\r\n", "\r"], ids=["crlf", "cr"])
def test_a_table_whose_lines_end_otherwise_reads_as_with_newlines_whole_and_in_chunks(tmp_path, line_end):
    """Lines ended by CR LF (Windows) or a lone CR (a Macintosh CSV export, which pyarrow reads as line ends) read as
    the same table as with LF: the preamble found, the header, the values, whole and streamed; a bad value's line
    is counted the same."""
    rng = np.random.default_rng(5)
    counts = np.column_stack(
        [rng.integers(-300, 300, (40, 2)), 16384 + rng.integers(-50, 50, 40), rng.integers(-500, 500, (40, 3))]
    )
    layout = TableLayout(
        parse_column_mapping("accel_x=ax,accel_y=ay,accel_z=az,gyro_x=gx,gyro_y=gy,gyro_z=gz"),
        gyro_unit="1/131 deg/s",
        rate_hz=100.0,
    )
    newline = _mpu_log(tmp_path / "lf.csv", counts)
    other = tmp_path / "other.csv"
    other.write_bytes(newline.read_bytes().replace(b"\n", line_end.encode()))
    expected = read_table(newline, layout)
    data = read_table(other, layout)
    assert data.text_format == expected.text_format and data.text_format.preamble_lines == 4
    np.testing.assert_array_equal(data.recording.gyro_dps, expected.recording.gyro_dps)
    np.testing.assert_array_equal(data.recording.accel_g, expected.recording.accel_g)
    chunks = list(TableStream(other, layout, chunk_rows=7).chunks())
    np.testing.assert_array_equal(np.concatenate([c.recording.gyro_dps for c in chunks]), expected.recording.gyro_dps)
    np.testing.assert_array_equal(np.concatenate([c.recording.accel_g for c in chunks]), expected.recording.accel_g)
    lines = other.read_bytes().split(line_end.encode())
    lines[4 + 30] = b"x" + lines[4 + 30][lines[4 + 30].index(b",") :]  # the 30th row's ax
    other.write_bytes(line_end.encode().join(lines))
    for reading in (lambda: read_table(other, layout), lambda: list(TableStream(other, layout, chunk_rows=7).chunks())):
        with pytest.raises(InputError, match=r"other.csv: row 30 \(line 35\), column 'ax': 'x' is not a number"):
            reading()


@pytest.mark.parametrize(
    "content,said",
    [
        ("time,gyro_z\n0,1\n1,2\n".encode("utf-16"), r"UTF-16 text \(it starts with a UTF-16 byte-order mark\)"),
        ("time,gyro_z\n0,1\n1,2\n".encode("utf-32"), r"UTF-32 text"),
        (b"time,gy\x00ro_z\r0,1\r1,2\r", r"not a text table: byte 7 is a NUL"),
        (b"\x93\x1c\r\xfa\x00\x00\x12" * 50, r"not a text table: byte 4 is a NUL"),
    ],
    ids=["utf-16", "utf-32", "nul", "binary"],
)
def test_text_in_another_encoding_or_bytes_that_are_no_text_are_refused_in_one_line(tmp_path, content, said):
    """A table in UTF-16 or UTF-32 (a spreadsheet's "Unicode text") and a binary file named .csv are refused in
    one line naming the file, whole, streamed and through the command (exit 2, nothing written); random bytes
    with a lone CR used to reach Python's csv module and end in an internal error."""
    path = tmp_path / "in.csv"
    path.write_bytes(content)
    for reading in (lambda: read_table(path), lambda: list(TableStream(path).chunks())):
        with pytest.raises(InputError, match=r"in.csv: " + said):
            reading()
    result = run("fit", path, "-o", tmp_path / "m.json")
    assert result.returncode == 2 and not (tmp_path / "m.json").exists()
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.stderr and "in.csv: " in lines[0], result.stderr


@pytest.mark.parametrize(
    "head,encoding",
    [
        (b"time,gyro_z\n0,1\n", "utf-8"),
        ("temperature [°C]\n".encode("utf-8")[:-3], "utf-8"),  # the head cut inside the degree sign's two bytes
        ("temperature [°C] – ‰\n".encode("cp1252"), "cp1252"),
        (b"temperature [\xb0C] \x81\n", "latin-1"),  # 0x81 is none of Windows-1252's characters
    ],
)
def test_a_text_tables_encoding_is_told_from_its_first_bytes(head, encoding):
    assert text_encoding(head) == encoding


def test_a_time_column_of_dates_and_times_or_times_of_day_is_read_as_seconds_whole_and_in_chunks(tmp_path):
    """Loggers (and pandas' to_csv of a DatetimeIndex) write the time as a date and time: ISO 8601 with a space
    or a T and Z, read as seconds since 1970-01-01 UTC; or as a time of day, read as seconds since midnight; a
    Parquet timestamp column too. The same seconds whole and streamed; a time unit for such a column and a row
    that is no time of day are refused in one line."""
    n, rate_hz = 50, 100.0
    t0 = pd.Timestamp("2024-05-01 12:00:00")
    stamps = t0 + pd.to_timedelta(np.arange(n) * 10, unit="ms")
    epoch_s = (stamps - pd.Timestamp("1970-01-01")).total_seconds().to_numpy()
    gyro = np.arange(n * 3, dtype=float).reshape(n, 3) / 1000.0
    frame = pd.DataFrame({"gyro_x": gyro[:, 0], "gyro_y": gyro[:, 1], "gyro_z": gyro[:, 2]})
    cases = {
        "space.csv": (stamps.strftime("%Y-%m-%d %H:%M:%S.%f"), epoch_s),
        "iso_z.csv": (stamps.strftime("%Y-%m-%dT%H:%M:%S.%fZ"), epoch_s),
        "clock.csv": (stamps.strftime("%H:%M:%S.%f").str[:-3], 43_200.0 + np.arange(n) / rate_hz),
    }
    for name, (texts, expected_s) in cases.items():
        frame.assign(time=texts).to_csv(tmp_path / name, index=False)
        whole = read_table(tmp_path / name).recording
        np.testing.assert_allclose(whole.time_s, expected_s, rtol=0, atol=1e-6)
        np.testing.assert_array_equal(whole.gyro_dps, gyro)
        chunks = list(TableStream(tmp_path / name, chunk_rows=7).chunks())
        np.testing.assert_array_equal(np.concatenate([c.recording.time_s for c in chunks]), whole.time_s)
    frame.assign(time=stamps).to_parquet(tmp_path / "stamps.parquet")
    np.testing.assert_allclose(read_table(tmp_path / "stamps.parquet").recording.time_s, epoch_s, rtol=0, atol=1e-6)
    with pytest.raises(InputError, match=r"space.csv: column 'time' holds dates or times of day, whose unit is"):
        read_table(tmp_path / "space.csv", TableLayout(time_unit="ms"))
    lines = (tmp_path / "clock.csv").read_text().splitlines()
    lines[5] = lines[5].replace(lines[5].split(",")[-1], "12:00")
    (tmp_path / "clock.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"clock.csv: row 5 \(line 6\), column 'time': '12:00' is not a time of"):
        read_table(tmp_path / "clock.csv")


def test_stamps_coarser_than_the_samples_are_refused_with_the_way_to_read_the_rows_at_their_mean_rate(tmp_path):
    """A 1 kHz log stamped by a clock in ms with jitter repeats some stamps: refused at the first repeat (row and
    line), with the rows' mean rate to read them at instead; read so, the n-th row is at n / rate. The command
    line spells the advice as its flags. A time going back gets no such advice."""
    rng = np.random.default_rng(2)
    n = 3000
    stamps = np.round(np.arange(n) * 1e-3 + 3e-4 * rng.standard_normal(n), 3)
    stamps = np.maximum.accumulate(stamps)  # never back: only repeats
    first = int(np.flatnonzero(np.diff(stamps) == 0)[0]) + 2  # the 1-based row of the first repeat
    rate_hz = (n - 1) / (stamps[-1] - stamps[0])
    rows = "".join(f"{t:.3f},0.1,0.2,0.3\n" for t in stamps)
    (tmp_path / "ms.csv").write_text("time,gyro_x,gyro_y,gyro_z\n" + rows)
    with pytest.raises(TimeOrderError, match=rf"ms.csv: row {first}: time repeats .*mean rate instead") as refused:
        read_table(tmp_path / "ms.csv")
    assert refused.value.row == first and refused.value.repeated
    assert f"(columns={{'time': ''}}, rate_hz={rate_hz:.6g})" in str(refused.value)
    data = read_table(tmp_path / "ms.csv", TableLayout({"time": ""}, rate_hz=float(f"{rate_hz:.6g}")))
    np.testing.assert_allclose(data.recording.time_s, np.arange(n) / float(f"{rate_hz:.6g}"), rtol=1e-12)
    said = run("check", tmp_path / "ms.csv").stdout
    assert f"(--columns time=, --rate {rate_hz:.6g})" in said, said
    (tmp_path / "back.csv").write_text("time,gyro_z\n0,1\n0.002,1\n0.001,1\n0.003,1\n")
    with pytest.raises(
        TimeOrderError,
        match=r"back.csv: row 3: time goes backwards \(0.001 s after 0.002 s\); time must strictly increase$",
    ):
        read_table(tmp_path / "back.csv")


def test_a_table_of_spaces_reads_as_the_same_table_with_commas_whole_and_in_chunks(tmp_path):
    """Columns aligned by runs of spaces and tabs (leading and trailing ones too; Fortran's and MATLAB's text
    output, many instruments'): told from the header, read as the comma table of the same values, whole and
    streamed; a value that is no number names its row and line; apply writes it back separated by spaces."""
    rng = np.random.default_rng(4)
    n = 60
    values = np.column_stack([np.arange(n) / 100.0, rng.normal(0, 0.1, (n, 3)), 25 + rng.random(n)])
    names = ["time", "gyro_x", "gyro_y", "gyro_z", "temperature"]
    (tmp_path / "commas.csv").write_text(
        ",".join(names) + "\n" + "".join(",".join(repr(v) for v in row) + "\n" for row in values.tolist())
    )
    padded = ["  " + "\t ".join(f"{name:>14}" for name in names) + "   \r\n"]
    padded += [" " + "   ".join(f"{v!r:>22}" for v in row) + " \t\r\n" for row in values.tolist()]
    (tmp_path / "spaces.txt").write_text("".join(padded), newline="")
    expected = read_table(tmp_path / "commas.csv").recording
    data = read_table(tmp_path / "spaces.txt")
    assert data.text_format.delimiter == " " and data.table.column_names == names
    chunks = [c.recording for c in TableStream(tmp_path / "spaces.txt", chunk_rows=7).chunks()]
    for got in (data.recording, chunks):
        gyro = got.gyro_dps if not isinstance(got, list) else np.concatenate([c.gyro_dps for c in got])
        time_s = got.time_s if not isinstance(got, list) else np.concatenate([c.time_s for c in got])
        np.testing.assert_array_equal(gyro, expected.gyro_dps)
        np.testing.assert_array_equal(time_s, expected.time_s)
    write_gyro_back(data, data.recording.gyro_dps + 1.0, tmp_path / "out.txt")
    back = read_table(tmp_path / "out.txt")
    assert back.text_format.delimiter == " " and (tmp_path / "out.txt").read_text().startswith("time gyro_x gyro_y")
    np.testing.assert_allclose(back.recording.gyro_dps, expected.gyro_dps + 1.0, rtol=1e-12)
    padded[11] = padded[11].replace(repr(float(values[10, 2])), "bad", 1)
    (tmp_path / "spaces.txt").write_text("".join(padded), newline="")
    for reading in (
        lambda: read_table(tmp_path / "spaces.txt"),
        lambda: list(TableStream(tmp_path / "spaces.txt", chunk_rows=7).chunks()),
    ):
        with pytest.raises(InputError, match=r"spaces.txt: row 11 \(line 12\), column 'gyro_y': 'bad' is not a number"):
            reading()


@settings(max_examples=80, deadline=None)
@given(
    lines=st.lists(
        st.lists(st.sampled_from(["1.5", "-2", "a_b", "x", "3e-4"]), min_size=1, max_size=5).flatmap(
            lambda fields: st.tuples(
                st.just(fields),
                st.lists(
                    st.sampled_from([" ", "\t", "  ", " \t "]), min_size=len(fields) + 1, max_size=len(fields) + 1
                ),
            )
        ),
        max_size=12,
    ),
    end=st.sampled_from(["\n", "\r\n", "\r"]),
    block_bytes=st.integers(1, 40),
)
def test_a_table_of_spaces_gives_the_same_commas_whatever_the_blocks_it_is_read_in(lines, end, block_bytes):
    """Runs of spaces cut by the blocks the file is read in, and line ends of any kind, give the commas of the
    whole text read at once; each line's fields joined by single commas."""
    text = "".join(gaps[0] + "".join(f + g for f, g in zip(fields, gaps[1:])) + end for fields, gaps in lines).encode()
    read = SpacedText(io.BytesIO(text), block_bytes=block_bytes).read()
    assert read == spaced_as_fields(text)
    assert [line for line in re.split(rb"\r\n|\r|\n", read)[:-1]] == [";".join(f).encode() for f, _ in lines]


@pytest.mark.parametrize(
    "separator,units",
    [(",", "s,deg/s,deg/s,degC"), (";", "[s];[°/s];[°/s];[°C]"), (" ", "  s    deg/s   deg/s   degC")],
    ids=["commas", "semicolons-decimal-comma", "spaces"],
)
def test_a_line_of_units_under_the_header_is_skipped_whole_and_in_chunks_and_lines_counted_past_it(
    tmp_path, separator, units
):
    """A line of units under the header (data acquisition tools write one) is told from its fields, none a number,
    and skipped: the rows are the table's without it, whole and streamed, with a decimal comma and in a table of
    spaces too; a bad value's line counts it; an output is written without it, as a preamble is."""
    rng = np.random.default_rng(6)
    n = 40
    values = np.column_stack([np.arange(n) / 100.0, rng.normal(0, 0.1, (n, 2)), 25 + rng.random(n)]).tolist()
    decimal = "," if separator == ";" else "."
    rows = [separator.join(repr(v).replace(".", decimal) for v in row) for row in values]
    names = separator.join(["time", "gyro_x", "gyro_z", "temperature"])
    (tmp_path / "plain.csv").write_text(
        "time,gyro_x,gyro_z,temperature\n" + "".join(f"{r}\n" for r in (",".join(map(repr, v)) for v in values))
    )
    (tmp_path / "units.csv").write_text("\n".join([names, units, *rows]) + "\n")
    expected = read_table(tmp_path / "plain.csv").recording
    data = read_table(tmp_path / "units.csv")
    assert data.text_format.units is not None and len(data.text_format.units) == 4
    assert data.recording.n_samples == n and data.text_format.decimal == decimal
    chunks = list(TableStream(tmp_path / "units.csv", chunk_rows=7).chunks())
    for gyro in (data.recording.gyro_dps, np.concatenate([c.recording.gyro_dps for c in chunks])):
        np.testing.assert_array_equal(gyro, expected.gyro_dps)
    write_gyro_back(data, data.recording.gyro_dps, tmp_path / "out.csv")
    written = (tmp_path / "out.csv").read_text().splitlines()
    assert len(written) == n + 1 and read_table(tmp_path / "out.csv").text_format.units is None
    rows[9] = rows[9].replace(rows[9].split(separator)[1], "bad", 1)
    (tmp_path / "units.csv").write_text("\n".join([names, units, *rows]) + "\n")
    for reading in (
        lambda: read_table(tmp_path / "units.csv"),
        lambda: list(TableStream(tmp_path / "units.csv", chunk_rows=7).chunks()),
    ):
        with pytest.raises(InputError, match=r"units.csv: row 10 \(line 12\), column 'gyro_x': 'bad' is not a number"):
            reading()
    assert units_line(b"time,gyro_z\n0.0,1.5\n0.1,1.6\n", ",") is None  # the first row is numbers: no units
    assert units_line(b"time,gyro_z,status\n0.0,1.5,OK\n0.1,1.6,OK\n", ",") is None  # text beside a number


def test_a_bad_value_in_a_table_of_decimal_commas_is_named_not_the_first_number(tmp_path):
    """One value that is no number makes its column text; the numbers around it keep their decimal commas, and the
    message names the bad value's row (it named the first row's number, 0,5, as no number)."""
    rows = [f"{k};{k / 2:.1f}".replace(".", ",") for k in range(20)]
    rows[13] = "13;n.v."
    (tmp_path / "de.csv").write_text("time;gyro_z\n" + "\n".join(rows) + "\n")
    for reading in (
        lambda: read_table(tmp_path / "de.csv"),
        lambda: list(TableStream(tmp_path / "de.csv", chunk_rows=5).chunks()),
    ):
        with pytest.raises(InputError, match=r"de.csv: row 14 \(line 15\), column 'gyro_z': 'n.v.' is not a number"):
            reading()


def test_a_table_of_spaces_with_decimal_commas_reads_its_numbers(tmp_path):
    """Columns aligned by spaces with decimal commas (a locale's text export): told from the first lines, which
    all split by spaces alike (the commas are no separator), and read with the comma as the decimal point."""
    rows = [f"  {k / 100:8.2f}   {0.5 + k / 1000:9.4f}   {25 + k / 10:7.2f}".replace(".", ",") for k in range(30)]
    (tmp_path / "de.txt").write_text("    time     gyro_z   temperature\n" + "\n".join(rows) + "\n")
    data = read_table(tmp_path / "de.txt")
    assert (data.text_format.delimiter, data.text_format.decimal) == (" ", ",")
    np.testing.assert_allclose(data.recording.gyro_dps[:, 0], 0.5 + np.arange(30) / 1000, rtol=1e-12)
    chunks = list(TableStream(tmp_path / "de.txt", chunk_rows=7).chunks())
    np.testing.assert_array_equal(np.concatenate([c.recording.time_s for c in chunks]), data.recording.time_s)
    # a preamble of spaced words before a tab-separated header is no table of spaces
    preamble = "// Start Time: 2024 05 01\n// Update Rate: 100.0Hz\n// Filter Profile: human (46.1)\n"
    body = "time\tgyro_z\n" + "".join(f"{k / 100}\t0.5\n" for k in range(30))
    (tmp_path / "mt.txt").write_text(preamble + body)
    assert read_table(tmp_path / "mt.txt").text_format.delimiter == "\t"


@pytest.mark.parametrize("chunk_rows", [7, 10, 1000])
def test_times_of_day_run_on_past_midnight_whole_and_in_chunks(tmp_path, chunk_rows):
    """An overnight chamber run stamped with the time of day: after 23:59:59.99 comes 00:00:00.00, read as the next
    day's (the samples run on by 10 ms), whole and streamed, midnight inside a chunk or between two."""
    n = 60
    seconds = 86_400.0 - 0.3 + np.arange(n) / 100.0
    texts = [f"{int(t // 3600) % 24:02d}:{int(t % 3600 // 60):02d}:{t % 60:06.3f}" for t in seconds]
    (tmp_path / "night.csv").write_text("time,gyro_z\n" + "".join(f"{t},0.1\n" for t in texts))
    whole = read_table(tmp_path / "night.csv").recording
    np.testing.assert_allclose(whole.time_s, seconds, rtol=0, atol=1e-9)
    chunks = list(TableStream(tmp_path / "night.csv", chunk_rows=chunk_rows).chunks())
    np.testing.assert_array_equal(np.concatenate([c.recording.time_s for c in chunks]), whole.time_s)
    assert texts[29:32] == ["23:59:59.990", "00:00:00.000", "00:00:00.010"]


def test_a_column_of_vectors_is_refused_saying_so_and_init_points_to_it(tmp_path):
    """A Parquet table whose gyro is one column of 3-number lists (or of x, y, z structs), as array columns and ROS
    conversions write it: mapped, it is refused saying it holds vectors and that a column per axis is read;
    init names it beside the columns (and does not take its temperature for a file of another sensor)."""
    n = 50
    rates = np.arange(n * 3, dtype=float).reshape(n, 3) / 1000
    listed = pa.table(
        {
            "time": np.arange(n) / 100,
            "gyro": pa.FixedSizeListArray.from_arrays(pa.array(rates.ravel()), 3),
            "temperature": np.linspace(20, 30, n),
        }
    )
    pq.write_table(listed, tmp_path / "list.parquet")
    fields = pa.StructArray.from_arrays([pa.array(rates[:, k]) for k in range(3)], ["x", "y", "z"])
    pq.write_table(pa.table({"time": np.arange(n) / 100, "imu": fields}), tmp_path / "struct.parquet")
    with pytest.raises(
        InputError,
        match=r"list.parquet: column 'gyro' holds a list of 3 numbers in each row \(a vector\); gyrocomp reads one column per axis",
    ):
        read_table(tmp_path / "list.parquet", TableLayout({"gyro_z": "gyro"}))
    with pytest.raises(InputError, match=r"struct.parquet: column 'imu' holds fields x, y, z in each row \(a vector\)"):
        list(TableStream(tmp_path / "struct.parquet", TableLayout({"gyro_z": "imu"})).chunks())
    with pytest.raises(
        InputError,
        match=r"its columns are time, gyro, temperature; column 'gyro' holds a list of 3 numbers in each row \(a vector\); gyrocomp reads one column per axis: split it into x, y and z first$",
    ):
        guess_layout(tmp_path / "list.parquet")


@pytest.mark.parametrize(
    "suffix, magic", [(".gz", b"\x1f\x8b"), (".bz2", b"BZh"), (".xz", b"\xfd7zXZ"), (".zst", b"\x28\xb5\x2f\xfd")]
)
def test_a_table_written_under_a_compressed_name_is_compressed_and_reads_back(tmp_path, suffix, magic):
    """A name ending in .gz, .bz2, .xz or .zst is written compressed, whole and streamed (the matrix of shapes found
    run.csv.gz written as plain text, which every reader then refused as a damaged gzip)."""
    rec = chamber_run([20, 30, 20], ramp_degc_per_min=2, hold_s=60, seed=1)
    whole = tmp_path / f"whole.csv{suffix}"
    write_recording(rec, whole)
    assert whole.read_bytes().startswith(magic)
    back = read(whole)
    np.testing.assert_array_equal(back.gyro_dps, rec.gyro_dps)
    streamed = tmp_path / f"streamed.csv{suffix}"
    with TableWriter(streamed) as writer:
        for chunk in TableStream(whole, chunk_rows=1000).chunks():
            writer.write(chunk.table)
    assert streamed.read_bytes().startswith(magic)
    np.testing.assert_array_equal(read(streamed).gyro_dps, rec.gyro_dps)
