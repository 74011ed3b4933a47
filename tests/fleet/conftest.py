"""A simulated fleet on disk: units of the consumer preset's production spread, a few made bad on purpose."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from gyrocomp.io.tables import write_recording
from gyrocomp.simulation import preset_model, resolve_profile, simulate

from ..conftest import run

PRESET = "consumer"
#: each unit: three 15-minute chamber runs over the preset's range at 10 Hz
RUNS_PER_UNIT = 3
RUN_DURATION_S = 900.0
RATE_HZ = 10.0
FLEET_UNITS = 120
#: units made bad on purpose: three times the white noise, five times the temperature coefficients
NOISY_UNIT = 17
HOT_UNIT = 42
#: a unit one of whose files is not a table
CORRUPT_UNIT = 99
PATTERN = "{serial}/run_{n}.parquet"


def unit_model(unit: int):
    """The true error model of ``unit`` (the preset's spread; the bad units changed)."""
    model = preset_model(PRESET, unit)
    if unit == NOISY_UNIT:
        model = dataclasses.replace(model, noise_density_dps_per_sqrt_hz=3 * model.noise_density_dps_per_sqrt_hz)
    if unit == HOT_UNIT:
        model = dataclasses.replace(
            model, temperature_coefficients=tuple(tuple(5 * c for c in row) for row in model.temperature_coefficients)
        )
    return model


def serial(unit: int) -> str:
    return f"SN{unit:04d}"


def write_unit(folder: Path, unit: int, session: int = 0) -> list[Path]:
    """Write the runs of ``unit`` in chamber ``session`` as folder/SERIAL/run_K.parquet; returns their paths."""
    paths = []
    (folder / serial(unit)).mkdir(parents=True, exist_ok=True)
    for k in range(RUNS_PER_UNIT):
        sim = simulate(
            unit_model(unit),
            profile=resolve_profile("chamber", PRESET),
            duration_s=RUN_DURATION_S,
            rate_hz=RATE_HZ,
            seed=1000 * unit + 10 * session + k,
        )
        path = folder / serial(unit) / f"run_{k}.parquet"
        write_recording(sim.recording, path)
        paths.append(path)
    return paths


@pytest.fixture(scope="session")
def fleet_data(tmp_path_factory) -> Path:
    """FLEET_UNITS units on disk (about 6 s to simulate); CORRUPT_UNIT's second run is garbage."""
    folder = tmp_path_factory.mktemp("fleet") / "data"
    for unit in range(FLEET_UNITS):
        write_unit(folder, unit)
    (folder / serial(CORRUPT_UNIT) / "run_1.parquet").write_bytes(b"PAR1 this is not a parquet file")
    return folder


def _limits_text() -> str:
    """Limits a production engineer would set from the part's nominal figures: twice its noise density, twice its
    largest temperature sensitivity."""
    nominal = preset_model(PRESET)
    sensitivity = max(abs(row[0]) for row in nominal.temperature_coefficients)
    return (
        f"[noise_density_dps_per_sqrt_hz]\nmax = {2 * nominal.noise_density_dps_per_sqrt_hz}\n\n"
        f"[temperature_sensitivity_dps_per_degc]\nabs_max = {2 * sensitivity}\n"
    )


@pytest.fixture(scope="session")
def fleet_run(fleet_data, tmp_path_factory):
    """The fleet fitted once through the command line, on a local Dask cluster of two workers."""
    out = tmp_path_factory.mktemp("fleet-out") / "FLEET"
    limits = out.parent / "limits.toml"
    limits.write_text(_limits_text())
    result = run("fleet", "fit", fleet_data, "--unit-from", PATTERN, "-o", out, "--limits", limits, "--workers", 2)
    return out, limits, result
