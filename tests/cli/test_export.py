"""``gyrocomp export`` through the real entry point: the C sources and an autopilot file with what the firmware
leaves against the model."""

from __future__ import annotations

import warnings

import pytest

from gyrocomp import fit_calibration
from gyrocomp.errors import InputError
from gyrocomp.export.c_code import c_sources
from gyrocomp.io.tables import write_recording
from gyrocomp.simulation import get_profile, simulate

from ..conftest import run


def test_lag_needs_the_rate_and_the_cli_writes_a_folder(tmp_path):
    prof = get_profile("cycle", set_points_degc=(-30.0, 80.0), cycles=1)
    runs = [simulate("adxrs450", profile=prof, rate_hz=1, seed=s).recording for s in range(2)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration(runs, hysteresis="lag")
    with pytest.raises(InputError, match="the model has thermal lag; give the data's sample rate with rate_hz="):
        c_sources(cal)
    cal.save(tmp_path / "m.json")
    r = run("export", tmp_path / "m.json", "--format", "c", "--rate", 1, "-o", tmp_path / "fw")
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "fw" / "gyrocomp.h").read_text().count("typedef struct gyrocomp_state") == 1
    r = run("export", tmp_path / "m.json", "--format", "c", "-o", tmp_path / "fw2")
    assert r.returncode == 2 and "give the data's sample rate with --rate" in r.stderr


def test_export_prints_what_the_firmware_leaves_against_the_model(tmp_path):
    runs = [
        simulate("adxrs450", profile=get_profile("cycle", set_points_degc=(-30.0, 80.0), cycles=1), rate_hz=1, seed=s)
        for s in range(2)
    ]
    paths = []
    for k, sim in enumerate(runs):
        paths.append(tmp_path / f"c{k}.csv")
        write_recording(sim.recording, paths[-1])
    assert run("fit", *paths, "-o", tmp_path / "m.json", "--hysteresis", "lag").returncode == 0
    r = run("export", tmp_path / "m.json", "--format", "px4", "-o", tmp_path / "t.params", "--device-id", 3)
    assert r.returncode == 0, r.stderr
    line = next(x for x in r.stdout.splitlines() if x.startswith("gyro_z: firmware vs model"))
    numbers = [float(v) for v in line.replace("(", " ").replace(")", " ").split() if v[0].isdigit()]
    in_range, beyond, as_run = numbers[0], numbers[2], numbers[5]
    assert "in range" in line and "beyond it" in line and "as it runs" in line
    assert as_run > in_range  # the lag the file cannot carry, and PX4's 1 degC steps
    assert beyond > 0
