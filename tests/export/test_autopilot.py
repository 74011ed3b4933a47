"""PX4 and ArduPilot parameters: each autopilot's own correction formula, written out here from its
source (PX4 temperature_compensation, ArduPilot AP_InertialSensor_tempcal.cpp), must reproduce gyrocomp's."""

import dataclasses
import math
import re
import warnings

import numpy as np
import pytest

from gyrocomp import Calibration, find_poses, fit_calibration
from gyrocomp.errors import DataQualityWarning, InputError
from gyrocomp.export import EXPORTERS
from gyrocomp.export.autopilot import ardupilot_params_file, px4_params_file
from gyrocomp.simulation import GyroErrorModel, Hysteresis, simulate
from gyrocomp.models.fit import fit_channels
from gyrocomp.units import STANDARD_GRAVITY_M_PER_S2 as G0
from gyrocomp.models.options import FitOptions, Polynomial

from ..conftest import run, xsens_session
from ..io.log_writers import write_ulog

RAD_TO_DEG = 180.0 / math.pi


def _model(order):
    truth = GyroErrorModel(bias_instability_deg_per_h=2.0)
    runs = [simulate(truth, profile="chamber", duration_s=3600, rate_hz=5, seed=s).recording for s in range(3)]
    return fit_calibration(runs, temperature=Polynomial(order), hysteresis="none")


def _read_px4(text):
    values = {}
    for line in text.splitlines():
        if line.startswith("#"):
            continue
        _, _, name, value, kind = line.split("\t")
        values[name] = int(value) if kind == "6" else float(value)
    return values


def px4_offset_rad_s(p, instance, axis, temperature, sensor="G"):
    """PX4: offset = X0 + X1 d + X2 d^2 + X3 d^3, d = clip(T, TMIN, TMAX) - TREF (sensor G gyro, A accel)."""
    g = f"TC_{sensor}{instance}_"
    d = np.clip(temperature, p[g + "TMIN"], p[g + "TMAX"]) - p[g + "TREF"]
    return sum(p[f"{g}X{k}_{axis}"] * d**k for k in range(4))


def _read_ardupilot(text):
    return {
        name: float(value) for name, value in (line.split() for line in text.splitlines() if not line.startswith("#"))
    }


def ardupilot_correction_rad_s(p, instance, axis, temperature, cal_temp, sensor="GYR"):
    """ArduPilot: v -= P(T - 35) - P(T_cal - 35), P(d) = (c1 + (c2 + c3 d) d) d * 1e-6, T clamped to TMIN..TMAX."""
    g = f"INS_TCAL{instance}_"
    c = [p[f"{g}{sensor}{k}_{'XYZ'[axis]}"] for k in (1, 2, 3)]

    def poly(t):
        d = np.clip(t, p[g + "TMIN"], p[g + "TMAX"]) - 35.0
        return (c[0] + (c[1] + c[2] * d) * d) * d * 1e-6

    return poly(temperature) - poly(cal_temp)


@pytest.mark.parametrize("order, tolerance_dps", [(3, 1e-6), (5, None)])
def test_px4_formula_reproduces_the_model(order, tolerance_dps):
    cal = _model(order)
    text = px4_params_file(cal, instance=1, device_id=1311244)
    p = _read_px4(text)
    assert p["TC_G_ENABLE"] == 1 and p["TC_G1_ID"] == 1311244
    assert not any("_SCL_" in name for name in p)  # PX4 removed TC_*_SCL_* (QGroundControl: no such parameter)
    t = np.linspace(-30, 80, 500)  # beyond the range on both sides: both clamp
    for name, j in (("gyro_x", 0), ("gyro_y", 1), ("gyro_z", 2)):
        ax = cal.axes[name]
        ours = ax.temperature.shape(t) + ax.mean_turn_on_bias_dps
        theirs = px4_offset_rad_s(p, 1, j, t) * RAD_TO_DEG
        stated = float(re.search(rf"{name}: ([\d.e+-]+) deg/s", text).group(1))
        # float32 parameters: about 1e-7 relative on coefficients of up to ~0.05 deg/s over the range
        assert np.max(np.abs(theirs - ours)) <= (tolerance_dps or stated) + 1e-6
        if order == 5:
            assert stated < 0.2 * np.ptp(ours)  # a cubic is close, and the file says how close


