"""`gyrocomp fit`, run through the real entry point in a subprocess."""

import json
import re

import pytest

from ..conftest import run


def test_fit_prints_table_and_writes_model(workdir):
    r = run("fit", workdir / "run1.csv", workdir / "run2.csv", "-o", workdir / "auto.json")
    assert r.returncode == 0, r.stderr
    # two runs that only heat: each run's one heating leg is held out (never time blocks unless asked), and two
    # folds are said to be thin evidence
    assert "model choice by held-out drift (legs: 2 folds" in r.stdout
    assert "held-out drift per fold" in r.stdout and "run 2 leg 1 (heating)" in r.stdout
    # one row per fold, one column per axis and model role: the table's width does not grow with the folds
    per_fold = r.stdout[r.stdout.index("held-out drift per fold") :]
    assert re.search(r"fold\s+\S\s+gyro_x chosen\s+\S\s+gyro_x", per_fold) and "gyro_z chosen" in per_fold
    assert "only 2 heating and cooling legs to hold out; the evidence for each axis's choice is thin" in r.stderr
    model = json.loads((workdir / "auto.json").read_text())
    assert model["fit_report"]["order_selection"] == "leave-one-leg-out"
    for axis in ("gyro_x", "gyro_y", "gyro_z"):
        sel = model["fit_report"]["selection"][axis]
        assert len(sel["folds"]) == 2 and all(len(c["fold_drift_dps"]) == 2 for c in sel["candidates"])
        assert sel["chosen_drift_dps"] <= sel["raw_drift_dps"]
        assert sel["chosen_standard_error_dps"] >= 0 and sel["fold_note"] == ""
        # two folds are thin: the order test on all the data was asked, and which rule decided is said, in the
        # table and in one line per axis
        assert sel["order_test"]["threshold"] == pytest.approx(9.0) and len(sel["order_test"]["statistics"]) == 5
        assert sel["decided_by"]
        assert re.search(
            rf"{axis}: (left with its constant only; do no harm|{re.escape(sel['chosen']['label'])}; )", r.stderr
        )
    assert "decided by" in r.stdout


@pytest.mark.slow
def test_fit_compares_hysteresis_candidates_on_cycles(tmp_path):
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
        "-o",
        tmp_path / "c.csv",
    )
    assert r.returncode == 0, r.stderr
    r = run(
        "fit",
        tmp_path / "c_0.csv",
        tmp_path / "c_1.csv",
        "-o",
        tmp_path / "m.json",
        "--hysteresis-band",
        "55,80",
        "--hysteresis-order",
        "2",
    )
    assert r.returncode == 0, r.stderr
    assert "hysteresis / thermal lag by leave-one-run-out" in r.stdout
    for candidate in ("none", "turning-point", "lag", "turning-point+lag"):
        assert candidate in r.stdout
    assert re.search(r"lag \d+(\.\d+)? s, turning-point hysteresis order 2 in 55..80 degC", r.stdout)
    model = json.loads((tmp_path / "m.json").read_text())
    scores = model["fit_report"]["hysteresis"]["axes"]["gyro_z"]["scores_dps"]
    # every memory scored, the heating and cooling branches and the temperature-rate terms too (the runs heat and cool)
    memories = {"none", "turning-point", "lag", "turning-point+lag", "branch", "branch+lag", "rate", "rate+lag"}
    assert set(scores) == memories
    assert model["axes"]["gyro_z"]["hysteresis"]["band_degc"] == [55.0, 80.0]


@pytest.mark.slow
def test_fit_prints_only_what_was_fitted(tmp_path):
    """A chamber run in one orientation fits no G: no table of "not fitted" cells; no fit-RMS column of dashes."""
    r = run(
        "simulate", "--preset", "consumer", "--profile", "cycle", "--rate", 0.1, "--runs", 2, "-o", tmp_path / "c.csv"
    )
    assert r.returncode == 0, r.stderr
    r = run("fit", tmp_path / "c_0.csv", tmp_path / "c_1.csv", "-o", tmp_path / "m.json")
    assert r.returncode == 0, r.stderr
    assert "g-sensitivity G" not in r.stdout and "not fitted" not in r.stdout
    assert "fit RMS" not in r.stdout and "constants [deg/s]" in r.stdout


