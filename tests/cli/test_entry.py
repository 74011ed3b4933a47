"""The suite's way of running the command (tests/conftest.py's ``run``: forked from the test process, its libraries
loaded) against the console script in a new interpreter, as a user runs it: the same files, output and status."""

import re

import pytest

from ..conftest import run

#: the one thing two runs of a fit may write differently: when it was made
_CREATED = re.compile(r'"created_utc": "[^"]*"')


def _both(tmp_path, *args):
    """The command run both ways, each in a folder of its own (its working directory, the paths relative)."""
    done = []
    for way, fresh in (("fork", False), ("anew", True)):
        (tmp_path / way).mkdir(exist_ok=True)
        done.append(run(*args, cwd=tmp_path / way, fresh=fresh))
    return done


def _same(forked, fresh):
    assert (forked.returncode, forked.stdout, forked.stderr) == (fresh.returncode, fresh.stdout, fresh.stderr)


@pytest.mark.slow
def test_a_simulated_fit_and_its_use_are_the_same_forked_and_in_a_new_interpreter(tmp_path):
    for seed in (1, 2):
        _same(*_both(tmp_path, "simulate", "--duration", 600, "--rate", 10, "--seed", seed, "-o", f"r{seed}.csv"))
    for seed in (1, 2):
        assert (tmp_path / "fork" / f"r{seed}.csv").read_bytes() == (tmp_path / "anew" / f"r{seed}.csv").read_bytes()
    fit = _both(tmp_path, "fit", "r1.csv", "r2.csv", "-o", "m.json")
    _same(*fit)
    assert "warning" in fit[0].stderr  # two legs only: the model choice warns, both ways alike
    model = [_CREATED.sub("", (tmp_path / way / "m.json").read_text()) for way in ("fork", "anew")]
    assert model[0] == model[1]
    _same(*_both(tmp_path, "apply", "m.json", "r1.csv", "-o", "c.csv"))
    assert (tmp_path / "fork" / "c.csv").read_bytes() == (tmp_path / "anew" / "c.csv").read_bytes()
    _same(*_both(tmp_path, "evaluate", "m.json", "r2.csv"))


def test_an_error_is_the_same_line_and_status_forked_and_in_a_new_interpreter(tmp_path):
    forked, fresh = _both(tmp_path, "fit", "missing.csv", "-o", "m.json")
    _same(forked, fresh)
    assert forked.returncode == 2 and forked.stderr.count("\n") == 1
    assert not list(tmp_path.rglob("m.json"))


def test_the_version_and_the_help_are_the_same_forked_and_in_a_new_interpreter(tmp_path):
    _same(*_both(tmp_path, "--version"))
    _same(*_both(tmp_path, "--help"))
