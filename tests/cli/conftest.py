"""The command line's tests: runs and a model made with the CLI itself, shared by the modules."""

import pytest

from ..conftest import run


@pytest.fixture(scope="session")
def workdir(tmp_path_factory):
    """Three simulated chamber runs and a model fitted on two of them, made with the CLI itself."""
    d = tmp_path_factory.mktemp("cli")
    for seed in (1, 2, 3):
        r = run(
            "simulate",
            "--profile",
            "chamber",
            "--duration",
            1200,
            "--rate",
            10,
            "--seed",
            seed,
            "-o",
            d / f"run{seed}.csv",
            "--truth",
            d / f"truth{seed}.json",
        )
        assert r.returncode == 0, r.stderr
    r = run("fit", d / "run1.csv", d / "run2.csv", "-o", d / "model.json", "--temperature", "poly:3")
    assert r.returncode == 0, r.stderr
    return d


@pytest.fixture(scope="session")
def static_log(tmp_path_factory):
    d = tmp_path_factory.mktemp("allan")
    r = run("simulate", "--profile", "static", "--duration", 1800, "--rate", 20, "--axes", "x,z", "-o", d / "s.csv")
    assert r.returncode == 0, r.stderr
    return d


@pytest.fixture(scope="session")
def report_files(tmp_path_factory):
    """Two simulated one-hour runs of the mti10 preset and a model fitted on the first, made with the CLI."""
    d = tmp_path_factory.mktemp("report")
    for seed in (1, 2):
        r = run(
            "simulate",
            "--preset",
            "mti10",
            "--profile",
            "combined",
            "--duration",
            3600,
            "--rate",
            1,
            "--seed",
            seed,
            "-o",
            d / f"run{seed}.csv",
        )
        assert r.returncode == 0, r.stderr
    r = run("fit", d / "run1.csv", "-o", d / "model.json", "--hysteresis", "none")
    assert r.returncode == 0, r.stderr
    return d


def assert_refused_in_one_line(args: list[str], message: str, folder) -> None:
    """The command (its arguments with ``{d}`` for ``folder``) exits 2 with one error line holding ``message``
    and no traceback."""
    r = run(*[a.format(d=folder) for a in args])
    assert r.returncode == 2
    errors = [line for line in r.stderr.splitlines() if line.startswith("gyrocomp: error")]
    assert len(errors) == 1 and message.format(d=folder) in errors[0], r.stderr
    assert "Traceback" not in r.stderr
