"""The command line, run through its real entry point in a subprocess."""

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from gyrocomp.calibration import SCHEMA_VERSION
from gyrocomp.cli import _environment_message, in_cli_words

from .conftest import run

@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    """Three simulated chamber runs and a model fitted on two of them, made with the CLI itself."""
    d = tmp_path_factory.mktemp("cli")
    for seed in (1, 2, 3):
        r = run("simulate", "--profile", "chamber", "--duration", 1200, "--rate", 10, "--seed", seed,
                "-o", d / f"run{seed}.csv", "--truth", d / f"truth{seed}.json")
        assert r.returncode == 0, r.stderr
    r = run("fit", d / "run1.csv", d / "run2.csv", "-o", d / "model.json", "--temperature", "poly:3")
    assert r.returncode == 0, r.stderr
    return d


def test_simulate_writes_data_and_truth(workdir):
    df = pd.read_csv(workdir / "run1.csv")
    assert list(df.columns) == ["time", "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z", "temperature"]
    assert len(df) == 12001
    truth = json.loads((workdir / "truth1.json").read_text())
    assert truth["preset"] == "mti10" and truth["rate_hz"] == 10 and truth["duration_s"] == 1200
    assert truth["profile"]["set_points_degc"] == [-25, 90]  # the preset's chamber range
    (only,) = truth["runs"]
    assert only["seed"] == 1 and only["file"] == "run1.csv" and only["samples"] == 12001
    assert set(only["turn_on_bias_dps"]) == {"gyro_x", "gyro_y", "gyro_z"}
    assert truth["error_model"]["noise_density_dps_per_sqrt_hz"] == 0.03


def test_simulate_runs_with_truth_columns_that_add_up(tmp_path):
    r = run("simulate", "--preset", "adxrs450", "--profile", "cycle", "--duration", 3600, "--rate", 2, "--runs", 3,
            "--seed", 10, "-o", tmp_path / "cyc.csv", "--truth", tmp_path / "truth.json", "--truth-columns")
    assert r.returncode == 0, r.stderr
    assert [p.name for p in sorted(tmp_path.glob("cyc_*.csv"))] == ["cyc_0.csv", "cyc_1.csv", "cyc_2.csv"]
    truth = json.loads((tmp_path / "truth.json").read_text())
    assert [run_["seed"] for run_ in truth["runs"]] == [10, 11, 12]
    biases = [run_["turn_on_bias_dps"]["gyro_z"] for run_ in truth["runs"]]
    assert len(set(biases)) == 3
    assert truth["error_model"]["hysteresis"]["band_degc"] == [55.0, 80.0]
    for i in range(3):
        df = pd.read_csv(tmp_path / f"cyc_{i}.csv")
        assert list(df.columns) == ["time", "gyro_z", "temperature", "true_error_gyro_z", "true_noise_gyro_z",
                                    "true_rate_gyro_z", "true_structure_temperature"]
        rebuilt = df["true_rate_gyro_z"] + df["true_error_gyro_z"] + df["true_noise_gyro_z"]
        np.testing.assert_allclose(df["gyro_z"], rebuilt, rtol=0, atol=1e-12)
        # the quantized output: whole multiples of the ADXRS450's 1/80 deg/s LSB
        np.testing.assert_allclose(df["gyro_z"] * 80, np.round(df["gyro_z"] * 80), atol=1e-6)
    # the data with truth columns is still an ordinary input: the extra columns are ignored
    r = run("allan", tmp_path / "cyc_0.csv", "--json")
    assert r.returncode == 0, r.stderr
    assert list(json.loads(r.stdout)["axes"]) == ["gyro_z"]


def test_simulate_combined_run_has_gaps_and_accelerometer(tmp_path):
    r = run("simulate", "--profile", "combined", "--rate", 1, "--duration", 7200, "-o", tmp_path / "c.parquet")
    assert r.returncode == 0, r.stderr
    assert re.search(r"wrote .*c.parquet: \d+ rows, \d+ s at 1 Hz, \d+ gaps", r.stdout)
    df = pd.read_parquet(tmp_path / "c.parquet")
    assert {"accel_x", "accel_y", "accel_z"} <= set(df.columns)
    assert np.diff(df["time"]).max() > 10


def test_fit_prints_table_and_writes_model(workdir):
    r = run("fit", workdir / "run1.csv", workdir / "run2.csv", "-o", workdir / "auto.json")
    assert r.returncode == 0, r.stderr
    # two runs that only heat: each run's one heating leg is held out (never time blocks unless asked), and two
    # folds are said to be thin evidence
    assert "model choice by held-out drift (legs: 2 folds" in r.stdout
    assert "held-out drift per fold" in r.stdout and "run 2 leg 1 (heating)" in r.stdout
    # one row per fold, one column per axis and model role: the table's width does not grow with the folds
    per_fold = r.stdout[r.stdout.index("held-out drift per fold"):]
    assert re.search(r"fold\s+\S\s+gyro_x chosen\s+\S\s+gyro_x", per_fold) and "gyro_z chosen" in per_fold
    assert "only 2 heating and cooling legs to hold out; the evidence for each axis's choice is thin" in r.stderr
    model = json.loads((workdir / "auto.json").read_text())
    assert model["fit_report"]["order_selection"] == "leave-one-leg-out"
    for axis in ("gyro_x", "gyro_y", "gyro_z"):
        sel = model["fit_report"]["selection"][axis]
        assert len(sel["folds"]) == 2 and all(len(c["fold_drift_dps"]) == 2 for c in sel["candidates"])
        assert sel["chosen_drift_dps"] <= sel["raw_drift_dps"]
        assert sel["chosen_standard_error_dps"] >= 0 and sel["fold_note"] == ""