def test_ardupilot_formula_reproduces_the_model_relative_to_the_calibration_temperature():
    cal = _model(3)
    text = ardupilot_params_file(cal, instance=2)
    p = _read_ardupilot(text)
    assert p["INS_TCAL2_ENABLE"] == 1 and "INS_TCAL2_GYR3_Z" in p
    t = np.linspace(-30, 80, 500)
    cal_temp = 22.0
    for name, j in (("gyro_x", 0), ("gyro_y", 1), ("gyro_z", 2)):
        curve = cal.axes[name].temperature
        ours = curve.shape(t) - curve.shape(np.array([cal_temp]))[0]
        theirs = ardupilot_correction_rad_s(p, 2, j, t, cal_temp) * RAD_TO_DEG
        np.testing.assert_allclose(theirs, ours, atol=1e-7)


def test_terms_the_autopilots_lack_are_named():
    runs = [simulate("adxrs450", profile="cycle", rate_hz=1, seed=s).recording for s in range(2)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration(runs, hysteresis="lag")
    with pytest.warns(DataQualityWarning, match="PX4 has no thermal lag term: left out of the export"):
        text = px4_params_file(cal, device_id=3)
    p = _read_px4(text)
    assert p["TC_G0_X1_0"] == 0.0 and p["TC_G0_X1_2"] != 0.0  # the ADXRS450 preset is z only
    with pytest.raises(InputError, match=r"instance: ArduPilot numbers its IMUs 1..3, got 0"):
        ardupilot_params_file(cal, instance=0)
    with pytest.raises(InputError, match=r"instance: PX4 has thermal compensation for gyros 0..3, got 7"):
        px4_params_file(cal, instance=7, device_id=3)
    flat = fit_calibration(runs, temperature=None)
    with pytest.raises(
        InputError, match="export: the model has no gyro or accelerometer axis with a temperature curve"
    ):
        px4_params_file(flat, device_id=3)


@pytest.mark.slow
def test_cli_export(tmp_path):
    _model(3).save(tmp_path / "m.json")
    r = run("export", tmp_path / "m.json", "--format", "px4", "-o", tmp_path / "tc.params", "--device-id", "7")
    assert r.returncode == 0, r.stderr
    assert "gyro_z:" in r.stdout and (tmp_path / "tc.params").read_text().count("TC_G0_X") == 12
    # what to do on the vehicle, in order, in the file and on the screen
    assert "on the vehicle, in this order:" in r.stdout and "2. reboot" in r.stdout
    assert "calibrate the gyro again (or zero them)" in (tmp_path / "tc.params").read_text()
    r = run("export", tmp_path / "m.json", "--format", "ardupilot", "-o", tmp_path / "tc.parm")
    assert r.returncode == 0, r.stderr
    assert "INS_TCAL1_GYR1_X" in (tmp_path / "tc.parm").read_text()
    assert "the INS_TCAL<n>_* group is hidden until then" in (tmp_path / "tc.parm").read_text()
    r = run("export", tmp_path / "m.json", "--format", "simulink", "-o", tmp_path / "x.slx")
    assert r.returncode == 2 and "Invalid value for '--format'" in r.stderr
    # without --format, the name says it: .params is PX4's, .parm ArduPilot's, a folder without a suffix C
    r = run("export", tmp_path / "m.json", "-o", tmp_path / "by_name.parm")
    assert r.returncode == 0 and "INS_TCAL1_GYR1_X" in (tmp_path / "by_name.parm").read_text()
    r = run("export", tmp_path / "m.json", "-o", tmp_path / "by_name.params", "--device-id", "7")
    assert r.returncode == 0 and "TC_G0_X" in (tmp_path / "by_name.params").read_text()
    r = run("export", tmp_path / "m.json", "-o", tmp_path / "x.slx")
    offered = [name for name in EXPORTERS if name != "json"]  # what gyrocomp export offers, whatever is registered
    named = ", ".join(f"{s} ({n})" for n in offered for s in EXPORTERS[n].suffixes)
    assert r.returncode == 2 and r.stderr.strip() == (
        f"gyrocomp: error: --format: not given, and 'x.slx' names none; give it ({', '.join(offered)}), or name the "
        f"file {named}, or a folder without a suffix (c)"
    )
    assert ".params (px4), .parm (ardupilot), .param (ardupilot)" in named
    r = run("export", tmp_path / "m.json", "--format", "px4", "-o", tmp_path / "m.json")
    assert r.returncode == 2 and "this is an input file" in r.stderr


def test_px4_export_without_a_device_id_is_refused_naming_where_to_find_it(tmp_path):
    _model(3).save(tmp_path / "m.json")
    r = run("export", tmp_path / "m.json", "--format", "px4", "-o", tmp_path / "tc.params")
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and not (tmp_path / "tc.params").exists()
    assert (
        "no gyro device id (PX4 applies TC_Gn_* only to the sensor whose device id matches, so 0 does nothing); "
        "give --device-id ID: find it in the ULog's sensor_gyro topic, with 'listener sensor_gyro' on the vehicle, "
        "or in the CAL_GYRO0_ID parameter"
    ) in r.stderr
    with pytest.raises(InputError, match=r"device_id: a PX4 device id is a positive 32-bit number, got 0"):
        px4_params_file(_model(3), device_id=0)


def test_px4_export_takes_the_device_ids_the_model_s_ulog_runs_recorded():
    cal = _model(3)
    inputs = [{"file": f"log{k}.ulg", "device_id": 2293768, "accel_device_id": 2359304} for k in range(2)]
    with_ids = dataclasses.replace(cal, provenance={**cal.provenance, "inputs": inputs})
    assert _read_px4(px4_params_file(with_ids))["TC_G0_ID"] == 2293768
    assert _read_px4(px4_params_file(with_ids, device_id=5))["TC_G0_ID"] == 5  # the option wins
    mixed = dataclasses.replace(cal, provenance={"inputs": [{"device_id": 1}, {"device_id": 2}]})
    with pytest.raises(InputError, match=r"the model's runs come from sensors with device_id 1, 2"):
        px4_params_file(mixed)


def test_accelerometer_parameters_reproduce_the_accelerometer_model():
    runs = [simulate("consumer", profile="cycle", rate_hz=0.5, seed=s).recording for s in range(2)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_channels(runs, ("gyro", "accel"), options=FitOptions(temperature=Polynomial(3), hysteresis="none"))
        px4, ardu = (
            _read_px4(px4_params_file(cal, device_id=5, accel_device_id=6)),
            _read_ardupilot(ardupilot_params_file(cal)),
        )
    assert px4["TC_A_ENABLE"] == 1 and px4["TC_G_ENABLE"] == 1
    reference = cal.accel_reference_degc
    assert px4["TC_A0_TREF"] == pytest.approx(reference, abs=1e-4)
    temps = np.linspace(px4["TC_A0_TMIN"], px4["TC_A0_TMAX"], 57)
    g0 = 9.80665
    for j, name in enumerate(("accel_x", "accel_y", "accel_z")):
        curve = cal.accel_axes[name].temperature
        ours_g = curve.shape(temps) - curve.shape(np.array([reference]))[0]
        theirs_px4 = px4_offset_rad_s(px4, 0, j, temps, sensor="A") / g0
        theirs_ardu = ardupilot_correction_rad_s(ardu, 1, j, temps, reference, sensor="ACC") / g0
        # a cubic model: exact to the float32 / 9-digit rounding of the parameter files
        np.testing.assert_allclose(theirs_px4, ours_g, atol=2e-6)
        np.testing.assert_allclose(theirs_ardu, ours_g, atol=2e-6)


def test_accelerometer_offsets_and_scales_from_a_multi_position_calibration(tmp_path):
    """imu_tk's Xsens session: the autopilots' (raw - offset) * scale [m/s^2] reproduces the triad's correction on
    its poses to its misalignment (a few mrad of 1 g), and the CLI writes them from the model file."""
    rec = xsens_session()
    cal = fit_channels(rec, ("accel",))
    triad = cal.accel_triad
    off_diagonal = np.max(np.abs(np.asarray(triad.sensitivity) - np.diag(np.diag(triad.sensitivity))))
    with pytest.warns(DataQualityWarning, match=r"accelerometer misalignment \(up to .* mrad; its offsets and scales"):
        px4 = _read_px4(px4_params_file(cal, device_id=5, accel_device_id=6))
    with pytest.warns(DataQualityWarning, match="accelerometer misalignment"):
        ardu = _read_ardupilot(ardupilot_params_file(cal, instance=2))
    raw = np.array([p.accel_g for p in find_poses(rec)])
    ours = triad.correct(raw) * G0
    for offsets, scales in (
        (np.array([px4[f"CAL_ACC0_{a}OFF"] for a in "XYZ"]), np.array([px4[f"CAL_ACC0_{a}SCALE"] for a in "XYZ"])),
        (np.array([ardu[f"INS_ACC2OFFS_{a}"] for a in "XYZ"]), np.array([ardu[f"INS_ACC2SCAL_{a}"] for a in "XYZ"])),
    ):
        theirs = (raw * G0 - offsets) * scales
        assert np.max(np.abs(theirs - ours)) < 2 * off_diagonal * G0 + 1e-5  # float32 in the PX4 file
    # the accelerometer's own id, not the gyro's (separate dies: BMI055, SCHA63T)
    assert px4["CAL_ACC0_ID"] == 6 and not any(k.startswith("INS_TCAL") for k in ardu)
    cal.save(tmp_path / "accel.json")
    r = run("export", tmp_path / "accel.json", "--format", "ardupilot", "-o", tmp_path / "acc.parm")
    assert r.returncode == 0, r.stderr
    assert _read_ardupilot((tmp_path / "acc.parm").read_text())["INS_ACCOFFS_X"] == pytest.approx(
        ardu["INS_ACC2OFFS_X"]
    )
    assert Calibration.load(tmp_path / "accel.json").accel_triad == triad


def test_the_installed_calibration_reproduces_each_autopilot_formula():
    """installed_calibration reads the parameters back: its correction, at temperatures inside and beyond
    TMIN..TMAX, is the autopilot's own formula (PX4 with its X0; ArduPilot relative to its curve's zero at 35 degC)."""
    from gyrocomp.export.autopilot import ardupilot_parameters, installed_calibration, px4_parameters

    model = _model(3)
    temperature = np.linspace(-40.0, 90.0, 27)
    px4 = px4_parameters(model, instance=1, device_id=5, accel_device_id=6).values
    installed = installed_calibration(px4, "px4", instance=1)
    for axis, j in (("gyro_x", 0), ("gyro_y", 1), ("gyro_z", 2)):
        got = installed.axes[axis].shape_dps(temperature) + installed.axes[axis].turn_on_biases_dps[0]
        assert np.allclose(got, px4_offset_rad_s(px4, 1, j, temperature) * RAD_TO_DEG, atol=1e-12)
    ardupilot = ardupilot_parameters(model, instance=2).values
    installed = installed_calibration(ardupilot, "ardupilot", instance=1)
    for axis, j in (("gyro_x", 0), ("gyro_y", 1), ("gyro_z", 2)):
        got = installed.axes[axis].shape_dps(temperature)
        want = ardupilot_correction_rad_s(ardupilot, 2, j, temperature, cal_temp=35.0) * RAD_TO_DEG
        assert np.allclose(got, want, atol=1e-12)
    assert installed_calibration({"TC_G_ENABLE": 0}, "px4") is None
    assert installed_calibration({}, "ardupilot") is None
    with pytest.raises(InputError, match=r"autopilot: 'betaflight'; use px4 or ardupilot"):
        installed_calibration({}, "betaflight")
    with pytest.raises(InputError, match=r"TC_G0_TMIN 50 is not below TC_G0_TMAX 10"):
        installed_calibration({"TC_G_ENABLE": 1, "TC_G0_TMIN": 50.0, "TC_G0_TMAX": 10.0}, "px4")


def test_a_logs_installed_calibration_is_read_from_its_parameters(tmp_path):
    """A ULog carrying TC_G* parameters: read() keeps them, and the installed calibration removes the drift that
    PX4's formula put into the (simulated) raw sensor_gyro."""
    from gyrocomp import apply, read
    from gyrocomp.export.autopilot import installed_calibration, px4_parameters

    from ..io.log_writers import write_ulog

    model = _model(3)
    params = px4_parameters(model, instance=0, device_id=5, accel_device_id=6).values
    n = 2000
    temperature = np.linspace(
        model.axes["gyro_x"].temperature.t_min_degc, model.axes["gyro_x"].temperature.t_max_degc, n
    )
    fields = {
        "timestamp": ("uint64_t", (1_000_000 + np.arange(n) * 100_000).astype(np.uint64)),
        "device_id": ("uint32_t", np.full(n, 5, np.uint32)),
        "temperature": ("float", temperature.astype(np.float32)),
    }
    for j, axis in enumerate("xyz"):
        fields[axis] = ("float", px4_offset_rad_s(params, 0, j, temperature).astype(np.float32))
    write_ulog(
        tmp_path / "tc.ulg",
        {("sensor_gyro", 0): fields},
        parameters={
            k: (int(v) if k.endswith(("ENABLE", "_ID")) else float(v))
            for k, v in params.items()
            if k.startswith("TC_G")
        },
    )
    rec = read(tmp_path / "tc.ulg")
    installed = installed_calibration(rec.metadata["autopilot_parameters"], "px4")
    assert np.max(np.abs(apply(installed, rec).gyro_dps)) < 1e-4  # float32 logging, nothing else left


@pytest.mark.slow
def test_evaluate_installed_judges_the_autopilots_calibration_against_the_model(tmp_path):
    """A ULog whose raw sensor_gyro drifts as a gyrocomp model says, written three times: with that model's PX4
    parameters installed, with a stale calibration (slopes halved), and with the right parameters for another
    device id. The installed residual (as PX4 applies it: 1 Hz, 1 degC steps) is near the model's in the first, in
    the second stays between the model's and raw, and in the third PX4 applies nothing, and says so."""
    from gyrocomp.evaluation import compare_installed
    from gyrocomp import read
    from gyrocomp.export.autopilot import px4_parameters

    from ..io.log_writers import write_ulog

    model = _model(3)
    model.save(tmp_path / "model.json")
    params = px4_parameters(model, instance=0, device_id=5, accel_device_id=6).values
    n = 6000
    curve = model.axes["gyro_x"].temperature
    temperature = np.linspace(curve.t_min_degc, curve.t_max_degc, n)
    rng = np.random.default_rng(3)
    fields = {
        "timestamp": ("uint64_t", (1_000_000 + np.arange(n) * 200_000).astype(np.uint64)),
        "device_id": ("uint32_t", np.full(n, 5, np.uint32)),
        "temperature": ("float", temperature.astype(np.float32)),
    }
    for j, axis in enumerate("xyz"):
        drift = px4_offset_rad_s(params, 0, j, temperature) + 2e-5 * rng.standard_normal(n)
        fields[axis] = ("float", drift.astype(np.float32))
    installed = {
        k: (int(v) if k.endswith(("ENABLE", "_ID")) else float(v)) for k, v in params.items() if k.startswith("TC_G")
    }
    stale = {k: (0.5 * v if "_X1_" in k or "_X2_" in k or "_X3_" in k else v) for k, v in installed.items()}
    write_ulog(tmp_path / "good.ulg", {("sensor_gyro", 0): fields}, parameters=installed)
    write_ulog(tmp_path / "stale.ulg", {("sensor_gyro", 0): fields}, parameters=stale)
    good = compare_installed(model, read(tmp_path / "good.ulg"))
    assert good.autopilot == "px4" and good.installed.startswith("installed px4 cubic") and not good.still_only
    for axis in good.raw_dps:
        # the same cubic, but PX4 republishes only after a 1 degC change: its steps leave somewhat more
        assert good.model_dps[axis] < good.installed_dps[axis] < 1.6 * good.model_dps[axis]
        assert good.installed_dps[axis] < good.raw_dps[axis] / 20
    bad = compare_installed(model, read(tmp_path / "stale.ulg"))
    for axis in bad.raw_dps:
        assert bad.model_dps[axis] * 5 < bad.installed_dps[axis] < bad.raw_dps[axis]
    fields["device_id"] = ("uint32_t", np.full(n, 7, np.uint32))
    write_ulog(tmp_path / "other.ulg", {("sensor_gyro", 0): fields}, parameters=installed)
    other = compare_installed(model, read(tmp_path / "other.ulg"))
    assert other.installed is None and all(np.isnan(v) for v in other.installed_dps.values())
    assert "no TC_G*_ID is the gyro's device id 7: PX4 applies no thermal correction" in other.note
    shown = run("evaluate", tmp_path / "model.json", tmp_path / "other.ulg", "--installed")
    assert shown.returncode == 0 and "no TC_G*_ID is the gyro's device id 7" in shown.stdout
    result = run("evaluate", tmp_path / "model.json", tmp_path / "stale.ulg", "--installed")
    assert result.returncode == 0, result.stderr
    assert "stale.ulg: installed px4 cubic (TC_G0_*) vs the model, on all" in result.stdout
    as_json = run("evaluate", tmp_path / "model.json", tmp_path / "stale.ulg", "--installed", "--json")
    assert '"autopilot": "px4"' in as_json.stdout
    csv = tmp_path / "table.csv"
    csv.write_text("time,gyro_x,gyro_y,gyro_z,temperature\n0,0,0,0,20\n1,0,0,0,21\n")
    refused = run("evaluate", tmp_path / "model.json", csv, "--installed")
    assert refused.returncode == 2 and "not a PX4 ULog or ArduPilot DataFlash log" in refused.stderr


def test_a_hostile_model_name_stays_in_its_comment_line():
    run_ = simulate(GyroErrorModel(), profile="cycle", duration_s=3000, rate_hz=1, seed=1).recording
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration([run_], temperature=Polynomial(2), hysteresis="none")
    plain = dataclasses.replace(cal, model="plain")
    hostile = dataclasses.replace(cal, model="x\nTC_G_ENABLE 0\r\n1\t1\tCAL_GYRO0_XOFF\t9\t9\u2028")
    for write, comment in ((lambda c: px4_params_file(c, device_id=5), "#"), (ardupilot_params_file, "#")):
        a, b = write(plain).splitlines(), write(hostile).splitlines()
        assert len(a) == len(b)
        assert [x for x in a if not x.startswith(comment)] == [x for x in b if not x.startswith(comment)]
        assert all(ord(c) < 128 for c in write(hostile))


def test_a_model_fitted_on_a_ulog_exports_its_sensor_s_device_id(tmp_path):
    n = 3000
    temperature = np.linspace(10.0, 50.0, n)
    fields = {
        "timestamp": ("uint64_t", (1_000_000 + np.arange(n) * 500_000).astype(np.uint64)),
        "device_id": ("uint32_t", np.full(n, 2293768, np.uint32)),
        "temperature": ("float", temperature.astype(np.float32)),
    }
    for j, axis in enumerate("xyz"):
        fields[axis] = ("float", (1e-4 * (j + 1) * (temperature - 30.0)).astype(np.float32))
    write_ulog(tmp_path / "chamber.ulg", {("sensor_gyro", 0): fields})
    r = run("fit", tmp_path / "chamber.ulg", "-o", tmp_path / "m.json", "--temperature", "poly:2")
    assert r.returncode == 0, r.stderr
    assert Calibration.load(tmp_path / "m.json").provenance["inputs"][0]["device_id"] == 2293768
    r = run("export", tmp_path / "m.json", "--format", "px4", "-o", tmp_path / "tc.params")
    assert r.returncode == 0, r.stderr
    assert _read_px4((tmp_path / "tc.params").read_text())["TC_G0_ID"] == 2293768


def test_the_firmware_files_say_they_cannot_carry_heating_and_cooling_branches():
    runs = [
        simulate(
            GyroErrorModel(hysteresis=Hysteresis(((0.02, 0.0005),) * 3, transition_degc=5.0)),
            profile="cycle",
            duration_s=6000,
            rate_hz=1,
            seed=s,
        ).recording
        for s in range(2)
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration(runs, hysteresis="branch")
    for write in (lambda c: px4_params_file(c, device_id=5), ardupilot_params_file):
        with pytest.warns(DataQualityWarning, match=r"has no heating/cooling branches term: left out of the export"):
            write(cal)


def test_terms_that_are_rounding_are_written_as_zero(tmp_path):
    """A model whose curve is a line exports X2 = X3 = 0 exactly (not 1e-20), and its correction is unchanged."""
    from gyrocomp.export.autopilot import px4_parameters
    from gyrocomp.models.options import Polynomial
    from gyrocomp.simulation import get_profile

    part = GyroErrorModel(
        axes=("gyro_z",), temperature_coefficients=((0.01,),), t_ref_degc=25.0, noise_density_dps_per_sqrt_hz=0.002
    )
    runs = [
        simulate(
            part, profile=get_profile("cycle", set_points_degc=(0.0, 50.0), cycles=1), rate_hz=0.5, seed=s
        ).recording
        for s in range(2)
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration(runs, temperature=Polynomial(1), hysteresis="none")
        values = px4_parameters(cal, device_id=3).values
    assert values["TC_G0_X2_2"] == 0.0 and values["TC_G0_X3_2"] == 0.0 and values["TC_G0_X1_2"] != 0.0
