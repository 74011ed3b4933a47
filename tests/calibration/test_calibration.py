import json
from pathlib import Path

import numpy as np
import pytest

from gyrocomp import Calibration, Polynomial, apply, fit_calibration
from gyrocomp.calibration import SCHEMA_VERSION, AxisCalibration
from gyrocomp.calibration.compensate import predict_error
from gyrocomp.errors import DataQualityWarning, InputError
from gyrocomp.fitting.online import OnlineCalibrator
from gyrocomp.io import write_recording
from gyrocomp.io.tables import read_table
from gyrocomp.curves.polynomial import PolynomialCurve
from gyrocomp.simulation import simulate


@pytest.fixture(scope="module")
def calibration(tmp_path_factory):
    folder = tmp_path_factory.mktemp("cal")
    paths = []
    for seed in (1, 2):
        path = folder / f"run{seed}.csv"
        write_recording(simulate(duration_s=600, rate_hz=10, seed=seed).recording, path)
        paths.append(path)
    from gyrocomp.io import read

    return fit_calibration([read(p) for p in paths], temperature=Polynomial(2))


def test_json_round_trip_applies_identically(calibration, tmp_path):
    path = tmp_path / "model.json"
    calibration.save(path)
    loaded = Calibration.load(path)
    assert loaded.to_dict() == calibration.to_dict()
    sim = simulate(duration_s=300, rate_hz=10, seed=9)
    np.testing.assert_array_equal(apply(loaded, sim.recording).gyro_dps, apply(calibration, sim.recording).gyro_dps)


def test_model_file_contents(calibration):
    d = json.loads(calibration.to_json())
    assert d["format"] == "gyrocomp-calibration"
    assert d["schema_version"] == SCHEMA_VERSION
    assert d["units"]["gyro"] == "deg/s"
    ax = d["axes"]["gyro_z"]
    assert ax["temperature"]["type"] == "polynomial"
    assert len(ax["temperature"]["coefficients_dps"]) == 2
    assert ax["temperature"]["t_min_degc"] < ax["temperature"]["t_max_degc"]
    prov = d["provenance"]
    assert prov["gyrocomp_version"]
    assert prov["created_utc"].endswith("+00:00")
    assert [i["file"] for i in prov["inputs"]] == ["run1.csv", "run2.csv"]
    assert all(len(i["sha256"]) == 64 for i in prov["inputs"])


def test_future_schema_is_refused(calibration, tmp_path):
    d = calibration.to_dict()
    d["schema_version"] = SCHEMA_VERSION + 1
    (tmp_path / "f.json").write_text(json.dumps(d))
    with pytest.raises(
        InputError, match=rf"f.json: written with model schema {SCHEMA_VERSION + 1}, .*upgrade gyrocomp"
    ):
        Calibration.load(tmp_path / "f.json")


def test_old_schema_is_upgraded(calibration, monkeypatch):
    import gyrocomp.calibration.calibration as module

    d = calibration.to_dict()
    # this file has the current schema; pretend gyrocomp is one schema ahead with an upgrade registered
    monkeypatch.setattr(module, "SCHEMA_VERSION", SCHEMA_VERSION + 1)
    calls = []

    def upgrade(old):
        calls.append(old["schema_version"])
        return {**old, "schema_version": old["schema_version"] + 1}

    monkeypatch.setitem(module.UPGRADES, SCHEMA_VERSION, upgrade)
    loaded = module.Calibration.from_dict(d)
    assert calls == [SCHEMA_VERSION]
    assert loaded.schema_version == SCHEMA_VERSION + 1


