"""`gyrocomp simulate`, run through the real entry point in a subprocess."""

import json
import re

import numpy as np
import pandas as pd

from ..conftest import run


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
    r = run(
        "simulate",
        "--preset",
        "adxrs450",
        "--profile",
        "cycle",
        "--duration",
        3600,
        "--rate",
        2,
        "--runs",
        3,
        "--seed",
        10,
        "-o",
        tmp_path / "cyc.csv",
        "--truth",
        tmp_path / "truth.json",
        "--truth-columns",
    )
    assert r.returncode == 0, r.stderr
    assert [p.name for p in sorted(tmp_path.glob("cyc_*.csv"))] == ["cyc_0.csv", "cyc_1.csv", "cyc_2.csv"]
    truth = json.loads((tmp_path / "truth.json").read_text())
    assert [run_["seed"] for run_ in truth["runs"]] == [10, 11, 12]
    biases = [run_["turn_on_bias_dps"]["gyro_z"] for run_ in truth["runs"]]
    assert len(set(biases)) == 3
    assert truth["error_model"]["hysteresis"]["band_degc"] == [55.0, 80.0]
    for i in range(3):
        df = pd.read_csv(tmp_path / f"cyc_{i}.csv")
        assert list(df.columns) == [
            "time",
            "gyro_z",
            "temperature",
            "true_error_gyro_z",
            "true_noise_gyro_z",
            "true_rate_gyro_z",
            "true_structure_temperature",
        ]
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
