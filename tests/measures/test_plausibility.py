"""Plausibility checks: unit mistakes and the wrong kind of data are said, never silently fitted."""

import dataclasses
import re
import warnings

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp import Polynomial, apply, fit_calibration, write
from gyrocomp.evaluation import comparison, validation
from gyrocomp.calibration.compensate import Compensator
from gyrocomp.errors import (
    DataQualityWarning,
    InputError,
    ModelChoiceWarning,
    PlausibilityWarning,
    TemperatureRangeWarning,
)
from gyrocomp.io import TableLayout, read
from gyrocomp.measures.noise import analyse_noise
from gyrocomp.measures.plausibility import (
    CHECKS,
    accel_unit_concern,
    agreement_concern,
    BlockMeans,
    ScaleAgreement,
    calibration_concerns,
    recording_concerns,
    scale_agreement,
    silence_pattern,
    temperature_span_concern,
    turned_between_poses,
)
from gyrocomp.recording import Recording
from gyrocomp.simulation import simulate

from ..conftest import burst_stamped_recording, run, shared_dataset, xsens_session

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
    return Recording(
        time_s=t * time_factor,
        gyro_dps=np.zeros((n, 1)),
        gyro_axes=("gyro_z",),
        temperature_degc=np.linspace(20.0, 30.0, n),
        source="t.csv",
    )


def test_time_in_another_unit():
    # 10 Hz with the time in ms read as s: 0.01 Hz for 116 days
    (concern,) = recording_concerns(_still(10.0, 100_000, time_factor=1000.0))
    assert (
        concern.check == "time-unit"
        and concern.message == "t.csv: 116 days at 0.01 Hz: is the time column in ms read as s?"
    )
    # 100 Hz with the time in s read as ms: 100 kHz
    (concern,) = recording_concerns(_still(100.0, 1000, time_factor=1e-3))
    assert concern.message.startswith("t.csv: 1e+05 Hz is no IMU's sample rate")
    assert recording_concerns(_still(100.0, 1000)) == []


def test_time_stamps_that_come_in_bursts_are_said_with_the_samples_mean_rate():
    """100 Hz delivered five samples at a time, stamped 2 ms apart on arrival: the median step says 500 Hz; the
    check says so and gives the samples' mean rate (100 Hz), as on sunsided's real MPU-6050 logs (below)."""
    (concern,) = recording_concerns(burst_stamped_recording(100.0, 10_000, 5, 2e-3))
    assert concern.check == "time-bursts"
    assert concern.message.startswith(
        "b.csv: the time stamps come in bursts: 1999 of 9999 steps (20%) are gaps over 2 times the median step "
        "(2 ms, 500 Hz), and the samples average 100 Hz: "
    ), concern.message
    assert concern.message.endswith(
        "would be 5 times off; if the sensor samples evenly, read the samples at that rate, their stamps left "
        "unread (columns={'time': ''} and rate_hz=100)"
    )


def test_dropouts_and_pauses_are_not_bursts():
    """Samples lost at random (three in ten: steps of two periods or more, gaps when the stamps' jitter makes them
    longer than two median steps, here about one step in nine) or long pauses between runs lengthen the mean step a
    little: not bursts."""
    rng = np.random.default_rng(3)
    kept = np.sort(rng.choice(20_000, 14_000, replace=False))
    jitter = 1e-4 * rng.standard_normal(kept.size)
    lossy = Recording(time_s=kept / 100.0 + jitter, gyro_dps=np.zeros((kept.size, 1)), gyro_axes=("gyro_z",))
    assert len(lossy.gaps) > 0.05 * kept.size and "time-bursts" not in _checks(recording_concerns(lossy))
    paused = np.concatenate([np.arange(1000) / 100.0 + 60.0 * k for k in range(5)])
    runs = Recording(time_s=paused, gyro_dps=np.zeros((paused.size, 1)), gyro_axes=("gyro_z",))
    assert len(runs.gaps) == 4 and recording_concerns(runs) == []


