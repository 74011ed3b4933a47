"""`gyrocomp allan`, run through the real entry point in a subprocess."""

import json
import re

import numpy as np
import pandas as pd
import pytest

from ..conftest import run


def test_allan_json_has_exactly_the_documented_shape(static_log):
    r = run("allan", static_log / "s.csv", "--json", "--axes", "gyro_z")
    assert r.returncode == 0, r.stderr
    doc = json.loads(r.stdout)
    assert set(doc) == {"rate_hz", "axes"} and doc["rate_hz"] == 20.0
    z = doc["axes"]["gyro_z"]
    assert list(z) == ["tau_s", "adev", "n", "ci_low", "ci_high", "noise"]
    assert list(z["noise"]) == [
        "noise_density_dps_per_sqrt_hz",
        "arw_deg_per_sqrt_h",
        "bias_instability_deg_per_h",
        "integration_time_s",
        "rrw_deg_per_h_per_sqrt_h",
        "quantization_deg",
        "rate_ramp_deg_per_h2",
    ]
    assert z["tau_s"][:3] == [0.05, 0.1, 0.2] and z["n"][0] == 36000
    assert all(lo < dev < hi for lo, dev, hi in zip(z["ci_low"], z["adev"], z["ci_high"]))
    assert z["noise"]["arw_deg_per_sqrt_h"] == pytest.approx(60 * z["noise"]["noise_density_dps_per_sqrt_hz"])


def test_allan_table_plot_and_kalibr(static_log):
    r = run(
        "allan",
        static_log / "s.csv",
        "--kind",
        "hdev",
        "--taus",
        "1,10,100",
        "--kalibr",
        static_log / "imu.yaml",
        "--rostopic",
        "/imu0",
        "--plot",
        static_log / "allan.png",
    )
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
        "deviations need evenly spaced samples: use --split-gaps to pool the contiguous stretches"
    )
    r = run("allan", tmp_path / "gap.csv", "--split-gaps", "--json")
    assert r.returncode == 0, r.stderr
    assert "pooled 2 contiguous stretches" in r.stderr and "warning" not in r.stderr
    assert json.loads(r.stdout)["axes"]["gyro_z"]["n"][0] == 2499 + 1499


@pytest.mark.parametrize(
    "args,message",
    [
        (["--taus", "weekly"], r"Invalid value for --taus: use octave, decade, all or a comma-separated list"),
        (["--kind", "xdev"], r"Invalid value for '--kind'"),
        (["--axes", "gyro_q"], r"--axes: 'gyro_q' is not in .*s.csv; it has gyro_x, gyro_z, accel_x"),
        (["--plot", "allan.gif"], r"allan.gif: figure suffix '.gif' is not one of .png, .svg, .pdf"),
        (["--fit-taus", "5,1"], r"Invalid value for --fit-taus: use MIN,MAX in seconds with 0 < MIN < MAX"),
        (["--fit-taus", "1e5,1e6"], r"--fit-taus: fewer than two taus between 100000 and 1e\+06 s"),
    ],
)
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
