import json

import numpy as np
import pytest

from gyrocomp import Calibration, apply, fit_calibration
from gyrocomp.calibration import SCHEMA_VERSION
from gyrocomp.errors import InputError
from gyrocomp.io import write_recording
from gyrocomp.simulate import simulate


@pytest.fixture(scope="module")
def calibration(tmp_path_factory):
    folder = tmp_path_factory.mktemp("cal")
    paths = []
    for seed in (1, 2):
        path = folder / f"run{seed}.csv"
        write_recording(simulate(duration_s=600, rate_hz=10, seed=seed).recording, path)
        paths.append(path)
    from gyrocomp.io import read

    return fit_calibration([read(p) for p in paths], temperature=2)


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
    with pytest.raises(InputError, match=rf"f.json: written with model schema {SCHEMA_VERSION + 1}, .*upgrade gyrocomp"):
        Calibration.load(tmp_path / "f.json")


def test_old_schema_is_upgraded(calibration, monkeypatch):
    import gyrocomp.calibration as module

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
        ('{"format": "gyrocomp-calibration", "schema_version": 1, "axes": {"gyro_z": {"temperature": nu', r"not valid JSON \(line 1, column \d+: .*\); the file may be truncated"),
        ("", r"not valid JSON"),
        ('{"a": 1}', r'not a gyrocomp model file \(no "format": "gyrocomp-calibration"\)'),
        ('{"format": "gyrocomp-calibration", "schema_version": "1"}', r"schema_version '1' is not a positive whole number"),
        ('{"format": "gyrocomp-calibration", "schema_version": 1, "model": "x"}', r"malformed model file \(KeyError: 'axes'\)"),
        ('{"format": "gyrocomp-calibration", "schema_version": 1, "model": "x", "axes": {}}', r"m.json: no axes"),
        ('{"format": "gyrocomp-calibration", "schema_version": 1, "model": "x", "axes": {"gyro_z": {"temperature": {"type": "spline"}, "turn_on_biases_dps": [0]}}}',
         r"unknown temperature model type 'spline'"),
    ],
)
def test_bad_model_files(tmp_path, text, message):
    (tmp_path / "m.json").write_text(text)
    with pytest.raises(InputError, match=message):
        Calibration.load(tmp_path / "m.json")


def test_missing_model_file(tmp_path):
    with pytest.raises(InputError, match=r"nope.json: no such model file"):
        Calibration.load(tmp_path / "nope.json")


def test_predict_error_is_raw_minus_compensated(calibration):
    sim = simulate(duration_s=300, rate_hz=10, seed=4)
    err = calibration.predict_error(sim.recording)
    np.testing.assert_allclose(sim.recording.gyro_dps - err, apply(calibration, sim.recording).gyro_dps, atol=1e-15)


def test_schema_1_files_load_without_lag_or_hysteresis(calibration, tmp_path):
    d = json.loads(calibration.to_json())
    d["schema_version"] = 1
    for ax in d["axes"].values():
        del ax["lag_time_constant_s"], ax["hysteresis"], ax["g_sensitivity_dps_per_g"], ax["g_squared_dps_per_g2"]
        del ax["acceleration_network"]
    del d["accel_axes"], d["accel_reference_degc"]
    path = tmp_path / "v1.json"
    path.write_text(json.dumps(d))
    loaded = Calibration.load(path)
    assert loaded.schema_version == SCHEMA_VERSION == 5
    assert loaded.accel_axes == {} and loaded.accel_reference_degc is None
    assert all(ax.lag_time_constant_s == 0 and ax.hysteresis is None for ax in loaded.axes.values())
    assert loaded.axes["gyro_z"].temperature == calibration.axes["gyro_z"].temperature
