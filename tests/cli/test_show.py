"""``gyrocomp show``: a model file in one screen, and as JSON, through the real entry point."""

import dataclasses
import json
import warnings

import pytest

from gyrocomp import fit_calibration
from gyrocomp.simulation import get_profile, simulate

from ..conftest import run


@pytest.mark.slow
def test_show_names_the_axes_the_device_ids_and_the_expected_drift(tmp_path):
    runs = [
        simulate(
            "consumer", profile=get_profile("cycle", set_points_degc=(-20.0, 70.0), cycles=1), rate_hz=1, seed=s
        ).recording
        for s in range(2)
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration(runs)
    inputs = [{**i, "device_id": 2293768} for i in cal.provenance["inputs"]]
    cal = dataclasses.replace(cal, provenance={**cal.provenance, "inputs": inputs})
    cal.save(tmp_path / "m.json")
    r = run("show", tmp_path / "m.json")
    assert r.returncode == 0, r.stderr
    assert f"m.json: {cal.model} (schema {cal.schema_version})" in r.stdout and "on 2 run(s)" in r.stdout
    assert "device ids (gyro, accelerometer): 2293768, None" in r.stdout
    assert "drift to expect on unseen data" in r.stdout and r.stdout.count("gyro_") >= 6
    r = run("show", tmp_path / "m.json", "--json")
    data = json.loads(r.stdout)
    assert [a["axis"] for a in data["axes"]] == ["gyro_x", "gyro_y", "gyro_z"]
    assert data["axes"][0]["range_degc"][0] < -15 and data["axes"][0]["lag_time_constant_s"] > 0
    assert len(data["expected_held_out_drift"]) == 3 and data["target"] == "model"
    missing = run("show", tmp_path / "nope.json")
    assert missing.returncode == 2 and "no such model file" in missing.stderr


@pytest.mark.slow
def test_quiet_prints_only_errors(tmp_path):
    made = run("simulate", "--profile", "chamber", "--duration", 3000, "--rate", 1, "-o", tmp_path / "c.csv")
    assert made.returncode == 0
    loud = run("fit", tmp_path / "c.csv", "-o", tmp_path / "m.json")
    assert "warning" in loud.stderr and loud.stdout  # one heating run: time blocks, said; tables printed
    quiet = run("-q", "fit", tmp_path / "c.csv", "-o", tmp_path / "m2.json")
    assert quiet.returncode == 0 and quiet.stdout == "" and quiet.stderr == ""
    failed = run("-q", "fit", tmp_path / "nope.csv", "-o", tmp_path / "m3.json")
    assert failed.returncode == 2 and failed.stderr.startswith("gyrocomp: error:")
    # evaluate printed its tables, and its note that the file was fitted on, under -q
    for args in (["evaluate", tmp_path / "m.json", tmp_path / "c.csv"], ["allan", tmp_path / "c.csv"]):
        quiet = run("-q", *args)
        assert quiet.returncode == 0 and quiet.stdout == "" and quiet.stderr == "", args
        assert run(*args).stdout  # without -q: the tables
