"""The thesis's comparison of methods on one data set, from the library and the command line."""

import json
import warnings

import numpy as np
import pytest

from gyrocomp import FitOptions, Network, Polynomial, apply
from gyrocomp.evaluation.comparison import (
    ARDUPILOT_TEMP_REF_DEGC,
    DEFAULT_METHODS,
    compare_methods,
    fit_method,
    fit_ardupilot_style,
    fit_px4_style,
)
from gyrocomp.errors import InputError, TemperatureRangeWarning
from gyrocomp.recording import Recording
from gyrocomp.simulation import get_profile, simulate
from ..conftest import run


@pytest.fixture(scope="module")
def cycles():
    """Two ADXRS450 cycles at 1 Hz: lag, and hysteresis on cooling between 55 and 80 degC."""
    prof = get_profile("cycle", set_points_degc=(-30.0, 80.0), cycles=1)
    return [simulate("adxrs450", profile=prof, rate_hz=1.0, seed=s) for s in range(2)]


@pytest.mark.slow
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
    # what the autopilots' tools fit is a cubic in the reported temperature: lag and hysteresis stay in the output
    for autopilot in ("PX4 cubic (process_sensor_caldata.py)", "ArduPilot cubic (tempcal_IMU.py)"):
        assert rows["gyrocomp default (auto)"].bias_offset_dps < 0.5 * rows[autopilot].bias_offset_dps


def test_one_run_is_scored_on_itself_and_says_so(cycles):
    result = compare_methods(
        [cycles[0].recording],
        methods={"polynomial": FitOptions(temperature=Polynomial(2), hysteresis="none")},
        window_s=100.0,
    )
    assert "fitted and scored on the same run" in result.how
    assert [r.method for r in result.rows] == ["raw", "polynomial"]
    with pytest.raises(InputError, match="compare: give at least one run"):
        compare_methods([])
    with pytest.raises(InputError, match=r"methods: FitOptions or a function of the training runs, got dict"):
        compare_methods([cycles[0].recording], methods={"polynomial": {"temperature": 2}}, window_s=100.0)


@pytest.mark.slow
def test_cli_compare(tmp_path):
    r = run(
        "simulate",
        "--preset",
        "adxrs450",
        "--profile",
        "cycle",
        "--cycles",
        1,
        "--rate",
        1,
        "--runs",
        2,
        "--duration",
        6000,
        "-o",
        tmp_path / "c.csv",
    )
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


def _cubic_run(temperature_degc, rate_hz=10.0):
    """A run whose gyro is exactly 0.02 + 1e-3 d - 2e-5 d^2 + 3e-7 d^3 [deg/s], d = T - 30, no noise."""
    d = temperature_degc - 30.0
    gyro = 0.02 + 1e-3 * d - 2e-5 * d**2 + 3e-7 * d**3
    n = temperature_degc.size
    return Recording(
        time_s=np.arange(n) / rate_hz, gyro_dps=gyro[:, None], gyro_axes=("gyro_z",), temperature_degc=temperature_degc
    )


def _expected(temperature_degc):
    d = np.clip(temperature_degc, -20.0, 80.0) - 30.0
    return 1e-3 * d - 2e-5 * d**2 + 3e-7 * d**3


def test_autopilot_cubics_recover_an_exact_cubic_and_clamp_like_the_firmware():
    """Plateaus at both ends keep the median filter's zero padding (PX4) and the moving average's edges
    (ArduPilot) exact; inside, bin means and 2 s averages of a slow ramp sit on the cubic to second order."""
    temperature = np.concatenate([np.full(200, -20.0), np.linspace(-20.0, 80.0, 60_000), np.full(200, 80.0)])
    run = _cubic_run(temperature)
    beyond = _cubic_run(np.linspace(-40.0, 100.0, 5000))
    for fit in (fit_px4_style, fit_ardupilot_style):
        cal = fit([run])
        curve = cal.axes["gyro_z"].temperature
        assert curve.order == 3 and (curve.t_min_degc, curve.t_max_degc) == pytest.approx((-20.0, 80.0), abs=1e-6)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", TemperatureRangeWarning)
            comp = apply(cal, beyond).gyro_dps[:, 0]
        # compensated = gyro - P(clip(T)) + P(T0)-type constant: what remains is the cubic outside the range only
        left = beyond.gyro_dps[:, 0] - _expected(beyond.temperature_degc)
        np.testing.assert_allclose(comp - comp.mean(), left - left.mean(), atol=2e-6)
    assert fit_px4_style([run]).axes["gyro_z"].temperature.t_ref_degc == pytest.approx(30.0)
    assert fit_ardupilot_style([run]).axes["gyro_z"].temperature.t_ref_degc == ARDUPILOT_TEMP_REF_DEGC


def test_a_method_keeps_its_own_network_seed_unless_one_is_given():
    runs = [simulate("mti10", profile="chamber", rate_hz=0.5, duration_s=3600, seed=s).recording for s in range(2)]
    method = FitOptions(temperature=Network((2,), seed=11), hysteresis="none", acceleration="none")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert fit_method(method, runs).report.network.seed == 11
        assert fit_method(method, runs, seed=3).report.network.seed == 3
