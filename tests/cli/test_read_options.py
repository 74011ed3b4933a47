"""The reading options every command shares (columns, units, delimiters), run through the real entry point in a
subprocess."""

import importlib

import click
import numpy as np
import pandas as pd

from gyrocomp.cli import COMMANDS
from gyrocomp.cli.projectfile import ReadingOption
from gyrocomp.io import ReadOptions
from gyrocomp.option_spelling import spelled_fields

from ..conftest import run


def test_mapping_and_units_through_cli(workdir, tmp_path):
    df = pd.read_csv(workdir / "run3.csv")
    vendor = pd.DataFrame({"Stamp": df["time"] * 1000, "GyrZ": np.deg2rad(df["gyro_z"]), "T": df["temperature"]})
    vendor.to_csv(tmp_path / "vendor.csv", index=False)
    r = run(
        "apply",
        workdir / "model.json",
        tmp_path / "vendor.csv",
        "-o",
        tmp_path / "v_out.csv",
        "--columns",
        "time=Stamp,gyro_z=GyrZ,temperature=T",
        "--gyro-unit",
        "rad/s",
        "--time-unit",
        "ms",
    )
    assert r.returncode == 0, r.stderr
    ours = pd.read_csv(tmp_path / "v_out.csv")
    theirs = run("apply", workdir / "model.json", workdir / "run3.csv", "-o", tmp_path / "d_out.csv")
    assert theirs.returncode == 0
    np.testing.assert_allclose(np.rad2deg(ours["GyrZ"]), pd.read_csv(tmp_path / "d_out.csv")["gyro_z"], atol=1e-12)


def test_a_tab_separated_export_with_decimal_commas_reads_with_or_without_options(tmp_path):
    (tmp_path / "v.txt").write_text("Time\tGyro_Z\tTemperature\n0\t1,5\t20,5\n1\t2,5\t21\n2\t3\t22\n")
    for extra, sep, decimal in (([], ",", "."), (["--delimiter", "tab", "--decimal", ","], "\t", ",")):
        r = run("convert", tmp_path / "v.txt", tmp_path / "o.csv", *extra)
        assert r.returncode == 0, r.stderr
        # the canonical columns; a .csv name gets commas, unless the options named the input's format (then that,
        # so that the next command given them reads it as it read v.txt)
        out = pd.read_csv(tmp_path / "o.csv", sep=sep, decimal=decimal)
        assert list(out["gyro_z"]) == [1.5, 2.5, 3.0] and list(out["temperature"]) == [20.5, 21.0, 22.0]
    r = run("convert", tmp_path / "v.txt", tmp_path / "o.csv", "--decimal", ":")
    assert r.returncode == 2 and r.stderr.strip() == "gyrocomp: error: --decimal: ':'; use '.' or ','"


def test_every_command_that_reads_data_has_the_reading_options_of_the_library():
    """The reading options are made from ReadOptions' fields: each command that reads has all of them, under the
    field's name; and across every command one parameter name has one flag (the message wording relies on it)."""
    flags_by_name: dict[str, set[str]] = {}
    readers = 0
    for name, (module, _) in COMMANDS.items():
        command = getattr(importlib.import_module(f"gyrocomp.cli.{module}"), name)
        for cmd in [command, *getattr(command, "commands", {}).values()]:
            options = [p for p in cmd.params if isinstance(p, click.Option)]
            for option in options:
                flags_by_name.setdefault(option.name, set()).add(max(option.opts, key=len))
            reading = {o.name: max(o.opts, key=len) for o in options if isinstance(o, ReadingOption)}
            if reading:
                readers += 1
                assert reading == {"fmt": "--format", **{f.name: s.flag for f, s in spelled_fields(ReadOptions)}}, (
                    cmd.name
                )
    assert readers >= 10
    assert {n: f for n, f in flags_by_name.items() if len(f) > 1} == {}
    assert flags_by_name["drop_nonfinite"] == {"--drop-nan"} and flags_by_name["time_range_s"] == {"--time"}


def test_a_bad_reading_option_is_one_line_naming_the_flag(workdir, tmp_path):
    for flag, value, said in [
        ("--time", "1:x", "--time: '1:x': give A:B"),
        ("--instance", "all", "--instance: all is for gyrocomp fit"),
        ("--device-id", "-3", "--device-id: -3: give a whole number >= 0"),
    ]:
        r = run("apply", workdir / "model.json", workdir / "run3.csv", "-o", tmp_path / "o.csv", flag, value)
        assert r.returncode == 2 and r.stderr.strip().startswith(f"gyrocomp: error: {said}"), r.stderr
        assert len(r.stderr.strip().splitlines()) == 1 and not (tmp_path / "o.csv").exists()


def test_the_project_file_read_section_takes_the_reading_options_of_the_command(workdir, tmp_path):
    (tmp_path / "gyrocomp.toml").write_text("[read]\ndrop-nan = true\nwindoww = 3\n")
    r = run("apply", workdir / "model.json", workdir / "run3.csv", "-o", tmp_path / "o.csv", cwd=tmp_path)
    assert r.returncode == 2 and "[read] windoww: not a reading option; use accel-unit, columns" in r.stderr


def test_the_project_file_in_use_is_named_once_with_what_it_sets(workdir, tmp_path):
    """A gyrocomp.toml left in a folder changes what every command there reads: the command says so, once, on
    stderr, naming the options it set; an option given on the command line (a switch's off form too) wins and is
    not named; --quiet and --help say nothing."""
    (tmp_path / "gyrocomp.toml").write_text('[read]\ndrop-nan = true\n[apply]\naxes = "gyro_z"\n')
    args = ("apply", workdir / "model.json", workdir / "run3.csv", "-o", tmp_path / "o.csv")
    r = run(*args, cwd=tmp_path)
    notes = [line for line in r.stderr.splitlines() if line.startswith("gyrocomp: note:")]
    assert r.returncode == 0 and notes == [
        "gyrocomp: note: gyrocomp.toml sets --axes, --drop-nan (an "
        "option on the command line wins; gyrocomp config show prints the "
        "file)"
    ], r.stderr
    r = run(*args, "--no-drop-nan", "--axes", "gyro_z", cwd=tmp_path)
    assert r.returncode == 0 and "gyrocomp: note" not in r.stderr, r.stderr
    assert "gyrocomp: note" not in run("-q", *args, cwd=tmp_path).stderr
    assert "gyrocomp: note" not in run("apply", "--help", cwd=tmp_path).stderr


def test_a_project_file_cannot_switch_on_what_the_command_line_could_not_switch_off(workdir, tmp_path):
    (tmp_path / "gyrocomp.toml").write_text("[allan]\njson = true\n")
    r = run("allan", workdir / "run3.csv", cwd=tmp_path)
    assert r.returncode == 2 and r.stderr.strip() == (
        "gyrocomp: error: gyrocomp.toml: json = true: a switch the command line could not turn off again; give "
        "--json when running gyrocomp allan"
    ), r.stderr
