"""gyrocomp noise through the real entry point: the model printed, each export written and read back, several
logs in one call, the options' errors in one line with nothing written."""

import json
import math
import re

import pytest

from ..conftest import run


@pytest.mark.slow
def test_noise_prints_the_model_and_writes_each_export(static_log, tmp_path):
    log = static_log / "s.csv"
    done = run("noise", log)
    assert done.returncode == 0, done.stderr
    assert "noise model at 20 Hz" in done.stdout and "gyro_x" in done.stdout and "gyro_z" in done.stdout
    written = run("noise", log, "--export", "json", "-o", tmp_path / "m.json")
    assert written.returncode == 0, written.stderr
    model = json.loads((tmp_path / "m.json").read_text())
    assert {"gyro_x", "gyro_z", "accel_x"} <= set(model["axes"]) and model["rate_hz"] == 20.0
    largest = max(
        a["bound"]["white_noise_density_u_per_sqrt_hz"] for name, a in model["axes"].items() if name.startswith("gyro")
    )
    kalibr = run("noise", log, "--export", "kalibr", "-o", tmp_path / "imu.yaml", "--rostopic", "/imu")
    assert kalibr.returncode == 0, kalibr.stderr
    text = (tmp_path / "imu.yaml").read_text()
    assert re.search(r'^rostopic: +"/imu" ', text, re.M) and "accelerometer_noise_density" in text
    density = float(text.split("gyroscope_noise_density:")[1].split()[0])
    assert abs(density - math.radians(largest)) <= 1e-6 * density  # the larger axis's N in rad/s/sqrt(Hz)
    two = run("noise", log, log.with_name("s.csv"), "--export", "json", "-o", tmp_path / "two.json")
    assert two.returncode == 0, two.stderr


def test_noise_options_are_checked_and_nothing_is_written(static_log, tmp_path):
    log = static_log / "s.csv"
    alone = run("noise", log, "--export", "kalibr")
    assert (
        alone.returncode == 2
        and alone.stderr.strip().splitlines()[-1].startswith("gyrocomp: error:")
        and "give --export and -o together" in alone.stderr
    )
    vins = run("noise", log, "--axes", "gyro_x", "--export", "vins", "-o", tmp_path / "v.yaml")
    assert vins.returncode == 2 and "export vins: the logs have no accelerometer axes" in vins.stderr
    assert not (tmp_path / "v.yaml").exists()
    over = run("noise", log, "--export", "json", "-o", log)
    assert over.returncode == 2 and "input" in over.stderr


def test_noise_of_a_chamber_runs_dwells(tmp_path):
    made = run(
        "simulate",
        "--profile",
        "chamber",
        "--set-points",
        "-20,25,70",
        "--dwell",
        1200,
        "--rate",
        10,
        "--axes",
        "z",
        "-o",
        tmp_path / "ch.csv",
    )
    assert made.returncode == 0, made.stderr
    done = run(
        "noise", tmp_path / "ch.csv", "--dwells", "--axes", "gyro_z", "--export", "json", "-o", tmp_path / "m.json"
    )
    assert done.returncode == 0, done.stderr
    logs = json.loads((tmp_path / "m.json").read_text())["axes"]["gyro_z"]["logs"]
    assert [round(log["temperature_degc"]) for log in logs] == [-20, 25, 70]
    assert "N at one sample [95 %]" in done.stdout and "at 70.0 degC" in done.stdout
    for log in logs:  # each dwell's bound with Gauss-Markov terms, said in the table as in the file
        markov = log["bound_with_markov"]
        said = f"{len(markov['gauss_markov'])}: {markov['ratio_to_measured_median']:.2f} / "
        assert said in done.stdout


@pytest.mark.slow
def test_noise_with_a_model_says_what_compensation_buys(tmp_path):
    made = run(
        "simulate", "--preset", "consumer", "--profile", "cycle", "--rate", 2, "--runs", 3, "-o", tmp_path / "c.csv"
    )
    assert made.returncode == 0, made.stderr
    fitted = run("fit", tmp_path / "c_0.csv", tmp_path / "c_1.csv", "-o", tmp_path / "m.json")
    assert fitted.returncode == 0, fitted.stderr
    done = run(
        "noise",
        tmp_path / "c_2.csv",
        "--model",
        tmp_path / "m.json",
        "--axes",
        "gyro_z",
        "--export",
        "json",
        "-o",
        tmp_path / "n.json",
    )
    assert done.returncode == 0, done.stderr
    assert "the bias random walk a filter needs" in done.stdout and "raw / compensated" in done.stdout
    ratio = float(done.stdout.split("gyro_z", 2)[2].split("│")[3])
    assert ratio > 10
    both = run("noise", tmp_path / "c_2.csv", "--model", tmp_path / "m.json", "--dwells")
    assert both.returncode == 2 and "give --model or --dwells, not both" in both.stderr


def test_noise_fits_the_ieee_952_model_on_the_taus_given_as_allan_does(static_log, tmp_path):
    """noise's warnings advise --fit-taus (the taus where a term holds, past an anti-alias filter): the option is
    noise's too, and its IEEE 952 figures are then allan's on the same taus; the bound does not change."""
    log = static_log / "s.csv"
    figures = {}
    for fit in (None, "1,100"):
        extra = ["--fit-taus", fit] if fit else []
        done = run("noise", log, "--axes", "gyro_z", "--export", "json", "-o", tmp_path / "m.json", *extra)
        assert done.returncode == 0, done.stderr
        model = json.loads((tmp_path / "m.json").read_text())["axes"]["gyro_z"]
        allan = run("allan", log, "--axes", "gyro_z", "--json", *extra)
        assert allan.returncode == 0, allan.stderr
        terms = json.loads(allan.stdout)["axes"]["gyro_z"]["noise"]
        assert model["ieee_952"]["white_noise_density"] == pytest.approx(
            terms["noise_density_dps_per_sqrt_hz"], rel=1e-12
        )
        assert model["ieee_952"]["bias_instability"] * 3600 == pytest.approx(
            terms["bias_instability_deg_per_h"], rel=1e-12
        )
        figures[fit] = model
    assert figures[None]["ieee_952"] != figures["1,100"]["ieee_952"]
    assert figures[None]["bound"] == figures["1,100"]["bound"]
    wrong = run("noise", log, "--fit-taus", "5,1")
    assert (
        wrong.returncode == 2
        and "Invalid value for --fit-taus: use MIN,MAX in seconds with 0 < MIN < MAX" in wrong.stderr
    )