def test_fit_compares_hysteresis_candidates_on_cycles(tmp_path):
    r = run("simulate", "--preset", "adxrs450", "--profile", "cycle", "--cycles", 1, "--rate", 1, "--runs", 2,
            "-o", tmp_path / "c.csv")
    assert r.returncode == 0, r.stderr
    r = run("fit", tmp_path / "c_0.csv", tmp_path / "c_1.csv", "-o", tmp_path / "m.json",
            "--hysteresis-band", "55,80", "--hysteresis-order", "2")
    assert r.returncode == 0, r.stderr
    assert "hysteresis / thermal lag by leave-one-run-out" in r.stdout
    for candidate in ("none", "turning-point", "lag", "turning-point+lag"):
        assert candidate in r.stdout
    assert re.search(r"lag \d+(\.\d+)? s, turning-point hysteresis order 2 in 55..80 degC", r.stdout)
    model = json.loads((tmp_path / "m.json").read_text())
    scores = model["fit_report"]["hysteresis"]["axes"]["gyro_z"]["scores_dps"]
    # every memory scored, the heating and cooling branches too (the runs heat and cool)
    assert set(scores) == {"none", "turning-point", "lag", "turning-point+lag", "branch", "branch+lag"}
    assert model["axes"]["gyro_z"]["hysteresis"]["band_degc"] == [55.0, 80.0]


def test_fit_prints_only_what_was_fitted(tmp_path):
    """A chamber run in one orientation fits no G: no table of "not fitted" cells; no fit-RMS column of dashes."""
    r = run("simulate", "--preset", "consumer", "--profile", "cycle", "--rate", 0.1, "--runs", 2,
            "-o", tmp_path / "c.csv")
    assert r.returncode == 0, r.stderr
    r = run("fit", tmp_path / "c_0.csv", tmp_path / "c_1.csv", "-o", tmp_path / "m.json")
    assert r.returncode == 0, r.stderr
    assert "g-sensitivity G" not in r.stdout and "not fitted" not in r.stdout
    assert "fit RMS" not in r.stdout and "constants [deg/s]" in r.stdout


@pytest.mark.slow
def test_fit_g_sensitivity_table_and_stages(tmp_path):
    r = run("simulate", "--preset", "consumer", "--profile", "combined", "--rate", 1, "--duration", 14000,
            "--runs", 2, "-o", tmp_path / "c.csv")
    assert r.returncode == 0, r.stderr
    r = run("simulate", "--preset", "consumer", "--profile", "combined", "--rate", 1, "--duration", 14000,
            "--seed", 9, "-o", tmp_path / "held.csv")
    assert r.returncode == 0, r.stderr
    r = run("fit", tmp_path / "c_0.csv", tmp_path / "c_1.csv", "-o", tmp_path / "m.json")
    assert r.returncode == 0, r.stderr
    assert "g-sensitivity G [deg/s/g] +- standard error" in r.stdout
    assert re.search(r"gyro_x\s*\S\s*\+0\.(09|10)\d* \+- 0\.00\d+", r.stdout)  # the preset's 0.1 deg/s/g on the diagonal
    model = json.loads((tmp_path / "m.json").read_text())
    assert model["axes"]["gyro_y"]["g_sensitivity_dps_per_g"][1] == pytest.approx(0.1, abs=0.01)
    r = run("evaluate", tmp_path / "m.json", tmp_path / "held.csv", "--stages", "--window", 100)
    assert r.returncode == 0, r.stderr
    for stage in ("raw", "temperature only", "temperature + acceleration"):
        assert stage in r.stdout
    r = run("evaluate", tmp_path / "m.json", tmp_path / "held.csv", "--stages", "--json", "--window", 100)
    stages = json.loads(r.stdout)["runs"][0]["stages"]
    assert stages["temperature + acceleration"]["gyro_z"]["bias_offset_comp_dps"] < \
        stages["temperature only"]["gyro_z"]["bias_offset_comp_dps"]
    r = run("fit", tmp_path / "c_0.csv", "-o", tmp_path / "x.json", "--acceleration", "cubic")
    assert r.returncode == 2 and "Invalid value for '--acceleration'" in r.stderr


def test_apply_keeps_columns_rows_and_other_channels(workdir):
    out = workdir / "comp.csv"
    r = run("apply", workdir / "model.json", workdir / "run3.csv", "-o", out)
    assert r.returncode == 0, r.stderr
    raw, comp = pd.read_csv(workdir / "run3.csv"), pd.read_csv(out)
    assert list(comp.columns) == list(raw.columns) and len(comp) == len(raw)
    for col in ("time", "accel_x", "accel_y", "accel_z", "temperature"):
        np.testing.assert_array_equal(comp[col], raw[col])
    assert comp["gyro_z"].rolling(600).mean().dropna().pipe(np.ptp) < raw["gyro_z"].rolling(600).mean().dropna().pipe(np.ptp)


def test_apply_parquet_and_turn_on_window(workdir):
    out = workdir / "comp.parquet"
    r = run("apply", workdir / "model.json", workdir / "run3.csv", "-o", out, "--turn-on-window", 30)
    assert r.returncode == 0, r.stderr
    comp = pd.read_parquet(out)
    assert abs(comp["gyro_z"][comp["time"] < 30].mean()) < 1e-12
    # evaluate takes the same window and says what it does to its figures (nothing: they ignore a constant)
    with_window = run("evaluate", workdir / "model.json", workdir / "run3.csv", "--turn-on-window", 30)
    plain = run("evaluate", workdir / "model.json", workdir / "run3.csv")
    assert with_window.returncode == 0 and with_window.stdout == plain.stdout
    assert "--turn-on-window 30: each run's constant was taken from its first seconds" in with_window.stderr


