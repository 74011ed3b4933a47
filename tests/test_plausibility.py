"""Plausibility checks: unit mistakes and the wrong kind of data are said, never silently fitted."""

import dataclasses
import warnings

import numpy as np
import pytest

from gyrocomp import Polynomial, apply, comparison, fit_calibration, validation, write
from gyrocomp.errors import DataQualityWarning, InputError, PlausibilityWarning
from gyrocomp.plausibility import (
    CHECKS,
    calibration_concerns,
    recording_concerns,
    silence_pattern,
    temperature_span_concern,
    turned_between_poses,
)
from gyrocomp.recording import Recording
from gyrocomp.simulate import simulate

from .conftest import run, xsens_session

RUN = simulate("mti10", profile="chamber", duration_s=1800, rate_hz=2, seed=1).recording


def _checks(concerns):
    return [c.check for c in concerns]


def test_a_clean_calibration_run_raises_no_concern():
    assert calibration_concerns(RUN) == []
    # turning between positions (moves recorded) is not rotation: a 10 s mean is the angle turned / 10 s
    tumble = simulate("consumer", profile="tumble", rate_hz=10, seed=2).recording
    assert "rotation" not in _checks(calibration_concerns(tumble))


def test_kelvin_looking_temperatures():
    kelvin = dataclasses.replace(RUN, temperature_degc=RUN.temperature_degc + 273.15)
    (concern,) = recording_concerns(kelvin)
    assert concern.check == "kelvin" and "looks like kelvin; gyrocomp reads degC" in concern.message


def _still(rate_hz, n, time_factor=1.0):
    t = np.arange(n) / rate_hz
    return Recording(time_s=t * time_factor, gyro_dps=np.zeros((n, 1)), gyro_axes=("gyro_z",),
                     temperature_degc=np.linspace(20.0, 30.0, n), source="t.csv")


def test_time_in_another_unit():
    # 10 Hz with the time in ms read as s: 0.01 Hz for 116 days
    (concern,) = recording_concerns(_still(10.0, 100_000, time_factor=1000.0))
    assert concern.check == "time-unit" and concern.message == "t.csv: 116 days at 0.01 Hz: is the time column in ms read as s?"
    # 100 Hz with the time in s read as ms: 100 kHz
    (concern,) = recording_concerns(_still(100.0, 1000, time_factor=1e-3))
    assert concern.message.startswith("t.csv: 1e+05 Hz is no IMU's sample rate")
    assert recording_concerns(_still(100.0, 1000)) == []


def test_values_beyond_any_mems_range():
    gyro = RUN.gyro_dps.copy()
    gyro[10, 0] = 6e31
    (concern,) = recording_concerns(dataclasses.replace(RUN, gyro_dps=gyro))
    assert concern.check == "rate" and "6e+31 deg/s, beyond any MEMS gyro's range" in concern.message


def test_a_rate_table_run_is_rotation_and_a_large_offset_is_said():
    gyro = RUN.gyro_dps.copy()
    gyro[100:400, 2] += 100.0  # 150 s at 100 deg/s about z, still before and after
    checks = _checks(calibration_concerns(dataclasses.replace(RUN, gyro_dps=gyro)))
    assert checks == ["rotation"]
    spinning = dataclasses.replace(RUN, gyro_dps=RUN.gyro_dps + 80.0)
    assert _checks(calibration_concerns(spinning)) == ["offset"] * 3


def test_a_curve_asked_for_on_runs_at_one_temperature():
    flat = dataclasses.replace(RUN, temperature_degc=np.full(RUN.n_samples, 25.0))
    assert calibration_concerns(flat) == [] and temperature_span_concern([RUN, flat]) is None
    concern = temperature_span_concern([flat, flat])
    assert concern.check == "temperature-span" and "every run spans at most 0 degC" in concern.message
    with pytest.warns(PlausibilityWarning, match=r"every run spans at most 0 degC"):
        fit_calibration([flat, flat], temperature=Polynomial(2))


