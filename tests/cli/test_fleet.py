"""``gyrocomp fleet`` through the real entry point: bad options in one line (the fleet's own runs through the
command line, on a simulated fleet, are in tests/fleet)."""

import pytest

from ..conftest import run


@pytest.mark.slow
def test_fleet_fit_refuses_bad_options_in_one_line(tmp_path):
    (tmp_path / "SN1").mkdir()
    (tmp_path / "SN1" / "run_0.csv").write_text("content of SN1/run_0.csv")
    no_units = run("fleet", "fit", tmp_path, "-o", tmp_path / "out")
    assert no_units.returncode == 2 and "give --unit-from PATTERN or --manifest FILE" in no_units.stderr
    (tmp_path / "limits.toml").write_text("[noise]\nmax = 1\n")
    bad = run(
        "fleet",
        "fit",
        tmp_path,
        "--unit-from",
        "{serial}/run_{n}.csv",
        "-o",
        tmp_path / "out",
        "--limits",
        tmp_path / "limits.toml",
    )
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "[noise]: unknown figure" in bad.stderr
    assert not (tmp_path / "out").exists()
    every = run(
        "fleet", "fit", tmp_path, "--unit-from", "{serial}/run_{n}.csv", "-o", tmp_path / "out", "--scheduler", "serial"
    )
    assert every.returncode == 2 and "every unit failed (e.g. SN1:" in every.stderr
    assert (tmp_path / "out" / "calibrations.sqlite").exists()  # the failure is on record
    nowhere = run(
        "fleet",
        "fit",
        tmp_path,
        "--unit-from",
        "{serial}/run_{n}.csv",
        "-o",
        tmp_path / "out2",
        "--scheduler",
        "tcp://127.0.0.1:9",
    )
    assert (
        nowhere.returncode == 2
        and "--scheduler: cannot reach a Dask scheduler at 'tcp://127.0.0.1:9'" in nowhere.stderr
    )
