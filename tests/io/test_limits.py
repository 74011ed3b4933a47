"""Limits said, not suffered: a header of a million columns, a compressed file that expands to gigabytes on one
line, a Parquet file of very many row groups, an address-space limit too small for the file, a glob through a
link loop, and an input cut short while it is read each end in one line saying what was too big, or are read
once; never an internal error, a hang, an abort or a silently shorter result."""

from __future__ import annotations

import gzip
import json
import os
import resource
import subprocess

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from gyrocomp.errors import DataQualityWarning, InputError
from gyrocomp.io import resource_limits as limits
from gyrocomp.io import tables as tables_module
from gyrocomp.io.inputs import expand_inputs
from gyrocomp.io.stream import TableStream
from gyrocomp.io.tables import read_table
from gyrocomp.io.text_format import MAX_COLUMNS

from ..conftest import SCRIPT, run


def _table(path, n=2000, bias_dps=0.1):
    k = np.arange(n)
    rows = "\n".join(f"{t / 10:.1f},{bias_dps + 0.001 * t:.6f},{25 + 10 * t / n:.4f}" for t in k)
    path.write_text("time,gyro_z,temperature\n" + rows + "\n")
    return path


def _one_line(result, message):
    assert result.returncode == 2, result.stderr
    errors = [line for line in result.stderr.splitlines() if line.startswith("gyrocomp: error")]
    assert len(errors) == 1 and message in errors[0], result.stderr
    assert "Traceback" not in result.stderr and "internal error" not in result.stderr


@pytest.mark.parametrize(
    "columns, message",
    [
        (MAX_COLUMNS + 1, f"the header names {MAX_COLUMNS + 1} columns; gyrocomp reads tables of up to {MAX_COLUMNS}"),
        (200_000, "its first line is over 1 MB long, which no table's header is"),
    ],
)
def test_a_header_of_too_many_columns_is_refused_naming_the_limit(tmp_path, columns, message):
    path = tmp_path / "wide.csv"
    path.write_text(",".join(f"column{i}" for i in range(columns)) + "\n" + ",".join("1" * columns) + "\n")
    with pytest.raises(InputError, match=message):
        read_table(path)
    with pytest.raises(InputError, match=message):
        TableStream(path)
    for args in (("init", path, "-o", tmp_path / "p.toml"), ("fit", path, "-o", tmp_path / "m.json")):
        _one_line(run(*args, cwd=tmp_path), message)


def _limited(address_space_bytes):
    return lambda: resource.setrlimit(resource.RLIMIT_AS, (address_space_bytes, address_space_bytes))


@pytest.mark.slow
def test_a_gzip_that_expands_to_a_gigabyte_on_one_line_is_refused_in_bounded_memory(tmp_path):
    """1 MB of gzip holding a 1 GiB line after the header: refused as a line no table has, under a 1.5 GB
    address-space limit (before: decompressed whole first, 4 GiB reached 4.2 GB of memory)."""
    bomb = tmp_path / "bomb.csv.gz"
    with gzip.open(bomb, "wb", compresslevel=9) as fh:
        fh.write(b"time,gyro_z,temperature\n0,0.1,25\n")
        block = b"1" * (1 << 20)
        for _ in range(1024):
            fh.write(block)
    assert bomb.stat().st_size < 5 << 20
    for args in (("fit", bomb, "-o", tmp_path / "m.json"), ("init", bomb, "-o", tmp_path / "p.toml")):
        result = subprocess.run(
            [str(SCRIPT), *map(str, args)], capture_output=True, text=True, timeout=120, preexec_fn=_limited(3 << 29)
        )
        _one_line(result, "bomb.csv.gz: a line over 1 MB long, which no row of a table is")
    assert not (tmp_path / "m.json").exists()


