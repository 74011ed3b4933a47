"""Start-up (#21): the package and the command line's help load without the numeric stack; the lazily loaded
public names all resolve; the command table matches the commands."""

from __future__ import annotations

import inspect
import subprocess
import sys

import click
import pytest

import gyrocomp
from gyrocomp.cli import COMMANDS, cli
from gyrocomp.simulation import simulate as simulate_function

from .conftest import run


def _modules_after(code: str) -> set[str]:
    out = subprocess.run(
        [sys.executable, "-c", f"{code}; import sys; print(' '.join(sys.modules))"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    return set(out.split())


def test_import_and_help_do_not_load_numpy_scipy_or_pandas():
    for code in ("import gyrocomp", "import gyrocomp.cli"):
        loaded = _modules_after(code)
        assert not {"numpy", "scipy", "pandas", "matplotlib"} & loaded, code
    result = run("--help")
    assert result.returncode == 0 and all(name in result.stdout for name in COMMANDS)
    assert run("--version").stdout.startswith("gyrocomp, version")


def test_each_command_starts_without_scipy_pandas_or_matplotlib():
    """A command's module (what ``gyrocomp CMD --help`` or a run imports before any work) loads none of them:
    scipy alone took 0.15 s of every command's start (its array API layer imports numpy.testing and f2py), so it
    is imported where it is used. The fleet's commands open a store (SQLAlchemy) and build tables (pandas)."""
    code = (
        "import click, sys; from gyrocomp.cli import cli, COMMANDS; ctx = click.Context(cli)\n"
        "for name in COMMANDS:\n"
        "    seen = set(sys.modules); cli.get_command(ctx, name)\n"
        "    heavy = {m.split('.')[0] for m in set(sys.modules) - seen} & {'scipy', 'pandas', 'matplotlib'}\n"
        "    print(name, *sorted(heavy))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    loaded = {name: rest for name, *rest in map(str.split, out.splitlines())}
    assert set(loaded) == set(COMMANDS)
    assert {name: heavy for name, heavy in loaded.items() if heavy} == {"fleet": ["pandas"]}


def test_every_public_name_resolves_and_simulate_stays_the_function():
    for name in gyrocomp.__all__:
        assert getattr(gyrocomp, name) is not None, name
    assert gyrocomp.simulate is simulate_function  # the function, whatever was imported before
    from gyrocomp.models.fit import fit

    assert gyrocomp.fit is fit  # the one entry point; fit_calibration is the keyword form beside it
    assert set(gyrocomp.__all__) <= set(dir(gyrocomp))
    with pytest.raises(AttributeError, match="module 'gyrocomp' has no attribute 'no_such_name'"):
        gyrocomp.no_such_name  # noqa: B018


def test_every_public_callable_spells_out_its_parameters():
    """No ``*args`` or ``**options`` in the public API: each option is a named, documented parameter."""
    hidden = []
    for name in gyrocomp.__all__:
        obj = getattr(gyrocomp, name)
        if not callable(obj) or isinstance(obj, type) and issubclass(obj, BaseException):
            continue
        target = obj.__init__ if isinstance(obj, type) else obj
        parameters = inspect.signature(target).parameters.values()
        hidden += [f"{name}({p})" for p in parameters if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]
    assert hidden == []


def test_the_command_table_matches_the_commands():
    ctx = click.Context(cli)
    for name, (_, text) in COMMANDS.items():
        command = cli.get_command(ctx, name)
        assert command is not None and command.get_short_help_str(limit=1000) == text, name
    assert cli.get_command(ctx, "nothing") is None
    result = run("nothing")
    assert result.returncode == 2 and "No such command 'nothing'" in result.stderr


def test_apply_and_convert_of_a_table_do_not_load_pandas(tmp_path):
    """pyarrow imports pandas (a third of a second) the first time it converts to or from numpy its own way; the
    table readers and writers read and build the columns' buffers directly, nulls and whole numbers included."""
    rec = simulate_function("mti10", profile="chamber", rate_hz=1, duration_s=1800, seed=1).recording
    gyrocomp.fit_calibration([rec], temperature=gyrocomp.Polynomial(1), hysteresis="none").save(tmp_path / "model.json")
    gyrocomp.write(rec, tmp_path / "run.csv")
    lines = (tmp_path / "run.csv").read_text().splitlines()
    lines[0] += ",count"
    lines[1:] = [line + f",{i}" for i, line in enumerate(lines[1:])]
    cells = lines[5].split(",")
    cells[1] = ""  # an empty gyro cell: a null in the column
    lines[5] = ",".join(cells)
    (tmp_path / "run.csv").write_text("\n".join(lines) + "\n")
    code = (
        "from gyrocomp.cli import main; "
        f"assert main(['-q', 'apply', r'{tmp_path / 'model.json'}', r'{tmp_path / 'run.csv'}', '--drop-nan', "
        f"'-o', r'{tmp_path / 'out.parquet'}']) == 0; "
        f"assert main(['-q', 'convert', r'{tmp_path / 'out.parquet'}', r'{tmp_path / 'back.csv'}']) == 0"
    )
    assert "pandas" not in _modules_after(code)
    back = gyrocomp.read(tmp_path / "back.csv")
    assert back.n_samples == rec.n_samples - 1
