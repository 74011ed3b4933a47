"""Shared fixtures: simulated runs with known truth, and the shared datasets (skipped when absent)."""

from __future__ import annotations

import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from gyrocomp import Compensator, apply
from gyrocomp.models.pipelines import fit_channels
from gyrocomp.recording import ACCEL_AXES, GYRO_AXES, Recording
from gyrocomp.simulate import GyroErrorModel, simulate

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"
DATASETS = SHARED / "datasets"


def shared_dataset(name: str) -> Path:
    """Path of a folder in ../shared/datasets, or skip the test with a message saying what is missing."""
    path = DATASETS / name
    if not path.is_dir():
        pytest.skip(f"shared dataset {name!r} not found at {path}; these tests need ../shared beside the repository")
    return path


def xsens_session():
    """imu_tk's Xsens multi-position session (../shared/datasets/imu_tk-xsens) as a Recording: raw 16-bit counts
    around 32768, scaled by nominal factors only (about 3700 counts per g, imu_tk's 1/6258 (rad/s)/count); the
    calibrations find the real ones. Skips when the dataset is absent."""
    folder = shared_dataset("imu_tk-xsens")
    acc = np.loadtxt(folder / "xsens_acc.mat")
    gyro = np.loadtxt(folder / "xsens_gyro.mat")
    return Recording(acc[:, 0], np.degrees((gyro[:, 1:] - 32768) / 6258), GYRO_AXES,
                     accel_g=(acc[:, 1:] - 32768) / 3700.0, accel_axes=ACCEL_AXES, source="xsens")


@pytest.fixture(scope="session")
def consumer_model():
    """A consumer part's default model (thermal lag included), fitted on two 1-hour chamber runs at 2 Hz (unit 3,
    seeds 0 and 1); the model the chunked paths (apply_file, evaluate_file) are checked with."""
    runs = [simulate("consumer", profile="chamber", rate_hz=2, duration_s=3600, seed=s, unit=3).recording
            for s in range(2)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit_channels(runs)


#: the test sensor: MTi-10-class temperature drift, moderate bias instability
TEST_MODEL = GyroErrorModel(bias_instability_deg_per_h=5.0)


@pytest.fixture(scope="session")
def chamber_runs():
    """Seven 1-hour chamber runs at 20 Hz of TEST_MODEL (seeds 0..6), each with its own turn-on bias."""
    return [simulate(TEST_MODEL, profile="chamber", duration_s=3600, rate_hz=20, seed=s) for s in range(7)]


def assert_streaming_equals_batch(calibration, recording, cuts: list[int]) -> None:
    """Compensate ``recording`` in chunks of the lengths ``cuts`` (the rest in one) through a Compensator and
    check the output equals ``apply`` on the whole recording to 1e-12 [deg/s]."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        batch = apply(calibration, recording).gyro_dps
        comp = Compensator(calibration, recording.gyro_axes, rate_hz=recording.rate_hz)
        parts, start = [], 0
        for c in list(cuts) + [recording.n_samples]:
            stop = min(start + c, recording.n_samples)
            if stop > start:
                parts.append(comp.update(recording.time_s[start:stop], recording.gyro_dps[start:stop],
                                         recording.temperature_degc[start:stop]))
            start = stop
    np.testing.assert_allclose(np.concatenate(parts), batch, rtol=0, atol=1e-12)


#: the console script of this environment, run as a user would
SCRIPT = Path(sys.executable).parent / "gyrocomp"


def run(*args, cwd=None) -> subprocess.CompletedProcess:
    """Run the ``gyrocomp`` command through its real entry point in a subprocess (wide terminal, 300 s limit)."""
    cmd = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "gyrocomp"]
    env = {**os.environ, "COLUMNS": "200"}
    return subprocess.run([*cmd, *map(str, args)], capture_output=True, text=True, cwd=cwd, env=env, timeout=300)