@pytest.mark.parametrize(
    "text,message",
    [
        (
            '{"format": "gyrocomp-calibration", "schema_version": 1, "axes": {"gyro_z": {"temperature": nu',
            r"not valid JSON \(line 1, column \d+: .*\); the file may be truncated",
        ),
        ("", r"not valid JSON"),
        ('{"a": 1}', r'not a gyrocomp model file \(no "format": "gyrocomp-calibration"\)'),
        (
            '{"format": "gyrocomp-calibration", "schema_version": "1"}',
            r"schema_version '1' is not a positive whole number",
        ),
        (
            '{"format": "gyrocomp-calibration", "schema_version": 1, "model": "x"}',
            r"m\.json: 'axes' is a required property",
        ),
        ('{"format": "gyrocomp-calibration", "schema_version": 1, "model": "x", "axes": {}}', r"m.json: no axes"),
        (
            '{"format": "gyrocomp-calibration", "schema_version": 1, "model": "x", "axes": {"gyro_z": {"temperature": {"type": "spline"}, "turn_on_biases_dps": [0]}}}',
            r"unknown temperature model type 'spline'",
        ),
    ],
)
def test_bad_model_files(tmp_path, text, message):
    (tmp_path / "m.json").write_text(text)
    with pytest.raises(InputError, match=message):
        Calibration.load(tmp_path / "m.json")


def test_missing_model_file(tmp_path):
    with pytest.raises(InputError, match=r"nope.json: no such model file"):
        Calibration.load(tmp_path / "nope.json")


def test_predicted_error_follows_the_true_deterministic_error(calibration):
    sim = simulate(duration_s=600, rate_hz=10, seed=4)
    err = predict_error(calibration, sim.recording)
    truth = sim.truth.components_dps["temperature"]
    # about their means (the held-out run's turn-on constant is not predictable): the temperature drift is
    # followed to within a small fraction of its swing
    for j in range(err.shape[1]):
        e, t = err[:, j] - err[:, j].mean(), truth[:, j] - truth[:, j].mean()
        assert np.sqrt(np.mean((e - t) ** 2)) < 0.1 * np.ptp(t)


def test_schema_1_files_load_without_lag_or_hysteresis(calibration, tmp_path):
    d = json.loads(calibration.to_json())
    d["schema_version"] = 1
    for ax in d["axes"].values():
        del ax["lag_time_constant_s"], ax["hysteresis"], ax["g_sensitivity_dps_per_g"], ax["g_squared_dps_per_g2"]
        del ax["acceleration_network"], ax["temperature_rate"]
    del d["accel_axes"], d["accel_reference_degc"], d["gyro_triad"], d["accel_triad"]
    path = tmp_path / "v1.json"
    path.write_text(json.dumps(d))
    loaded = Calibration.load(path)
    assert loaded.schema_version == SCHEMA_VERSION == 7
    assert loaded.accel_axes == {} and loaded.accel_reference_degc is None
    assert loaded.gyro_triad is None and loaded.accel_triad is None
    assert all(ax.lag_time_constant_s == 0 and ax.hysteresis is None for ax in loaded.axes.values())
    assert all(ax.rate_term is None for ax in loaded.axes.values())
    assert loaded.axes["gyro_z"].temperature == calibration.axes["gyro_z"].temperature


def _mutated(calibration, change):
    d = json.loads(calibration.to_json())
    change(d)
    return d


def _poly(d):
    return d["axes"]["gyro_z"]["temperature"]