def test_the_burst_stamped_real_mpu6050_logs_are_said_and_the_others_are_not():
    """../shared's sunsided MPU-6050 logs: 'nominal 100 Hz (mean about 99.3 Hz, timestamps irregular/bursty;
    median dt about 2 ms)' (its README): each said, with the README's mean rate; the shared logs with regular
    stamps (CATS, tofupilot) are not."""
    from ..real.real_data import cats_runs, tofupilot_run

    folder = shared_dataset("sunsided-mpu6050-static")
    for path in sorted(folder.glob("*/mpu6050_gyroscope.mat")):
        columns = {"time": "gyroBuffer[:, 0]", "gyro_x": "gyroBuffer[:, 1]"}
        (concern,) = [c for c in recording_concerns(read(path, TableLayout(columns=columns)))]
        mean_hz = float(re.search(r"the samples average ([\d.]+) Hz", concern.message).group(1))
        assert concern.check == "time-bursts" and 98.5 < mean_hz < 100.0, concern.message
    shared_dataset("skdivemove-cats-tempcal")
    shared_dataset("tofupilot-imu-thermal")
    assert all("time-bursts" not in _checks(recording_concerns(r)) for r in [*cats_runs(), tofupilot_run()])


def test_values_beyond_any_mems_range():
    gyro = RUN.gyro_dps.copy()
    gyro[10, 0] = 6e4
    (concern,) = recording_concerns(dataclasses.replace(RUN, gyro_dps=gyro))
    assert concern.check == "rate" and "6e+04 deg/s, beyond any MEMS gyro's range" in concern.message
    # what no output can be (a damaged binary file gives 1e36..1e302) is refused where the recording is made
    gyro[10, 0] = 6e31
    with pytest.raises(
        InputError,
        match=r"row 11, column 'gyro_x': 6e\+31 deg/s is beyond what any sensor gives "
        r"\(-1e\+06\.\.1e\+06 deg/s\): a damaged file, or a column in another unit",
    ):
        dataclasses.replace(RUN, gyro_dps=gyro)


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
    flat = [
        dataclasses.replace(RUN, temperature_degc=np.full(RUN.n_samples, 25.0), source=f"flat{k}.csv") for k in range(3)
    ]
    function = getattr(comparison if call == "compare_methods" else validation, call)
    with pytest.raises(
        InputError,
        match=rf"flat0.csv: the temperature of every run spans at most 0 degC; {what} "
        "compares temperature models",
    ):
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


# -- the model against the data it is applied to ------------------------------------------------------------------


