"""Start-up (#21): the package and the command line's help load without the numeric stack; the lazily loaded
public names all resolve; the command table matches the commands."""

from __future__ import annotations

import subprocess
import sys

import click
import pytest

import gyrocomp
from gyrocomp.cli import COMMANDS, cli
from gyrocomp.simulate import simulate as simulate_function

from .conftest import run


def _modules_after(code: str) -> set[str]:
    out = subprocess.run([sys.executable, "-c", f"{code}; import sys; print(' '.join(sys.modules))"],
                         capture_output=True, text=True, check=True).stdout
    return set(out.split())


def test_import_and_help_do_not_load_numpy_scipy_or_pandas():
    for code in ("import gyrocomp", "import gyrocomp.cli"):
        loaded = _modules_after(code)
        assert not {"numpy", "scipy", "pandas", "matplotlib"} & loaded, code
    result = run("--help")
    assert result.returncode == 0 and all(name in result.stdout for name in COMMANDS)
    assert run("--version").stdout.startswith("gyrocomp, version")


def test_every_public_name_resolves_and_simulate_stays_the_function():
    for name in gyrocomp.__all__:
        assert getattr(gyrocomp, name) is not None, name
    assert gyrocomp.simulate is simulate_function  # the subpackage of that name was imported above
    assert gyrocomp.fit is gyrocomp.fit_calibration
    assert set(gyrocomp.__all__) <= set(dir(gyrocomp))
    with pytest.raises(AttributeError, match="module 'gyrocomp' has no attribute 'no_such_name'"):
        getattr(gyrocomp, "no_such_name")


def test_the_command_table_matches_the_commands():
    ctx = click.Context(cli)
    for name, (_, text) in COMMANDS.items():
        command = cli.get_command(ctx, name)
        assert command is not None and command.get_short_help_str(limit=1000) == text, name
    assert cli.get_command(ctx, "nothing") is None
    result = run("nothing")
    assert result.returncode == 2 and "No such command 'nothing'" in result.stderr