@pytest.mark.parametrize(
    "change, message",
    [
        (
            lambda d: _poly(d)["coefficients_dps"].__setitem__(0, float("nan")),
            r"axes\.gyro_z\.temperature\.coefficients_dps\[0\]: nan is not a finite number",
        ),
        (
            lambda d: _poly(d)["coefficients_dps"].__setitem__(1, float("inf")),
            r"axes\.gyro_z\.temperature\.coefficients_dps\[1\]: inf is not a finite number",
        ),
        (
            lambda d: _poly(d)["coefficients_dps"].__setitem__(0, 1e300),
            r"axes\.gyro_z\.temperature\.coefficients_dps\[0\]: 1e\+300 is greater than the maximum of 10000",
        ),
        (
            lambda d: _poly(d).__setitem__("coefficients_dps", [0.0] * 5000),
            r"axes\.gyro_z\.temperature\.coefficients_dps: 5000 values; at most 10$",
        ),
        (
            lambda d: _poly(d).update(t_min_degc=90.0, t_max_degc=-20.0),
            r"axes\.gyro_z\.temperature: t_min_degc 90 is above t_max_degc -20",
        ),
        (lambda d: d["axes"]["gyro_z"].pop("temperature"), r"axes\.gyro_z: 'temperature' is a required property"),
        (
            lambda d: d["axes"]["gyro_z"].__setitem__("lag_time_constant_s", -5.0),
            r"axes\.gyro_z\.lag_time_constant_s: -5\.0 is less than the minimum of 0\.0",
        ),
        (
            lambda d: d["axes"].__setitem__("../../etc/passwd", d["axes"]["gyro_z"]),
            r"axes: '\.\./\.\./etc/passwd' is not one of \['gyro_x', 'gyro_y', 'gyro_z'\]",
        ),
        (
            lambda d: d["axes"]["gyro_z"].__setitem__("temperature_column", "../x"),
            r"axes\.gyro_z\.temperature_column: '\.\./x' is not one of \['temperature', 'temperature_x'",
        ),
        (
            lambda d: d["axes"]["gyro_z"].__setitem__("turn_on_biases_dps", []),
            r"axes\.gyro_z\.turn_on_biases_dps: 0 values; at least 1",
        ),
        # text where a number belongs: float() would read "NaN" as a number and apply would write NaN (the sweep found it)
        (
            lambda d: d["axes"]["gyro_z"].__setitem__("turn_on_biases_dps", ["NaN"]),
            r"axes\.gyro_z\.turn_on_biases_dps\[0\]: 'NaN' is not of type 'number'",
        ),
        (
            lambda d: _poly(d).__setitem__("t_max_degc", "1e5"),
            r"axes\.gyro_z\.temperature\.t_max_degc: '1e5' is not of type 'number'",
        ),
    ],
)
def test_model_files_are_validated_on_load(calibration, tmp_path, change, message):
    (tmp_path / "m.json").write_text(json.dumps(_mutated(calibration, change)))
    with pytest.raises(InputError, match=r"m\.json: " + message):
        Calibration.load(tmp_path / "m.json")


@pytest.mark.parametrize(
    "text, message",
    [
        ("[" * 100000 + "]" * 100000, r"not a gyrocomp model file \(nested too deeply\)"),
        (
            '{"format": "gyrocomp-calibration", "schema_version": ' + "9" * 5000 + "}",
            r"an integer of 5000 digits; gyrocomp's files hold none of more than 30",
        ),
    ],
)
def test_pathological_json_is_refused_in_one_line(tmp_path, text, message):
    (tmp_path / "m.json").write_text(text)
    with pytest.raises(InputError, match=r"m\.json: " + message):
        Calibration.load(tmp_path / "m.json")


def test_a_valid_file_still_loads_and_applies_identically(calibration, tmp_path):
    calibration.save(tmp_path / "ok.json")
    sim = simulate(duration_s=120, rate_hz=10, seed=8)
    np.testing.assert_array_equal(
        apply(Calibration.load(tmp_path / "ok.json"), sim.recording).gyro_dps,
        apply(calibration, sim.recording).gyro_dps,
    )


def test_schema_5_file_written_by_the_previous_release_loads_and_applies_identically():
    """tests/calibration/data/schema5: a model file written by gyrocomp at commit dcded69 (schema 5; its fit_report emptied
    to keep the file small, apply does not read it) and a held-out run with the output that version's apply
    gave (``expected_gyro_*``, turn-on window 60 s)."""
    folder = Path(__file__).parent / "data" / "schema5"
    assert json.loads((folder / "model.json").read_text())["schema_version"] == 5
    loaded = Calibration.load(folder / "model.json")
    assert loaded.schema_version == SCHEMA_VERSION and loaded.gyro_triad is None and loaded.accel_triad is None
    with pytest.warns(DataQualityWarning, match="time gap"):  # the run pauses between positions
        data = read_table(folder / "heldout.csv")
    out = apply(loaded, data.recording, turn_on_window_s=60)
    for j, axis in enumerate(out.gyro_axes):
        expected = data.table.column(f"expected_{axis}").to_numpy()
        np.testing.assert_allclose(out.gyro_dps[:, j], expected, rtol=0, atol=1e-12)