def test_evaluate_json_shape(workdir):
    r = run("evaluate", workdir / "model.json", workdir / "run3.csv", "--json")
    assert r.returncode == 0, r.stderr
    data = json.loads(r.stdout)
    # model.json's order was asked for (poly:3): the selection still scored it on held-out folds and says so
    assert set(data) == {"runs", "expected_held_out_drift"}
    run0 = data["runs"][0]
    assert set(run0) == {"file", "window_s", "axes"}
    assert run0["window_s"] >= 1.0
    keys = {"bias_offset_raw_dps", "bias_offset_comp_dps", "offset_improvement", "bias_instability_raw_dph",
            "bias_instability_comp_dph", "integration_time_raw_s", "integration_time_comp_s", "residual_rms_dps"}
    for axis in ("gyro_x", "gyro_y", "gyro_z"):
        assert set(run0["axes"][axis]) == keys
        assert run0["axes"][axis]["offset_improvement"] > 1


def test_evaluate_table_and_window(workdir):
    r = run("evaluate", workdir / "model.json", workdir / "run3.csv", "--window", 20)
    assert r.returncode == 0, r.stderr
    assert "offset raw" in r.stdout and "[deg/s]" in r.stdout and "run3.csv" in r.stdout
    assert re.search(r"run3\.csv\s*\S\s*gyro_x\s*\S\s*20\s", r.stdout)  # the window column shows --window


@pytest.mark.slow
def test_demo(tmp_path):
    r = run("demo", "-o", tmp_path / "demo")
    assert r.returncode == 0, r.stderr
    names = {p.name for p in (tmp_path / "demo").iterdir()}
    assert {"model.json", "heldout_compensated.csv", "metrics.json", "heldout_run.csv", "effects.json",
            "heldout_truth.json"} <= names
    metrics = json.loads((tmp_path / "demo" / "metrics.json").read_text())
    assert all(a["offset_improvement"] > 1.0 for a in metrics["runs"][0]["axes"].values())
    assert "held-out run, raw vs compensated" in r.stdout
    # the preset's three effects are shown; what the compensation leaves is less than the temperature drift
    effects = json.loads((tmp_path / "demo" / "effects.json").read_text())
    sizes = effects["effects_peak_to_peak_dps"]
    assert set(sizes) == {"temperature (with thermal lag)", "hysteresis", "g-sensitivity"}
    for axis, left in effects["residual_peak_to_peak_dps"].items():
        assert left < sizes["temperature (with thermal lag)"][axis]
        assert sizes["hysteresis"][axis] > 0.001 and sizes["g-sensitivity"][axis] > 0.0005
    assert "hysteresis" in r.stdout and "g-sensitivity" in r.stdout
    # every compensation leaves less deterministic error than raw on every axis
    left = effects["deterministic_error_left_rms_dps_by_method"]
    assert list(left)[0] == "raw (no compensation)" and list(left)[1].startswith("gyrocomp: ")
    assert all(axes[a] < left["raw (no compensation)"][a] for axes in list(left.values())[1:] for a in axes)
    # the validation table of the calibration runs: every method, by leave-one-run-out; averaged over the axes,
    # the default is no worse than the plain cubic by more than the standard error of the cubic's folds (this
    # part's drift is mostly noise: the table shows the default and the cubic within it of each other)
    validation = json.loads((tmp_path / "demo" / "validation.json").read_text())
    assert validation["fold_kind"] == "runs" and len(validation["folds"]) == 3
    assert "held-out drift [deg/s]" in r.stdout and "gyrocomp default" in r.stdout and "PX4 cubic" in r.stdout
    by = {(s["method"], s["axis"]): s for s in validation["scores"]}
    axes = ("gyro_x", "gyro_y", "gyro_z")
    mean = {m: np.mean([by[(m, a)][k] for a in axes]) for m in ("gyrocomp default", "cubic + run constants")
            for k in ("mean_drift_dps",)}
    cubic_se = np.mean([by[("cubic + run constants", a)]["standard_error_dps"] for a in axes])
    assert mean["gyrocomp default"] <= mean["cubic + run constants"] + cubic_se
    assert all(by[("gyrocomp default", a)]["mean_drift_dps"] < by[("raw", a)]["mean_drift_dps"] for a in axes)
    # temperature drift makes the raw Allan deviation rise at long averaging times; compensated, it stays near
    # what the sensor's noise alone gives (within the scatter of a few independent averages)
    allan = json.loads((tmp_path / "demo" / "allan.json").read_text())
    assert "Allan deviation of the held-out run" in r.stdout
    for axis, c in allan.items():
        raw, comp, noise = (np.array(c[k]) for k in ("raw_deg_per_h", "compensated_deg_per_h", "noise_alone_deg_per_h"))
        assert c["tau_s"][-1] >= 2000 and raw[-1] > 2.0 * noise[-1] and raw[-1] > 1.5 * comp[-1]
        assert comp[-1] < 1.5 * noise[-1]
        np.testing.assert_allclose(comp[0], noise[0], rtol=0.01)  # at 1 s it is the white noise, untouched
    assert "ArduPilot cubic (tempcal_IMU.py)" in r.stdout
    assert re.search(r"g-sensitivity .*\(compensated: 3x3 G fitted jointly\)", r.stdout)
    truth = json.loads((tmp_path / "demo" / "heldout_truth.json").read_text())
    assert truth["preset"] == "mti10" and truth["profile"]["name"] == "cycle"
    assert "warning" not in r.stderr
    report = (tmp_path / "demo" / "report.html").read_text()
    assert report.startswith("<!DOCTYPE html>") and "heldout_run.csv" in report and "data:image/png;base64," in report
    assert "report.html (open it in a browser)" in r.stdout
    # the case where gyrocomp's models matter, against the simulator's truth, and the one where they do not
    cases = json.loads((tmp_path / "demo" / "cases.json").read_text())
    matters, not_matters = cases
    assert matters["part"].startswith("consumer") and not_matters["part"].startswith("mti10")
    assert all(f > 2.0 for f in matters["gyrocomp_factor_vs"].values())  # measured 11-12x
    assert all(0.5 < f < 2.0 for f in not_matters["gyrocomp_factor_vs"].values())  # as good as a cubic
    for case in cases:
        assert case["drift_dps"]["gyrocomp"] < case["drift_dps"]["raw"]
    assert "Where gyrocomp's models matter" in r.stdout and "Where they do not" in r.stdout
    assert f"{matters['gyrocomp_factor_vs']['PX4 cubic (process_sensor_caldata.py)']:.2f}x less than PX4 cubic" in r.stdout
    assert "case_consumer.png" in names


