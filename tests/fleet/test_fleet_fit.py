"""A simulated fleet of 120 units through ``gyrocomp fleet fit`` on a local Dask cluster: the models are the ones
``gyrocomp fit`` gives unit by unit, a rerun skips every unit, a corrupt unit fails alone, the bad units fail their
limits and stand out of the population."""

from __future__ import annotations

import json
import re

import numpy as np
import pandas as pd
import pytest

from gyrocomp.calibration import Calibration
from gyrocomp.fleet import CalibrationStore, FleetSettings, UnitRuns, fit_unit
from gyrocomp.io import read
from gyrocomp.models.fit import fit_channels
from gyrocomp.simulation import resolve_profile, simulate

from ..conftest import run
from .conftest import (
    CORRUPT_UNIT,
    FLEET_UNITS,
    HOT_UNIT,
    NOISY_UNIT,
    PATTERN,
    PRESET,
    RATE_HZ,
    RUN_DURATION_S,
    RUNS_PER_UNIT,
    serial,
    unit_model,
    write_unit,
)

pytestmark = pytest.mark.slow


def test_every_unit_is_fitted_or_recorded_as_failed(fleet_run):
    out, _, result = fleet_run
    assert result.returncode == 0, result.stderr
    assert f"{FLEET_UNITS - 1} unit(s) fitted, 0 unchanged (skipped), 1 failed" in result.stdout
    table = pd.read_parquet(out / "fleet.parquet")
    assert len(table) == FLEET_UNITS
    assert list(table.loc[table["status"] == "failed", "serial"]) == [serial(CORRUPT_UNIT)]
    error = table.loc[table["status"] == "failed", "error"].item()
    assert re.search(rf"{serial(CORRUPT_UNIT)}/run_1\.parquet", error), error
    assert len(list((out / "models").glob("*.json"))) == FLEET_UNITS - 1
    with CalibrationStore(out) as db:
        assert len(db.serials()) == FLEET_UNITS
        assert db.latest(serial(CORRUPT_UNIT)).error == error


def test_the_bad_units_fail_their_limits_and_stand_out(fleet_run):
    out, _, result = fleet_run
    table = pd.read_parquet(out / "fleet.parquet").set_index("serial")
    assert set(table.index[table["verdict"] == "fail"]) == {serial(NOISY_UNIT), serial(HOT_UNIT)}
    assert "noise_density_dps_per_sqrt_hz" in table.loc[serial(NOISY_UNIT), "failing"]
    assert "noise_density" not in table.loc[serial(HOT_UNIT), "failing"]
    assert "temperature_sensitivity_dps_per_degc" in table.loc[serial(HOT_UNIT), "failing"]
    passed = FLEET_UNITS - 3  # the corrupt unit does not pass either
    assert f"yield: {passed}/{FLEET_UNITS} units pass ({100 * passed / FLEET_UNITS:.1f} %)" in result.stdout
    outliers = set(table.index[table["outlier"]])
    assert {serial(NOISY_UNIT), serial(HOT_UNIT)} <= outliers
    assert "noise_density" in table.loc[serial(NOISY_UNIT), "outlier_figures"]
    assert "temperature_sensitivity" in table.loc[serial(HOT_UNIT), "outlier_figures"]
    # the bad units are far out; of the good ones (whose figures differ only by the spread and the
    # estimation noise) at most 2 % score above the threshold
    assert table.loc[[serial(NOISY_UNIT), serial(HOT_UNIT)], "outlier_score"].min() > 10
    assert len(outliers) - 2 <= 0.02 * (FLEET_UNITS - 3)


def _model_document(calibration: Calibration) -> dict:
    d = calibration.to_dict()
    d["provenance"].pop("created_utc")
    return d


@pytest.mark.parametrize("unit", [0, 1, HOT_UNIT, NOISY_UNIT, 64, 88])
def test_fleet_models_equal_the_single_unit_fit(fleet_run, fleet_data, unit):
    out, _, _ = fleet_run
    fleet_model = Calibration.load(out / "models" / f"{serial(unit)}.json")
    runs = sorted((fleet_data / serial(unit)).glob("run_*.parquet"))
    alone = fit_channels([read(p) for p in runs])
    assert _model_document(fleet_model) == _model_document(alone)


def test_a_fleet_model_equals_gyrocomp_fit_on_the_command_line(fleet_run, fleet_data, tmp_path):
    out, _, _ = fleet_run
    runs = sorted((fleet_data / serial(5)).glob("run_*.parquet"))
    result = run("fit", *runs, "-o", tmp_path / "alone.json")
    assert result.returncode == 0, result.stderr
    assert _model_document(Calibration.load(out / "models" / f"{serial(5)}.json")) == _model_document(
        Calibration.load(tmp_path / "alone.json")
    )


