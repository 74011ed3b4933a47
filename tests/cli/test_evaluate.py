"""`gyrocomp evaluate`, run through the real entry point in a subprocess."""

import json
import re

from ..conftest import run


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