def test_demo_without_matplotlib_says_why_there_is_no_report(tmp_path, monkeypatch):
    from gyrocomp import demo

    monkeypatch.setitem(sys.modules, "matplotlib", None)  # import matplotlib now fails, as when not installed
    why = demo._write_report(None, None, tmp_path / "report.html")
    assert why is not None and "[plot]" in why and not (tmp_path / "report.html").exists()


def test_mapping_and_units_through_cli(workdir, tmp_path):
    df = pd.read_csv(workdir / "run3.csv")
    vendor = pd.DataFrame({"Stamp": df["time"] * 1000, "GyrZ": np.deg2rad(df["gyro_z"]), "T": df["temperature"]})
    vendor.to_csv(tmp_path / "vendor.csv", index=False)
    r = run("apply", workdir / "model.json", tmp_path / "vendor.csv", "-o", tmp_path / "v_out.csv",
            "--columns", "time=Stamp,gyro_z=GyrZ,temperature=T", "--gyro-unit", "rad/s", "--time-unit", "ms")
    assert r.returncode == 0, r.stderr
    ours = pd.read_csv(tmp_path / "v_out.csv")
    theirs = run("apply", workdir / "model.json", workdir / "run3.csv", "-o", tmp_path / "d_out.csv")
    assert theirs.returncode == 0
    np.testing.assert_allclose(np.rad2deg(ours["GyrZ"]), pd.read_csv(tmp_path / "d_out.csv")["gyro_z"], atol=1e-12)


ERROR_CASES = {
    "empty": ("", r"empty.csv: the file is empty"),
    "header_only": ("time,gyro_z,temperature\n", r"header_only.csv: a header but no data rows"),
    "no_temperature": ("time,gyro_z\n0,1\n1,2\n2,3\n", r"no_temperature.csv: no temperature column"),
    "text_in_number": ("time,gyro_z,temperature\n0,1,20\n1,x1,21\n2,1,22\n",
                       r"text_in_number.csv: row 2 \(line 3\), column 'gyro_z': 'x1' is not a number"),
    "nan_rows": ("time,gyro_z,temperature\n0,1,20\n1,NaN,21\n2,1,22\n",
                 r"nan_rows.csv: row 2, column 'gyro_z': nan is not a finite number; fix the file or drop such rows explicitly \(--drop-nan\)"),
    "time_backwards": ("time,gyro_z,temperature\n0,1,20\n1,1,21\n0.5,1,22\n",
                       r"time_backwards.csv: row 3: time goes backwards \(0.5 s after 1 s\)"),
}


@pytest.mark.parametrize("name", sorted(ERROR_CASES))
def test_bad_inputs_give_one_line_and_status_2(tmp_path, name):
    text, message = ERROR_CASES[name]
    (tmp_path / f"{name}.csv").write_text(text)
    r = run("fit", tmp_path / f"{name}.csv", "-o", tmp_path / "m.json")
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    assert lines[0].startswith("gyrocomp: error: ")
    assert re.search(message, lines[0]), lines[0]
    assert "Traceback" not in r.stderr
    assert not (tmp_path / "m.json").exists()


def test_debug_shows_traceback(tmp_path):
    (tmp_path / "e.csv").write_text("")
    r = run("--debug", "fit", tmp_path / "e.csv", "-o", tmp_path / "m.json")
    assert r.returncode == 2 and "Traceback" in r.stderr


def test_drop_nan_reports_and_proceeds(tmp_path):
    (tmp_path / "n.csv").write_text("time,gyro_z,temperature\n0,1,20\n1,NaN,21\n2,1,22\n3,2,23\n")
    r = run("fit", tmp_path / "n.csv", "-o", tmp_path / "m.json", "--drop-nan", "--temperature", "poly:1")
    assert r.returncode == 0, r.stderr
    assert "gyrocomp: warning: " in r.stderr and "dropped 1 of 4 rows" in r.stderr