def test_figures_recover_the_true_temperature_sensitivity(fleet_run):
    """d bias/dT at 25 degC against the simulated unit's first coefficient, within three times what the curve's
    held-out drift allows over half the temperature span (the slope error a drift that size could cause); the bias
    at 25 degC against the mean of the runs' true constant biases (the curve is zero there), within three held-out
    drifts."""
    out, _, _ = fleet_run
    with CalibrationStore(out) as db:
        for unit in (0, 7, 64, HOT_UNIT):
            figures = db.valid_at(serial(unit)).figures
            truths = [
                simulate(
                    unit_model(unit),
                    profile=resolve_profile("chamber", PRESET),
                    duration_s=RUN_DURATION_S,
                    rate_hz=RATE_HZ,
                    seed=1000 * unit + k,
                ).truth
                for k in range(RUNS_PER_UNIT)
            ]
            # at rest, upright: the turn-on bias plus the g-sensitivity's 1 g term, which a run at one orientation
            # cannot tell apart
            turn_on = np.mean(
                [t.turn_on_bias_dps + t.components_dps["acceleration"].mean(axis=0) for t in truths], axis=0
            )
            for j, f in enumerate(figures.axes.values()):
                assert f.turn_on_bias_dps == pytest.approx(turn_on[j], abs=3 * f.held_out_drift_dps), (unit, j)
            span = figures.temperature_max_degc - figures.temperature_min_degc
            for axis, row in zip(figures.axes, unit_model(unit).temperature_coefficients):
                f = figures.axes[axis]
                tolerance = 3 * f.held_out_drift_dps / (span / 2)
                assert f.temperature_sensitivity_dps_per_degc == pytest.approx(row[0], abs=tolerance), (unit, axis)
                assert f.noise_density_dps_per_sqrt_hz == pytest.approx(
                    unit_model(unit).noise_density_dps_per_sqrt_hz, rel=0.15
                )


def test_a_rerun_skips_every_unchanged_unit_and_refits_a_changed_one(fleet_run, fleet_data, tmp_path):
    out, limits, _ = fleet_run
    # (without Dask: what is skipped is decided from the store before anything is sent to a worker)
    again = run(
        "fleet", "fit", fleet_data, "--unit-from", PATTERN, "-o", out, "--limits", limits, "--scheduler", "serial"
    )
    assert again.returncode == 0, again.stderr
    # the corrupt unit has no successful calibration to compare with: it is tried again (and fails again)
    assert f"0 unit(s) fitted, {FLEET_UNITS - 1} unchanged (skipped), 1 failed" in again.stdout
    # one unit's files written again with the same content (new times): still unchanged; another unit's runs
    # replaced by a new chamber session: only that one is fitted again
    for k, path in enumerate(write_unit(tmp_path / "same", 4)):
        path.replace(fleet_data / serial(4) / f"run_{k}.parquet")
    for k, path in enumerate(write_unit(tmp_path / "new", 3, session=1)):
        path.replace(fleet_data / serial(3) / f"run_{k}.parquet")
    third = run("fleet", "fit", fleet_data, "--unit-from", PATTERN, "-o", out, "--limits", limits, "--workers", 2)
    assert f"1 unit(s) fitted, {FLEET_UNITS - 2} unchanged (skipped), 1 failed" in third.stdout
    with CalibrationStore(out) as db:
        history = db.history(serial(3))
        assert [r.status for r in history] == ["ok", "ok"]
        assert history[0].input_hash != history[1].input_hash
        assert len(db.history(serial(4))) == 1
        assert len(db.history(serial(CORRUPT_UNIT))) == 3


def test_serial_scheduler_gives_the_dask_models(fleet_run, fleet_data):
    out, _, _ = fleet_run
    unit = UnitRuns(serial(11), tuple(str(p) for p in sorted((fleet_data / serial(11)).glob("run_*.parquet"))))
    outcome = fit_unit(unit, FleetSettings())
    assert outcome.status == "ok"
    assert _model_document(Calibration.from_dict(json.loads(outcome.model_json))) == _model_document(
        Calibration.load(out / "models" / f"{serial(11)}.json")
    )
    assert fit_unit(unit, FleetSettings(), known_hash=outcome.input_hash).status == "unchanged"
    assert np.isfinite(outcome.figures.axes["gyro_x"].bias_instability_deg_per_h)


def test_the_fleet_report_shows_yield_distributions_outliers_and_failures(fleet_run, tmp_path):
    out, limits, _ = fleet_run
    result = run("fleet", "report", out, "-o", tmp_path / "fleet.html", "--limits", limits)
    assert result.returncode == 0, result.stderr
    assert "sections: summary, distributions, outliers, worst, rejected, failed" in result.stdout
    page = (tmp_path / "fleet.html").read_text()
    sections = dict(re.findall(r'<section id="(\w+)">(.*?)</section>', page, re.S))
    for bad in (NOISY_UNIT, HOT_UNIT):
        assert serial(bad) in sections["outliers"] and serial(bad) in sections["rejected"]
        assert serial(bad) in sections["worst"]
    assert serial(CORRUPT_UNIT) in sections["failed"] and "run_1.parquet" in sections["failed"]
    assert "data:image/png;base64," in sections["distributions"]
    assert "<td>yield</td>" in sections["summary"].replace(' class="text"', "")