@pytest.mark.slow
def test_fit_g_sensitivity_table_and_stages(tmp_path):
    r = run(
        "simulate",
        "--preset",
        "consumer",
        "--profile",
        "combined",
        "--rate",
        1,
        "--duration",
        14000,
        "--runs",
        2,
        "-o",
        tmp_path / "c.csv",
    )
    assert r.returncode == 0, r.stderr
    r = run(
        "simulate",
        "--preset",
        "consumer",
        "--profile",
        "combined",
        "--rate",
        1,
        "--duration",
        14000,
        "--seed",
        9,
        "-o",
        tmp_path / "held.csv",
    )
    assert r.returncode == 0, r.stderr
    r = run("fit", tmp_path / "c_0.csv", tmp_path / "c_1.csv", "-o", tmp_path / "m.json")
    assert r.returncode == 0, r.stderr
    assert "g-sensitivity G [deg/s/g] +- standard error" in r.stdout
    assert re.search(
        r"gyro_x\s*\S\s*\+0\.(09|10)\d* \+- 0\.00\d+", r.stdout
    )  # the preset's 0.1 deg/s/g on the diagonal
    model = json.loads((tmp_path / "m.json").read_text())
    assert model["axes"]["gyro_y"]["g_sensitivity_dps_per_g"][1] == pytest.approx(0.1, abs=0.01)
    r = run("evaluate", tmp_path / "m.json", tmp_path / "held.csv", "--stages", "--window", 100)
    assert r.returncode == 0, r.stderr
    for stage in ("raw", "temperature only", "temperature + acceleration"):
        assert stage in r.stdout
    r = run("evaluate", tmp_path / "m.json", tmp_path / "held.csv", "--stages", "--json", "--window", 100)
    stages = json.loads(r.stdout)["runs"][0]["stages"]
    assert (
        stages["temperature + acceleration"]["gyro_z"]["bias_offset_comp_dps"]
        < stages["temperature only"]["gyro_z"]["bias_offset_comp_dps"]
    )
    r = run("fit", tmp_path / "c_0.csv", "-o", tmp_path / "x.json", "--acceleration", "cubic")
    assert r.returncode == 2 and "Invalid value for '--acceleration'" in r.stderr


@pytest.mark.slow
def test_fit_pipeline_option(tmp_path):
    r = run(
        "simulate", "--preset", "consumer", "--profile", "tumble", "--rate", 1, "--runs", 2, "-o", tmp_path / "t.csv"
    )
    assert r.returncode == 0, r.stderr
    r = run("fit", tmp_path / "t_0.csv", tmp_path / "t_1.csv", "-o", tmp_path / "m.json", "--pipeline", "matrix>poly")
    assert r.returncode == 0, r.stderr
    model = json.loads((tmp_path / "m.json").read_text())
    assert model["model"].startswith("matrix>poly: g-sensitivity > ")
    assert model["fit_report"]["pipeline"] == "matrix>poly" and len(model["fit_report"]["stages"]) == 2
    r = run("fit", tmp_path / "t_0.csv", "-o", tmp_path / "m.json", "--pipeline", "poly+matrix")
    assert r.returncode == 2 and "--pipeline: 'poly+matrix'; use one of joint, poly>matrix" in r.stderr


@pytest.mark.slow
def test_fit_and_evaluate_state_the_drift_to_expect_from_one_run(tmp_path):
    for seed, name in ((3, "one.csv"), (4, "two.csv")):
        r = run(
            "simulate", "--profile", "cycle", "--duration", 6000, "--rate", 2, "--seed", seed, "-o", tmp_path / name
        )
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


def test_a_log_too_short_to_judge_at_one_temperature_is_refused_with_the_reason(tmp_path):
    """Six samples at one temperature (a truncated log): before, fitted into a model of constants (exit 0) with
    'no static segment found' printed twice; now refused in one line saying why and what to do, each warning once,
    no model file; asked for the constants alone, fitted."""
    rows = ["time,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z,temperature"] + [
        f"{0.1 * k:.1f},0.1,0.2,{0.3 + 0.001 * k},0.01,0.02,{1.0 + 0.01 * k},{40.0 + 0.05 * k:.2f}" for k in range(6)
    ]
    (tmp_path / "short.csv").write_text("\n".join(rows) + "\n")
    done = run("fit", tmp_path / "short.csv", "-o", tmp_path / "m.json")
    assert done.returncode == 2 and not (tmp_path / "m.json").exists()
    errors = [line for line in done.stderr.splitlines() if "error" in line]
    assert errors == [
        f"gyrocomp: error: {tmp_path / 'short.csv'}: 6 samples over 0.25 degC: too little to hold any "
        "of it out, and no temperature range to fit a curve over; a calibration needs runs over a "
        "temperature range (for the turn-on constants alone, fit with --temperature None)"
    ]
    warned = [line for line in done.stderr.splitlines() if "warning" in line]
    assert len(warned) == len(set(warned)), warned  # each said once
    constants = run("fit", tmp_path / "short.csv", "-o", tmp_path / "m.json", "--temperature", "none")
    assert constants.returncode == 0, constants.stderr