@pytest.mark.parametrize("edit,message", [
    (lambda t: t.replace(f'"schema_version": {SCHEMA_VERSION}', '"schema_version": 99'), r"written with model schema 99, .*upgrade gyrocomp"),
    (lambda t: t[: len(t) // 2], r"not valid JSON \(line \d+, column \d+: .*\); the file may be truncated"),
])
def test_bad_model_files(workdir, tmp_path, edit, message):
    (tmp_path / "bad.json").write_text(edit((workdir / "model.json").read_text()))
    r = run("apply", tmp_path / "bad.json", workdir / "run3.csv", "-o", tmp_path / "o.csv")
    assert r.returncode == 2
    assert re.search(message, r.stderr.strip()) and len(r.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "o.csv").exists()


def test_refuses_to_overwrite_input(workdir, tmp_path):
    src = tmp_path / "in.csv"
    shutil.copy(workdir / "run3.csv", src)
    before = src.read_bytes()
    r = run("apply", workdir / "model.json", src, "-o", src)
    assert r.returncode == 2
    assert "this is an input file; choose another output path" in r.stderr
    assert src.read_bytes() == before


@pytest.mark.parametrize("args,message", [
    (["simulate", "--duration", "abc", "-o", "x.csv"], r"Invalid value for '--duration': 'abc' is not a number"),
    (["fit", "x.csv"], r"Missing option '-o'"),
    (["fit", "{run}", "-o", "m.json", "--temperature", "poly:7"], r"--temperature: 'poly:7': the order must be"),
    (["fit", "{run}", "-o", "m.json", "--columns", "gyro_z=Nope"], r"--columns gyro_z=Nope: no column 'Nope'"),
    (["apply", "{model}", "{run}", "-o", "o.csv", "--gyro-unit", "rpm"], r"--gyro-unit: unknown unit 'rpm'"),
    (["apply", "{model}", "{run}", "-o", "o.csv", "--turn-on-window", "-3"], r"--turn-on-window: must be a positive"),
    (["evaluate", "{model}", "{run}", "--window", "1e9"], r"--window: 1e\+09 s is longer than the run"),
    (["simulate", "--profile", "oven", "-o", "x.csv"], r"--profile: unknown profile 'oven'"),
    (["simulate", "--axes", "q", "-o", "x.csv"], r"--axes: gyro_q; this part has gyro_x, gyro_y, gyro_z"),
    (["simulate", "--preset", "adxrs450", "--axes", "x", "-o", "x.csv"], r"--axes: gyro_x; this part has gyro_z"),
    (["simulate", "--preset", "mems", "-o", "x.csv"], r"--preset: unknown preset 'mems'; use one of adxrs450, mti10"),
    (["simulate", "--runs", "0", "-o", "x.csv"], r"Invalid value for --runs: must be at least 1"),
    (["simulate", "--set-points", "cold", "-o", "x.csv"], r"Invalid value for --set-points: give comma-separated"),
    (["simulate", "--ramp-rate", "0", "-o", "x.csv"], r"--ramp-rate: must be positive, got 0"),
    (["simulate", "--cycles", "0", "-o", "x.csv"], r"--cycles: must be at least 1, got 0"),
    (["simulate", "--unit", "-1", "-o", "x.csv"], r"--unit: must be a whole number >= 0, got -1"),
    (["simulate", "-o", "x.csv", "--truth", "x.csv"], r"--truth x.csv: the same file as a data output"),
    (["fit", "{run}", "-o", "m.json", "--hysteresis", "sometimes"], r"Invalid value for '--hysteresis': 'sometimes'"),
    (["fit", "{run}", "-o", "m.json", "--hysteresis-order", "9"], r"Invalid value for --hysteresis-order: use auto, 1, 2 or 3"),
    (["fit", "{run}", "-o", "m.json", "--hysteresis-band", "80,55"], r"Invalid value for --hysteresis-band: give LO,HI"),
    (["nosuchcommand"], r"No such command 'nosuchcommand'"),
])
def test_usage_errors(workdir, tmp_path, args, message):
    args = [a.format(run=workdir / "run3.csv", model=workdir / "model.json") for a in args]
    r = run(*args, cwd=tmp_path)
    assert r.returncode == 2, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert re.search(message, r.stderr), r.stderr


def test_version_and_help():
    r = run("--version")
    assert r.returncode == 0 and "gyrocomp" in r.stdout
    r = run("--help")
    assert r.returncode == 0 and "demo" in r.stdout and "evaluate" in r.stdout


def test_apply_unknown_output_suffix_keeps_input_format(workdir, tmp_path):
    r = run("apply", workdir / "model.json", workdir / "run3.csv", "-o", tmp_path / "out.dat")
    assert r.returncode == 0, r.stderr
    assert len(pd.read_csv(tmp_path / "out.dat")) == 12001


@pytest.fixture(scope="module")
def static_log(tmp_path_factory):
    d = tmp_path_factory.mktemp("allan")
    r = run("simulate", "--profile", "static", "--duration", 1800, "--rate", 20, "--axes", "x,z", "-o", d / "s.csv")
    assert r.returncode == 0, r.stderr
    return d


def test_allan_json_has_exactly_the_documented_shape(static_log):
    r = run("allan", static_log / "s.csv", "--json", "--axes", "gyro_z")
    assert r.returncode == 0, r.stderr
    doc = json.loads(r.stdout)
    assert set(doc) == {"rate_hz", "axes"} and doc["rate_hz"] == 20.0
    z = doc["axes"]["gyro_z"]
    assert list(z) == ["tau_s", "adev", "n", "ci_low", "ci_high", "noise"]
    assert list(z["noise"]) == ["noise_density_dps_per_sqrt_hz", "arw_deg_per_sqrt_h", "bias_instability_deg_per_h",
                                "integration_time_s", "rrw_deg_per_h_per_sqrt_h", "quantization_deg",
                                "rate_ramp_deg_per_h2"]
    assert z["tau_s"][:3] == [0.05, 0.1, 0.2] and z["n"][0] == 36000
    assert all(lo < dev < hi for lo, dev, hi in zip(z["ci_low"], z["adev"], z["ci_high"]))
    assert z["noise"]["arw_deg_per_sqrt_h"] == pytest.approx(60 * z["noise"]["noise_density_dps_per_sqrt_hz"])


def test_allan_table_plot_and_kalibr(static_log):
    r = run("allan", static_log / "s.csv", "--kind", "hdev", "--taus", "1,10,100", "--kalibr", static_log / "imu.yaml",
            "--rostopic", "/imu0", "--plot", static_log / "allan.png")
    assert r.returncode == 0, r.stderr
    assert "s.csv: gyro_x HDEV [deg/s]" in r.stdout and "noise terms" in r.stdout
    assert "noise type by" in r.stdout and "lag-1" in r.stdout  # what decided each tau's interval
    assert "accel_z" in r.stdout  # Kalibr needs the accelerometers, so they are analysed too
    text = (static_log / "imu.yaml").read_text()
    assert "gyroscope_noise_density:" in text and "update_rate:                 20" in text
    assert (static_log / "allan.png").read_bytes()[:4] == b"\x89PNG"


def test_allan_refuses_gaps_unless_split(tmp_path):
    t = np.arange(4000) / 10.0
    t[2500:] += 30.0
    rng = np.random.default_rng(0)
    pd.DataFrame({"time": t, "gyro_z": rng.standard_normal(4000)}).to_csv(tmp_path / "gap.csv", index=False)
    r = run("allan", tmp_path / "gap.csv")
    assert r.returncode == 2
    assert r.stderr.strip() == (  # one line: the reader's gap warning is not repeated before it
        f"gyrocomp: error: {tmp_path / 'gap.csv'}: time gap of 30.1 s after row 2500 (t = 249.9 s); Allan "
        "deviations need evenly spaced samples: use --split-gaps to pool the contiguous stretches")
    r = run("allan", tmp_path / "gap.csv", "--split-gaps", "--json")
    assert r.returncode == 0, r.stderr
    assert "pooled 2 contiguous stretches" in r.stderr and "warning" not in r.stderr
    assert json.loads(r.stdout)["axes"]["gyro_z"]["n"][0] == 2499 + 1499


@pytest.mark.parametrize("args,message", [
    (["--taus", "weekly"], r"Invalid value for --taus: use octave, decade, all or a comma-separated list"),
    (["--kind", "xdev"], r"Invalid value for '--kind'"),
    (["--axes", "gyro_q"], r"--axes: 'gyro_q' is not in .*s.csv; it has gyro_x, gyro_z, accel_x"),
    (["--plot", "allan.gif"], r"allan.gif: figure suffix '.gif' is not one of .png, .svg, .pdf"),
    (["--fit-taus", "5,1"], r"Invalid value for --fit-taus: use MIN,MAX in seconds with 0 < MIN < MAX"),
    (["--fit-taus", "1e5,1e6"], r"--fit-taus: fewer than two taus between 100000 and 1e\+06 s"),
])
def test_allan_usage_errors(static_log, args, message):
    r = run("allan", static_log / "s.csv", *args, cwd=static_log)
    assert r.returncode == 2
    assert len(r.stderr.strip().splitlines()) == 1
    assert re.search(message, r.stderr), r.stderr


def test_allan_never_overwrites_its_input(static_log):
    before = (static_log / "s.csv").read_bytes()
    r = run("allan", static_log / "s.csv", "--kalibr", static_log / "s.csv")
    assert r.returncode == 2 and "--kalibr" in r.stderr and "this is an input file" in r.stderr
    assert (static_log / "s.csv").read_bytes() == before


def test_fit_pipeline_option(tmp_path):
    r = run("simulate", "--preset", "consumer", "--profile", "tumble", "--rate", 1, "--runs", 2, "-o", tmp_path / "t.csv")
    assert r.returncode == 0, r.stderr
    r = run("fit", tmp_path / "t_0.csv", tmp_path / "t_1.csv", "-o", tmp_path / "m.json", "--pipeline", "matrix>poly")
    assert r.returncode == 0, r.stderr
    model = json.loads((tmp_path / "m.json").read_text())
    assert model["model"].startswith("matrix>poly: g-sensitivity > ")
    assert model["fit_report"]["pipeline"] == "matrix>poly" and len(model["fit_report"]["stages"]) == 2
    r = run("fit", tmp_path / "t_0.csv", "-o", tmp_path / "m.json", "--pipeline", "poly+matrix")
    assert r.returncode == 2 and "--pipeline: 'poly+matrix'; use one of joint, poly>matrix" in r.stderr


def test_validate_prints_every_method_and_json_holds_the_folds(workdir):
    runs = sorted(str(p) for p in Path(workdir).glob("run*.csv"))[:3]
    out = run("validate", *runs, "--json")
    assert out.returncode == 0, out.stderr
    result = json.loads(out.stdout)
    assert result["fold_kind"] == "runs" and len(result["folds"]) == 3
    assert result["methods"] == ["raw", "PX4 cubic", "ArduPilot cubic", "cubic + run constants", "gyrocomp default",
                                 "gyrocomp for firmware"]
    means = result["mean_over_axes_dps"]
    # chamber runs with a strong tempco: every model beats the raw output
    assert all(means[m] < means["raw"] for m in result["methods"] if m != "raw")
    table = run("validate", *runs, "--candidate", "poly:1")
    assert table.returncode == 0, table.stderr
    assert "gyrocomp poly:1" in table.stdout and "vs cubic" in table.stdout
    bad = run("validate", *runs, "--folds", "sideways")
    assert bad.returncode == 2 and "--folds" in bad.stderr


def test_a_model_with_nan_coefficients_is_refused_before_anything_is_written(workdir, tmp_path):
    d = json.loads((workdir / "model.json").read_text())
    d["axes"]["gyro_x"]["temperature"]["coefficients_dps"][1] = float("nan")
    (tmp_path / "nan.json").write_text(json.dumps(d))  # Python writes the NaN token JSON readers accept
    r = run("export", tmp_path / "nan.json", "--format", "px4", "-o", tmp_path / "tc.params")
    assert r.returncode == 2 and not (tmp_path / "tc.params").exists()
    assert r.stderr.strip() == (f"gyrocomp: error: {tmp_path / 'nan.json'}: "
                                "axes.gyro_x.temperature.coefficients_dps[1]: nan is not a finite number")


def test_apply_refuses_an_axis_the_model_lacks_unless_axes_are_named(workdir, tmp_path):
    d = json.loads((workdir / "model.json").read_text())
    d["axes"] = {"gyro_z": d["axes"]["gyro_z"]}
    (tmp_path / "z.json").write_text(json.dumps(d))
    r = run("apply", tmp_path / "z.json", workdir / "run3.csv", "-o", tmp_path / "out.csv")
    assert r.returncode == 2 and not (tmp_path / "out.csv").exists()
    assert r.stderr.strip() == (f"gyrocomp: error: {workdir / 'run3.csv'}: the model has no curve for gyro_x, gyro_y "
                                "(it covers gyro_z); give --axes with the axes to compensate, the others are then "
                                "left raw")
    r = run("apply", tmp_path / "z.json", workdir / "run3.csv", "-o", tmp_path / "out.csv", "--axes", "gyro_z")
    assert r.returncode == 0, r.stderr
    assert "gyro_x, gyro_y left raw (not among the axes to compensate)" in r.stderr
    assert "gyro_z compensated" in r.stdout
    raw, out = pd.read_csv(workdir / "run3.csv"), pd.read_csv(tmp_path / "out.csv")
    assert (out["gyro_x"] == raw["gyro_x"]).all() and not (out["gyro_z"] == raw["gyro_z"]).all()


@pytest.mark.parametrize("message, shown", [
    ("window_s: must be positive, got -1", "--window: must be positive, got -1"),
    ("a.csv: the model has no curve for gyro_x; give axes= with the axes", "a.csv: the model has no curve for gyro_x; give --axes with the axes"),
    ("no temperature column (map it with columns={'temperature': 'NAME'}, or fit with temperature=none)",
     "no temperature column (map it with --columns temperature=NAME, or fit with --temperature none)"),
    ("row 2: nan (drop such rows explicitly (drop_nonfinite=True))", "row 2: nan (drop such rows explicitly (--drop-nan))"),
    ("a.ulg: instance=3: no sensor_gyro instance 3", "a.ulg: --instance 3: no sensor_gyro instance 3"),
    # what is not a parameter stays: axis names, words in file paths, parameters the command line lacks
    ("/data/axes: gyro_z: the temperature does not vary; fit_report: x", "/data/axes: gyro_z: the temperature does not vary; fit_report: x"),
])
def test_library_messages_are_shown_with_the_flags_that_set_their_parameters(message, shown):
    assert in_cli_words(message) == shown


def test_apply_drop_nan_leaves_the_dropped_rows_out_and_keeps_the_others(workdir, tmp_path):
    raw = pd.read_csv(workdir / "run3.csv").iloc[:200].copy()
    raw.loc[5, "temperature"] = np.nan  # the gyro values of row 7 (1-based, after the header) are valid
    raw.to_csv(tmp_path / "holes.csv", index=False)
    r = run("apply", workdir / "model.json", tmp_path / "holes.csv", "-o", tmp_path / "out.csv", "--drop-nan")
    assert r.returncode == 0, r.stderr
    assert "dropped 1 of 200 rows" in r.stderr and "wrote" in r.stdout and ": 199 rows," in r.stdout
    out = pd.read_csv(tmp_path / "out.csv")
    assert len(out) == 199 and not out.isna().any().any()
    np.testing.assert_array_equal(out["time"], raw["time"].drop(index=5))


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this platform")
def test_special_outputs_are_refused_and_links_written_through(workdir, tmp_path):
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    r = run("apply", workdir / "model.json", workdir / "run3.csv", "-o", fifo)
    assert r.returncode == 2 and r.stderr.strip() == f"gyrocomp: error: {fifo}: is a FIFO; outputs are written to " \
                                                     "regular files (name a new path)"
    assert fifo.is_fifo()
    r = run("apply", workdir / "model.json", workdir / "run3.csv", "-o", "-")
    assert r.returncode == 2 and "-: gyrocomp writes its outputs to files, not to standard output" in r.stderr
    assert not Path("-").exists()
    # a symbolic link is written through: the link stays, its target gets the output
    (tmp_path / "real.csv").write_text("old\n")
    (tmp_path / "link.csv").symlink_to(tmp_path / "real.csv")
    r = run("apply", workdir / "model.json", workdir / "run3.csv", "-o", tmp_path / "link.csv")
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "link.csv").is_symlink() and (tmp_path / "real.csv").read_text().startswith("time,gyro_x,")


def test_sigterm_leaves_no_temporary_file(tmp_path):
    # the console script's signal handling around an atomic write interrupted half-way
    code = ("import os, signal, sys; from gyrocomp import cli; from gyrocomp.io.atomic import atomic_path\n"
            "cli._exit_on_termination()\n"
            "with atomic_path(sys.argv[1]) as tmp:\n"
            "    tmp.write_text('half')\n"
            "    os.kill(os.getpid(), signal.SIGTERM)\n")
    done = subprocess.run([sys.executable, "-c", code, str(tmp_path / "out.csv")], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 128 + 15, done.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads files whatever their permissions")
def test_permission_denied_is_a_bad_input_in_one_line(workdir, tmp_path):
    locked = tmp_path / "locked.csv"
    shutil.copy(workdir / "run3.csv", locked)
    locked.chmod(0)
    r = run("apply", workdir / "model.json", locked, "-o", tmp_path / "o.csv")
    assert r.returncode == 2 and r.stderr.strip() == f"gyrocomp: error: {locked}: permission denied; check its permissions"


def test_a_model_that_is_a_symbolic_link_loop(workdir, tmp_path):
    loop = tmp_path / "loop.json"
    loop.symlink_to(loop)
    r = run("apply", loop, workdir / "run3.csv", "-o", tmp_path / "o.csv")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1
    assert r.stderr.strip() == f"gyrocomp: error: {loop}: cannot read the model file (too many levels of symbolic links)"


def test_a_write_the_file_system_refuses_is_a_bad_input_and_leaves_nothing(workdir, tmp_path):
    resource = pytest.importorskip("resource")
    limit = lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (64 * 1024, 64 * 1024))  # noqa: E731 - ulimit -f 64
    done = subprocess.run([shutil.which("gyrocomp") or str(Path(sys.executable).with_name("gyrocomp")), "apply",
                           str(workdir / "model.json"), str(workdir / "run3.csv"), "-o", str(tmp_path / "o.csv")],
                          capture_output=True, text=True, preexec_fn=limit, timeout=300)
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith("gyrocomp: error: ") and "file too large" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("exc, line", [
    (PermissionError(13, "Permission denied", "x.csv"), "x.csv: permission denied; check its permissions"),
    (OSError(28, "No space left on device", "o.csv"), "o.csv: no space left on device; the disk is full; free space and run again"),
    (MemoryError(), "not enough memory for this size of data; process it in pieces or on a larger machine"),
])
def test_environment_errors_read_as_one_line(exc, line):
    assert _environment_message(exc) == line


def test_a_tab_separated_export_with_decimal_commas_reads_with_or_without_options(tmp_path):
    (tmp_path / "v.txt").write_text("Time\tGyro_Z\tTemperature\n0\t1,5\t20,5\n1\t2,5\t21\n2\t3\t22\n")
    for extra in ([], ["--delimiter", "tab", "--decimal", ","]):
        r = run("convert", tmp_path / "v.txt", tmp_path / "o.csv", *extra)
        assert r.returncode == 0, r.stderr
        out = pd.read_csv(tmp_path / "o.csv")
        assert list(out["gyro_z"]) == [1.5, 2.5, 3.0] and list(out["temperature"]) == [20.5, 21.0, 22.0]
    r = run("convert", tmp_path / "v.txt", tmp_path / "o.csv", "--decimal", ":")
    assert r.returncode == 2 and r.stderr.strip() == "gyrocomp: error: --decimal: ':'; use '.' or ','"


def test_control_characters_in_a_message_are_escaped_to_keep_one_line(tmp_path):
    """A file name (or a foreign library's message) with a newline or a raw byte stays one escaped line."""
    odd = tmp_path / "two\nlines\x1b.csv"
    odd.write_text("time,gyro_z\n0,1\n")
    result = run("allan", odd)
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and "two\\nlines\\x1b.csv" in result.stderr, result.stderr


def test_fit_and_evaluate_state_the_drift_to_expect_from_one_run(tmp_path):
    for seed, name in ((3, "one.csv"), (4, "two.csv")):
        r = run("simulate", "--profile", "cycle", "--duration", 6000, "--rate", 2, "--seed", seed, "-o", tmp_path / name)
        assert r.returncode == 0, r.stderr
    r = run("fit", tmp_path / "one.csv", "-o", tmp_path / "m.json")
    assert r.returncode == 0, r.stderr
    assert "model choice by held-out drift (legs: 4 folds" in r.stdout
    r = run("evaluate", tmp_path / "m.json", tmp_path / "two.csv")
    assert r.returncode == 0, r.stderr
    assert "drift to expect on unseen data (the model file's 4 held-out legs" in r.stdout
    r = run("evaluate", tmp_path / "m.json", tmp_path / "two.csv", "--json")
    expected = json.loads(r.stdout)["expected_held_out_drift"]
    model = json.loads((tmp_path / "m.json").read_text())["fit_report"]["selection"]
    assert [e["axis"] for e in expected] == ["gyro_x", "gyro_y", "gyro_z"]
    for e in expected:
        sel = model[e["axis"]]
        assert e["drift_dps"] == sel["chosen_drift_dps"] and e["standard_error_dps"] == sel["chosen_standard_error_dps"]
        assert e["fold_kind"] == "legs" and e["folds"] == 4 and not e["thin"]


@pytest.mark.parametrize("args, message", [
    (("simulate", "--rate", "inf", "-o", "x.csv"), "Invalid value for '--rate': inf is not a finite number"),
    (("simulate", "--rate", "nan", "-o", "x.csv"), "Invalid value for '--rate': nan is not a finite number"),
    (("simulate", "--set-points", "10,inf", "-o", "x.csv"), "Invalid value for --set-points: '10,inf': give finite"),
    (("simulate", "--duration", "1e999", "-o", "x.csv"), "Invalid value for '--duration': inf is not a finite number"),
])
def test_number_options_are_finite_or_refused_in_one_line(tmp_path, args, message):
    r = run(*args, cwd=tmp_path)
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and message in r.stderr
    assert not (tmp_path / "x.csv").exists()


def test_window_inf_and_learn_rate_0_are_refused(workdir, tmp_path):
    r = run("evaluate", workdir / "model.json", workdir / "run3.csv", "--window", "inf")
    assert r.returncode == 2 and "Invalid value for '--window': inf is not a finite number" in r.stderr
    r = run("learn", workdir / "run1.csv", "--rate", "0", "-o", tmp_path / "m.json")
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "--rate: must be positive, got 0" in r.stderr