def test_a_parquet_file_of_very_many_row_groups_is_refused_before_its_metadata_is_read(tmp_path, monkeypatch):
    path = tmp_path / "groups.parquet"
    n = 300
    pq.write_table(
        pa.table({"time": np.arange(n) / 10.0, "gyro_z": np.full(n, 0.1), "temperature": np.linspace(20, 30, n)}),
        path,
        row_group_size=1,
    )
    assert read_table(path).recording.n_samples == n
    footer = int.from_bytes(path.read_bytes()[-8:-4], "little")
    monkeypatch.setattr(tables_module, "PARQUET_FOOTER_MAX_BYTES", footer // 2)  # as a file 2x past the limit
    with pytest.raises(
        InputError,
        match=r"groups.parquet: its metadata takes .* very many small row groups\), "
        r"which would take gigabytes to read; rewrite it with larger row groups",
    ):
        read_table(path)
    with pytest.raises(InputError, match="groups.parquet: its metadata takes"):
        TableStream(path)


def test_a_file_larger_than_the_memory_left_is_refused_naming_both(tmp_path, monkeypatch):
    path = _table(tmp_path / "run.csv")
    need = limits.estimated_table_bytes(path, compressed=False)
    assert need == pytest.approx(limits.CSV_MEMORY_FACTOR * path.stat().st_size)
    monkeypatch.setattr(tables_module, "address_space_left", lambda: int(need * 2))
    monkeypatch.setattr(limits, "address_space_left", lambda: int(need * 2))
    assert read_table(path).recording.n_samples == 2000
    monkeypatch.setattr(limits, "address_space_left", lambda: int(need / 2))
    with pytest.raises(
        InputError,
        match=r"run.csv: reading it whole takes about .* GB of memory, and this process "
        r"may map .* GB more under its limit \(ulimit -v\)",
    ):
        read_table(path)


def test_too_small_an_address_space_is_one_line_not_a_hang(tmp_path):
    """Under 300 MB of address space, OpenBLAS retried its buffers for ever while loading (a hang at 100 % CPU);
    refused at once, naming the limit."""
    path = _table(tmp_path / "run.csv")
    result = subprocess.run(
        [str(SCRIPT), "fit", str(path), "-o", str(tmp_path / "m.json")],
        capture_output=True,
        text=True,
        timeout=60,
        preexec_fn=_limited(300 << 20),
    )
    _one_line(result, "this process may map 315 MB (ulimit -v); gyrocomp needs at least 1 GB")


def test_a_glob_through_a_link_loop_names_each_file_once(tmp_path):
    (tmp_path / "a").mkdir()
    for name, bias_dps in (("r1.csv", 0.1), ("r2.csv", 0.2)):  # two runs (the same one twice is refused)
        _table(tmp_path / "a" / name, bias_dps=bias_dps)
    os.symlink("..", tmp_path / "a" / "loop")
    with pytest.warns(DataQualityWarning, match=r"name\(s\) matched are files already named by another path"):
        found = expand_inputs([str(tmp_path / "a" / "**" / "*.csv")])
    assert found == [tmp_path / "a" / "r1.csv", tmp_path / "a" / "r2.csv"]
    result = run(
        "fit",
        str(tmp_path / "a" / "**" / "*.csv"),
        "-o",
        tmp_path / "m.json",
        "--temperature",
        "poly:1",
        "--hysteresis",
        "none",
        cwd=tmp_path,
    )
    assert result.returncode == 0, result.stderr
    assert "files already named by another path" in result.stderr
    inputs = json.loads((tmp_path / "m.json").read_text())["provenance"]["inputs"]
    assert [entry["file"] for entry in inputs] == ["r1.csv", "r2.csv"]  # each run once (before: 40 times)


def test_a_table_cut_short_while_it_is_read_is_refused_not_read_shorter(tmp_path):
    path = _table(tmp_path / "run.csv", n=5000)
    stream = TableStream(path, chunk_rows=500)
    chunks = stream.chunks()
    next(chunks)
    with open(path, "r+b") as fh:  # another program cuts the file while the first chunk is used
        fh.truncate(path.stat().st_size // 2)
    with pytest.raises(
        InputError,
        match=r"run.csv: changed while it was read \(\d+ bytes when the reading began, "
        r"\d+ at its end: still being written, or cut short\); nothing written",
    ):
        list(chunks)


def test_a_parquet_file_replaced_while_it_is_read_is_said_to_have_changed_not_to_be_damaged(tmp_path, monkeypatch):
    """pyarrow opens a Parquet file by path more than once (its metadata, its schema, its table): another program
    replacing it in between makes the read fail part way ("couldn't deserialize thrift"); the refusal says the file
    changed, not that it is unreadable."""
    path = tmp_path / "run.parquet"
    pq.write_table(pa.table({"time": np.arange(100.0), "gyro_z": np.zeros(100)}), path)
    read_arrow = tables_module.read_arrow

    def replaced_part_way(*args):
        other = tmp_path / "other.parquet"
        pq.write_table(pa.table({"time": np.arange(50.0), "gyro_z": np.ones(50)}), other)
        os.replace(other, path)  # another program's atomic write lands while the file is read
        read_arrow(tmp_path / "missing.parquet", *args[1:])  # and the read fails part way

    monkeypatch.setattr(tables_module, "read_arrow", replaced_part_way)
    with pytest.raises(InputError, match=r"run.parquet: changed while it was read \(.*\); nothing written from it"):
        read_table(path)