def test_fit_and_apply_warn_and_the_warning_can_be_silenced():
    kelvin = dataclasses.replace(RUN, temperature_degc=RUN.temperature_degc + 273.15)
    with pytest.warns(PlausibilityWarning, match=r"looks like kelvin"):
        cal = fit_calibration([kelvin], temperature=Polynomial(2))
    with pytest.warns(PlausibilityWarning, match=r"looks like kelvin"):
        apply(cal, kelvin)
    assert issubclass(PlausibilityWarning, DataQualityWarning)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.filterwarnings("ignore", category=PlausibilityWarning)
        warnings.filterwarnings("ignore", category=DataQualityWarning)
        apply(cal, kelvin)


@pytest.mark.parametrize("what, call", [("compare", "compare_methods"), ("validate", "validate")])
def test_comparing_temperature_models_on_flat_runs_is_refused_in_one_line(what, call):
    flat = [dataclasses.replace(RUN, temperature_degc=np.full(RUN.n_samples, 25.0), source=f"flat{k}.csv")
            for k in range(3)]
    function = getattr(comparison if call == "compare_methods" else validation, call)
    with pytest.raises(InputError, match=rf"flat0.csv: the temperature of every run spans at most 0 degC; {what} "
                                         "compares temperature models"):
        function(flat)


def test_one_check_is_silenced_by_its_name_and_the_others_still_speak():
    kelvin = dataclasses.replace(RUN, temperature_degc=RUN.temperature_degc + 273.15)
    spinning = dataclasses.replace(kelvin, gyro_dps=kelvin.gyro_dps + 80.0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        warnings.filterwarnings("ignore", message=silence_pattern("kelvin"), category=PlausibilityWarning)
        fit_calibration([spinning], temperature=Polynomial(2))
    found = [w.message for w in caught if isinstance(w.message, PlausibilityWarning)]
    assert {w.check for w in found} == {"offset"} and len(found) == 3
    assert all(str(w).endswith("(check 'offset')") for w in found)
    with pytest.raises(InputError, match=r"check: unknown plausibility check 'kelvins'; use one of rate, kelvin"):
        silence_pattern("kelvins")
    assert set(CHECKS) >= {"rate", "kelvin", "time-unit", "offset", "rotation", "temperature-span"}


def test_cli_allow_silences_one_check(tmp_path):
    kelvin = dataclasses.replace(RUN, temperature_degc=RUN.temperature_degc + 273.15)
    path = tmp_path / "k.csv"
    write(kelvin, path)
    said = run("fit", path, "-o", tmp_path / "m.json", "--temperature", "poly:2")
    assert said.returncode == 0 and "looks like kelvin" in said.stderr and "(check 'kelvin')" in said.stderr
    quiet = run("--allow", "kelvin", "fit", path, "-o", tmp_path / "m2.json", "--temperature", "poly:2")
    assert quiet.returncode == 0 and "kelvin" not in quiet.stderr, quiet.stderr
    bad = run("--allow", "kelvins", "fit", path, "-o", tmp_path / "m3.json")
    assert bad.returncode == 2 and "'kelvins' is not one of" in bad.stderr


def test_a_hand_turned_multi_position_session_is_not_taken_for_a_rotating_run():
    """imu_tk's Xsens session swings by about 40 deg/s over 10 s means (fast hand turns), but its 38 still poses
    turn every axis up and down: a multi-position session, whose turns are meant; the same data with the
    accelerometer held on one face is a rotating run again."""
    session = xsens_session()
    assert turned_between_poses(session)
    assert "rotation" not in _checks(calibration_concerns(session))
    one_face = dataclasses.replace(session, accel_g=np.tile([0.0, 0.0, 1.0], (session.n_samples, 1)))
    assert not turned_between_poses(one_face)
    assert "rotation" in _checks(calibration_concerns(one_face))