def test_schema_6_file_written_before_the_registries_loads_and_applies_identically():
    """tests/calibration/data/schema6: a model file written by gyrocomp at commit 0fddd35 (schema 6, before the
    readers, exports and curves became registries and the fit one path; an ADXRS450 cubic with thermal lag and
    turning-point hysteresis; its fit_report emptied, apply does not read it) and a held-out run with the output
    that version's apply gave (turn-on window 60 s)."""
    folder = Path(__file__).parent / "data" / "schema6"
    assert json.loads((folder / "model.json").read_text())["schema_version"] == 6
    loaded = Calibration.load(folder / "model.json")
    assert loaded.axes["gyro_z"].hysteresis is not None and loaded.axes["gyro_z"].lag_time_constant_s > 0
    data = read_table(folder / "heldout.csv")
    out = apply(loaded, data.recording, turn_on_window_s=60)
    np.testing.assert_allclose(out.gyro_dps[:, 0], data.table.column("expected_gyro_z").to_numpy(), rtol=0, atol=1e-12)


def test_each_axis_carries_its_unit_and_the_names_with_a_unit_refuse_the_other():
    """A gyro axis is in deg/s, an accelerometer axis in g: the unit-free names read either, the ``_dps`` and ``_g``
    accessors only their own; a calibration refuses an axis in the wrong section, and a file read back keeps the
    accelerometer's axes in g."""
    curve = PolynomialCurve((1e-3, 2e-4), 25.0, 20.0, 0.0, 50.0)
    gyro = AxisCalibration(curve, (0.1, 0.3))
    accel = AxisCalibration(curve, (0.02, 0.04), unit="g")
    assert gyro.unit == "deg/s" and gyro.turn_on_biases_dps == (0.1, 0.3) and gyro.mean_turn_on_bias_dps == 0.2
    assert accel.turn_on_biases_g == accel.turn_on_biases == (0.02, 0.04) and accel.mean_turn_on_bias == pytest.approx(
        0.03
    )
    with pytest.raises(InputError, match=r"turn_on_biases_dps: the axis's values are in g, not deg/s"):
        _ = accel.turn_on_biases_dps
    with pytest.raises(InputError, match=r"mean_turn_on_bias_dps: the axis's values are in g, not deg/s"):
        _ = accel.mean_turn_on_bias_dps
    with pytest.raises(InputError, match=r"turn_on_biases_g: the axis's values are in deg/s, not g"):
        _ = gyro.turn_on_biases_g
    with pytest.raises(InputError, match=r"unit: 'm/s\^2'; an axis is in one of deg/s, g"):
        AxisCalibration(curve, (0.0,), unit="m/s^2")
    with pytest.raises(InputError, match=r"accel_axes\['accel_x'\]\.unit: 'deg/s'; the axes of accel_axes are in g"):
        Calibration(axes={}, model="x", accel_axes={"accel_x": gyro}, accel_reference_degc=25.0)
    with pytest.raises(InputError, match=r"axes\['gyro_x'\]\.unit: 'g'; the axes of axes are in deg/s"):
        Calibration(axes={"gyro_x": accel}, model="x")
    cal = Calibration(axes={"gyro_x": gyro}, model="x", accel_axes={"accel_x": accel}, accel_reference_degc=25.0)
    text = cal.to_json()
    assert '"turn_on_biases_g"' in text and '"turn_on_biases_dps"' in text  # the file names each unit
    back = Calibration.from_dict(json.loads(text))
    assert back.accel_axes["accel_x"] == accel and back.axes["gyro_x"] == gyro


@pytest.mark.parametrize("digits", [31, 4000, 5000])
def test_integers_beyond_any_count_are_refused_in_one_line(calibration, tmp_path, digits):
    """Python turns a 4,000-digit integer into an int no float holds and refuses 5,000 digits with an error about
    its own limits: a model file or a learner state holding one is refused naming the file."""
    text = json.dumps(calibration.to_dict()).replace(
        '"schema_version": ', '"schema_version": ' + "9" * digits + ', "was": ', 1
    )
    (tmp_path / "m.json").write_text(text)
    with pytest.raises(
        InputError,
        match=rf"m.json: an integer of {digits} digits; gyrocomp's files hold none of more "
        r"than 30",
    ):
        Calibration.load(tmp_path / "m.json")
    (tmp_path / "s.json").write_text('{"format": "gyrocomp-learner", "schema_version": ' + "9" * digits + "}")
    with pytest.raises(InputError, match=rf"s.json: an integer of {digits} digits"):
        OnlineCalibrator.load(tmp_path / "s.json")