@pytest.fixture(scope="module")
def chamber_model():
    """A consumer part's default model from two chamber runs, and a third run of the same part held out."""
    runs = [simulate("consumer", profile="chamber", rate_hz=1, seed=s).recording for s in range(3)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit_calibration(runs[:2]), runs[2]


def _agreement_warnings(calibration, recording):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        apply(calibration, recording)
    return [
        str(w.message) for w in caught if issubclass(w.category, PlausibilityWarning) and w.message.check == "agreement"
    ]


def test_a_model_applied_to_its_own_part_agrees_and_says_nothing(chamber_model):
    calibration, held = chamber_model
    assert _agreement_warnings(calibration, held) == []
    # and in motion: a field log of the same part (turns, vibration, a warm-up) raises nothing either
    field = simulate("consumer", profile="field", rate_hz=20, seed=4, duration_s=3600).recording
    assert _agreement_warnings(calibration, field) == []


def test_a_unit_mistake_or_a_flipped_axis_is_said_with_its_slope(chamber_model):
    """The same held-out run read in rad/s, and with one axis's sign flipped: the slopes are the conversion
    factor and -1 (within four standard errors), and the warning names the mistake."""
    calibration, held = chamber_model
    radians = held.with_gyro(np.radians(held.gyro_dps))
    said = _agreement_warnings(calibration, radians)
    assert len(said) == 3 and all("rad/s read as deg/s? (check 'agreement')" in m for m in said)
    flipped = held.with_gyro(held.gyro_dps * np.array([1.0, -1.0, 1.0]))
    (message,) = _agreement_warnings(calibration, flipped)
    assert message.startswith(f"{held.source}: gyro_y follows the error the model predicts for it with a slope of")
    assert "the opposite sign: an axis mapped with the wrong sign?" in message
    slope_of = Compensator(calibration, held.gyro_axes, rate_hz=held.rate_hz)
    slope_of.update(radians.time_s, radians.gyro_dps, radians.temperature_degc, radians.accel_g)
    for agreement in slope_of.agreement().values():
        assert abs(agreement.slope - np.pi / 180) < 4 * agreement.standard_error + 1e-3
        assert agreement.blocks >= 100  # the chamber run: hours of 60 s blocks


def test_the_agreement_check_is_silenced_by_name_and_on_the_command_line(chamber_model, tmp_path):
    calibration, held = chamber_model
    radians = held.with_gyro(np.radians(held.gyro_dps))
    with warnings.catch_warnings():
        warnings.filterwarnings("error", category=PlausibilityWarning)
        warnings.filterwarnings("ignore", message=silence_pattern("agreement"), category=PlausibilityWarning)
        warnings.simplefilter("ignore", TemperatureRangeWarning)
        apply(calibration, radians)
    calibration.save(tmp_path / "model.json")
    write(radians, tmp_path / "rad.csv")
    said = run("apply", tmp_path / "model.json", tmp_path / "rad.csv", "-o", tmp_path / "out.csv")
    assert said.returncode == 0 and said.stderr.count("(check 'agreement')") == 3
    quiet = run(
        "--allow", "agreement", "apply", tmp_path / "model.json", tmp_path / "rad.csv", "-o", tmp_path / "out2.csv"
    )
    assert quiet.returncode == 0 and "agreement" not in quiet.stderr


@given(cuts=st.lists(st.integers(0, 3000), max_size=8, unique=True))
@settings(max_examples=40, deadline=None)
def test_block_means_are_the_same_for_any_chunking(cuts):
    rng = np.random.default_rng(0)
    time_s = np.cumsum(rng.uniform(0.5, 1.5, 3000))
    values = rng.standard_normal((3000, 2))
    whole = BlockMeans(2)
    whole.add(time_s, values)
    pieces = BlockMeans(2)
    edges = [0, *sorted(cuts), 3000]
    for a, b in zip(edges[:-1], edges[1:]):
        pieces.add(time_s[a:b], values[a:b])
    np.testing.assert_allclose(pieces.means(), whole.means(), rtol=0, atol=1e-12)
    # the blocks are 60 s from the first sample, the partial last one left out
    blocks = np.floor((time_s - time_s[0]) / 60.0)
    expected = [values[blocks == k].mean(axis=0) for k in range(int(blocks.max()))]
    np.testing.assert_allclose(whole.means()[: len(expected)], expected, atol=1e-12)


def test_block_means_keep_only_the_blocks_with_data():
    """A corrupt time stamp 1e15 s on (3e7 years of blocks) costs one block, not an array of every block between."""
    blocks = BlockMeans(1)
    blocks.add(np.array([0.0, 1.0, 2.0, 3.0, 1e15]), np.array([[1.0], [2.0], [3.0], [4.0], [9.0]]))
    np.testing.assert_array_equal(blocks.means(), [[2.5]])  # the lone sample's block is not half as full


def test_the_slope_and_when_there_is_none():
    rng = np.random.default_rng(3)
    ramp = np.linspace(-0.1, 0.1, 40)
    noise = 0.001
    fit = scale_agreement(2.0 * ramp + noise * rng.standard_normal(40) + 5.0, ramp)
    # the slope of a line through noisy points: within 4 standard errors of 2, the error as least squares says
    assert abs(fit.slope - 2.0) < 4 * fit.standard_error
    assert fit.standard_error == pytest.approx(noise / np.sqrt(np.sum((ramp - ramp.mean()) ** 2)), rel=0.35)
    assert not fit.disagrees  # a factor of 2 is within what is left unsaid
    assert scale_agreement(ramp[:9], ramp[:9]) is None  # fewer than 10 blocks
    step = np.zeros(40)
    step[0] = 1.0  # the prediction moves in one block only
    assert scale_agreement(step, step) is None
    assert scale_agreement(np.ones(40), np.full(40, 0.3)) is None  # a prediction that does not vary
    huge = 1e300 * ramp  # a corrupt temperature sent far along the tangent: no overflow, the slope as ever
    assert scale_agreement(2.0 * huge, huge).slope == pytest.approx(2.0)
    assert scale_agreement(ramp, np.where(ramp > 0, np.inf, ramp)) is None
    assert ScaleAgreement(0.0175, 1e-4, 40).disagrees and ScaleAgreement(-1.0, 0.1, 40).disagrees
    assert not ScaleAgreement(0.3, 0.06, 40).disagrees  # 0.3 + 4 x 0.06 > 0.5: not sure enough


@pytest.mark.parametrize(
    "factor, words", [(9.80665, "m/s^2 read as g"), (1000.0, "mg read as g"), (1 / 9.80665, "g read as m/s^2")]
)
def test_an_accelerometer_in_the_wrong_unit_is_said(factor, words):
    assert RUN.accel_g is not None and "accel-unit" not in _checks(recording_concerns(RUN))
    wrong = dataclasses.replace(RUN, accel_g=RUN.accel_g * factor)
    (concern,) = [c for c in recording_concerns(wrong) if c.check == "accel-unit"]
    norm = np.median(np.linalg.norm(wrong.accel_g, axis=1))
    assert concern.message == (
        f"{RUN.source}: the accelerometer's median norm is {norm:.3g} g where gravity is 1 g: "
        f"{words}? (give its unit with accel_unit=)"
    )
    # in motion too: a field log's median norm is gravity's (turns, vibration and accelerations average out)
    field = simulate("consumer", profile="field", rate_hz=20, seed=4, duration_s=600).recording
    assert accel_unit_concern(field) is None
    assert accel_unit_concern(dataclasses.replace(field, accel_g=field.accel_g * factor)).check == "accel-unit"


def test_the_accelerometer_unit_is_said_on_the_command_line_with_its_flag(tmp_path):
    wrong = dataclasses.replace(RUN, accel_g=RUN.accel_g * 9.80665)
    write(wrong, tmp_path / "ms2.csv")
    fitted = run("fit", tmp_path / "ms2.csv", "-o", tmp_path / "m.json", "--temperature", "poly:1")
    assert fitted.returncode == 0, fitted.stderr
    assert "m/s^2 read as g? (give its unit with --accel-unit) (check 'accel-unit')" in fitted.stderr


def test_an_output_that_parts_with_the_direction_of_temperature_change_is_named_hysteresis():
    # heating 20 -> 60 degC over 400 blocks, cooling to 55 over 200 (a run stopped early on its way down): the
    # model predicts a tempco, the output carries it plus an offset between the branches the model lacks, which
    # pulls the plain slope far from 1
    temperature = np.concatenate([np.linspace(20, 60, 400), np.linspace(60, 55, 200)])
    direction = np.sign(np.gradient(temperature))
    predicted = 0.01 * (temperature - 40)
    rng = np.random.default_rng(0)
    output = predicted + 0.15 * direction + 0.002 * rng.standard_normal(temperature.size)
    fit = scale_agreement(output, predicted, temperature)
    # the plain slope's residual is the step between the branches, one long correlated stretch: that slope alone
    # is not trusted (few effective blocks), the fit with the direction is
    assert fit.follows_direction and not fit.disagrees
    assert fit.direction_offset == pytest.approx(0.3, rel=0.02) and fit.slope_with_direction == pytest.approx(
        1, rel=0.05
    )
    message = agreement_concern("f.csv", "gyro_z", fit).message
    assert "gyro_z's output differs between heating and cooling by 0.3 deg/s more than the model predicts;" in message
    assert "slope of" not in message  # the slope agrees: no "slope of 1 +- 0.06, not 1"
    assert "a hysteresis or a thermal lag the model does not carry" in message and "another part" not in message
    assert "fit on runs that both heat and cool" not in message  # they did: advice that was untrue
    # a unit mistake is still named as one, the direction notwithstanding
    rad = scale_agreement(np.radians(predicted) + 1e-4 * rng.standard_normal(temperature.size), predicted, temperature)
    assert "rad/s read as deg/s?" in agreement_concern("f.csv", "gyro_z", rad).message
    # without a temperature nothing is said about the direction
    assert not scale_agreement(output, predicted).follows_direction


def test_a_drift_of_the_part_is_not_read_as_a_unit_or_another_part():
    """A later stretch of the same sensor: the prediction varies little (three degrees), the output follows it
    plus a slow drift of the part (a random walk over the 60 s blocks). With the blocks taken as independent, the
    slope came out far from 1 with a small standard error and the check asked whether the data was in another unit
    or of another part (measured: 18 of 40 draws); the drift's correlated blocks now count as fewer (3 of 40). A
    unit mistake on the same stretch is still named as one."""
    rng = np.random.default_rng(4)
    temperature = np.linspace(30.0, 33.0, 80)
    predicted = 0.02 * (temperature - 30.0)
    said = 0
    for _ in range(40):
        drift = np.cumsum(0.016 * rng.standard_normal(temperature.size))
        fit = scale_agreement(predicted + drift + 0.001 * rng.standard_normal(temperature.size), predicted, temperature)
        said += agreement_concern("f.csv", "gyro_z", fit) is not None
    assert said <= 5
    wrong = scale_agreement(
        np.degrees(predicted) + 1e-4 * rng.standard_normal(temperature.size), predicted, temperature
    )
    assert (
        agreement_concern("f.csv", "gyro_z", wrong).message.endswith("not 1: deg/s data for a model fitted on rad/s?")
        and "slope of 57.3 +-" in agreement_concern("f.csv", "gyro_z", wrong).message
    )


def test_an_impossible_temperature_is_named_with_its_row():
    rec = simulate("consumer", profile="cycle", duration_s=3000, rate_hz=1, seed=1).recording
    t = rec.temperature_degc.copy()
    t[[500, 900]] = [900.0, -150.0]
    (concern,) = [
        c for c in recording_concerns(dataclasses.replace(rec, temperature_degc=t)) if c.check == "temperature-range"
    ]
    assert concern.message.endswith(
        "row 501: temperature 900 degC, beyond any sensor's range (-100..200 degC), "
        "and 1 row(s) more: a corrupt sample, or another unit?"
    )
    assert not [c for c in recording_concerns(rec) if c.check == "temperature-range"]
    with pytest.warns(PlausibilityWarning, match=r"row 501: temperature 900 degC"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ModelChoiceWarning)
            fit_calibration([dataclasses.replace(rec, temperature_degc=t)])


def test_allan_says_a_time_column_in_another_unit(tmp_path):
    path = tmp_path / "ns.csv"
    rng = np.random.default_rng(0)
    pd.DataFrame(
        {
            "time": (np.arange(5000) * 10_000_000).astype(np.int64),  # 100 Hz in ns, read as s
            "gyro_z": rng.standard_normal(5000),
        }
    ).to_csv(path, index=False)
    result = run("allan", path)
    assert result.returncode == 0
    assert (
        "ns.csv: 1e-07 Hz is no IMU's sample rate: is the time column in another unit than the one given? "
        "(check 'time-unit')" in result.stderr
    )
    with pytest.warns(PlausibilityWarning, match=r"1e-07 Hz is no IMU's sample rate"):
        analyse_noise(read(path))
