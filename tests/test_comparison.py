"""The thesis's comparison of methods on one data set, from the library and the command line."""

import json

import pytest

from gyrocomp.comparison import DEFAULT_METHODS, compare_methods
from gyrocomp.errors import InputError
from gyrocomp.simulate import get_profile, simulate
from tests.test_cli import run


@pytest.fixture(scope="module")
def cycles():
    """Two ADXRS450 cycles at 1 Hz: lag, and hysteresis on cooling between 55 and 80 degC."""
    prof = get_profile("cycle", set_points_degc=(-30.0, 80.0), cycles=1)
    return [simulate("adxrs450", profile=prof, rate_hz=1.0, seed=s) for s in range(2)]


def test_leave_one_run_out_table_has_every_method_and_hysteresis_helps(cycles):
    result = compare_methods([s.recording for s in cycles], hysteresis_band_degc=(55.0, 80.0), window_s=100.0)
    assert result.how.startswith("leave one run out")
    rows = {r.method: r for r in result.rows}
    assert list(rows) == ["raw", *DEFAULT_METHODS]
    assert rows["raw"].improvement == 1.0
    # the preset's 0.2 deg/s hysteresis: compensating it must shrink the offset left by the polynomial
    assert rows["polynomial + hysteresis"].bias_offset_dps < 0.7 * rows["polynomial"].bias_offset_dps
    assert rows["network + hysteresis"].bias_offset_dps < 0.7 * rows["network"].bias_offset_dps
    for r in result.rows[1:]:
        assert r.improvement == pytest.approx(rows["raw"].bias_offset_dps / r.bias_offset_dps)
        assert r.improvement > 3
    assert rows["gyrocomp default (auto)"].bias_offset_dps <= 1.05 * rows["polynomial + hysteresis"].bias_offset_dps


def test_one_run_is_scored_on_itself_and_says_so(cycles):
    result = compare_methods([cycles[0].recording], methods={"polynomial": {"temperature": 2, "hysteresis": "none"}},
                             window_s=100.0)
    assert "fitted and scored on the same run" in result.how
    assert [r.method for r in result.rows] == ["raw", "polynomial"]
    with pytest.raises(InputError, match="compare: give at least one run"):
        compare_methods([])


def test_cli_compare(tmp_path):
    r = run("simulate", "--preset", "adxrs450", "--profile", "cycle", "--cycles", 1, "--rate", 1, "--runs", 2,
            "--duration", 6000, "-o", tmp_path / "c.csv")
    assert r.returncode == 0, r.stderr
    r = run("evaluate", "--compare", tmp_path / "c_0.csv", tmp_path / "c_1.csv", "--window", 60, "--json")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert {row["method"] for row in d["rows"]} == {"raw", *DEFAULT_METHODS}
    r = run("evaluate", "--compare", tmp_path / "c_0.csv", tmp_path / "c_1.csv", "--window", 60)
    assert r.returncode == 0, r.stderr
    assert "methods compared (leave one run out" in r.stdout and "network + hysteresis" in r.stdout
    r = run("evaluate", tmp_path / "c_0.csv")
    assert r.returncode == 2 and "give MODEL and at least one run, or --compare RUNS..." in r.stderr
    r = run("evaluate", "--compare", tmp_path / "c_0.csv", "--hysteresis-band", "9")
    assert r.returncode == 2 and "Invalid value for --hysteresis-band" in r.stderr
