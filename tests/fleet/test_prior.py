"""Short chamber runs with the fleet's population as the prior: the block noise covariance reproduces the Allan
floor of flicker noise, a new unit's short run with the prior comes far closer to its full calibration than the
short run alone, and the stated uncertainty covers the true curve."""

from __future__ import annotations

import math
import warnings
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from gyrocomp.calibration import Calibration
from gyrocomp.calibration.compensate import apply
from gyrocomp.errors import DataQualityWarning, InputError
from gyrocomp.fleet import (
    CalibrationStore,
    block_covariance,
    comes_back,
    fit_with_prior,
    population_prior,
    prior_from_models,
)
from gyrocomp.io import read
from gyrocomp.io.tables import write_recording
from gyrocomp.measures.merit import smoothed_residual_rms
from gyrocomp.models.fit import fit_channels
from gyrocomp.simulation import preset_model, resolve_profile, simulate

from ..conftest import run
from .conftest import FLEET_UNITS, PRESET, RATE_HZ, RUN_DURATION_S, RUNS_PER_UNIT

pytestmark = pytest.mark.slow


#: new units, not in the fleet
NEW_UNITS = (300, 301, 302, 303, 304, 305)
#: the short run: the middle third of the preset's -20..70 degC, a quarter of the full runs' chamber time, there and
#: back twice (the ``cycle`` profile: held at 10, up to 40, held, down to 10, held, and again)
SHORT_SET_POINTS_DEGC = (10.0, 40.0)
SHORT_DURATION_S = RUNS_PER_UNIT * RUN_DURATION_S / 4
DRIFT_WINDOW_S = 60.0


def test_block_covariance_gives_the_allan_floor_of_flicker_and_white_noise():
    """Allan variance of adjacent block means, 0.5 (var_1 + var_2 - 2 cov_12): for flicker it is the plateau
    (0.664 B)^2, for a rate random walk K^2 tau / 3, for white noise N^2 / tau (IEEE Std 952, C.1)."""
    b_deg_per_h, length_s = 10.0, 20.0
    cov = block_covariance(np.full(200, length_s), 0.0, b_deg_per_h)
    i = 100
    adev = math.sqrt(0.5 * (cov[i, i] + cov[i + 1, i + 1] - 2 * cov[i, i + 1]))
    assert adev == pytest.approx(math.sqrt(2 * math.log(2) / math.pi) * b_deg_per_h / 3600, rel=0.03)
    walk = block_covariance(np.full(50, length_s), 0.0, 0.0, 1e-4)  # rate random walk: K^2 tau / 3
    allan_variance = 0.5 * (walk[i - 60, i - 60] + walk[i - 59, i - 59] - 2 * walk[i - 60, i - 59])
    assert allan_variance == pytest.approx(1e-8 * length_s / 3, rel=1e-12)
    white = block_covariance(np.array([10.0, 10.0, 5.0]), 0.01, 0.0)
    assert np.allclose(white, np.diag([1e-5, 1e-5, 2e-5]))
    assert np.all(np.linalg.eigvalsh(cov) > 0)  # a covariance: symmetric positive definite


def _held_out_drift(calibration: Calibration, recording) -> float:
    """Mean over the axes of the RMS of the 60 s moving average of the compensated rate (at rest: 0) about its mean."""
    compensated = apply(calibration, recording)
    window = int(DRIFT_WINDOW_S * recording.rate_hz)
    return float(
        np.mean(
            [smoothed_residual_rms(compensated.gyro_dps[:, j], window) for j in range(compensated.gyro_dps.shape[1])]
        )
    )


@pytest.fixture(scope="module")
def prior(fleet_run):
    out, _, _ = fleet_run
    with CalibrationStore(out) as db:
        return population_prior(db.latest_rows())


def _short_run(unit: int, seed: int, profile_name: str = "cycle"):
    """The short run of ``unit``: ``cycle`` goes there and back (twice), ``chamber`` one way (held cold, up, held
    hot)."""
    profile = resolve_profile(profile_name, PRESET, set_points_degc=SHORT_SET_POINTS_DEGC)
    return simulate(
        preset_model(PRESET, unit), profile=profile, duration_s=SHORT_DURATION_S, rate_hz=RATE_HZ, seed=seed
    ).recording


def test_the_prior_leaves_out_outliers_and_spans_the_fleet(prior, fleet_run):
    table = pd.read_parquet(fleet_run[0] / "fleet.parquet")
    assert prior.units == int(((table["status"] == "ok") & ~table["outlier"]).sum())
    assert FLEET_UNITS - 3 - 4 <= prior.units <= FLEET_UNITS - 3  # less the corrupt unit, the bad ones, <= 2 % more
    assert (prior.temperature_min_degc, prior.temperature_max_degc) == pytest.approx((-20.0, 70.0), abs=1.0)
    nominal = preset_model(PRESET)
    for axis, row in zip(prior.axes, nominal.temperature_coefficients):
        p = prior.axes[axis]
        # the population mean of the linear coefficient is the nominal part's, within its 20 % spread / sqrt(n)
        slope = p.mean_dps[0] / prior.temperature_scale_degc
        assert slope == pytest.approx(row[0], rel=3 * 0.2 / math.sqrt(prior.units))
        assert math.sqrt(p.covariance_dps2[0][0]) / prior.temperature_scale_degc == pytest.approx(
            0.2 * abs(row[0]), rel=0.2
        )
        assert p.lag_time_constant_s == pytest.approx(nominal.thermal_time_constant_s, rel=0.2)


@pytest.fixture(scope="module")
def oracle(prior):
    """The simulator's own population on the fleet prior's basis: what no fleet can know."""
    return prior_from_models([preset_model(PRESET, unit) for unit in range(50_000, 52_000)], like=prior)


def test_a_short_run_with_the_prior_comes_as_close_as_the_true_population_allows(prior, oracle):
    """A run over a third of the range (there and back) in a quarter of the time. With the fleet's prior it comes
    as close to the unit's full calibration as the simulator's true population as the prior does (the best this
    estimator can do on that run), and at least twice as close as the short run alone, on every unit.
    benchmarks/bench_prior.py measured 40 new units, a prior from 200: see the README (the issue's 1.5x is below what
    even the true population gives on this part)."""
    with_prior, with_truth, alone = [], [], []
    for unit in NEW_UNITS:
        full = [
            simulate(
                PRESET, profile="chamber", duration_s=RUN_DURATION_S, rate_hz=RATE_HZ, seed=1000 * unit + k, unit=unit
            ).recording
            for k in range(RUNS_PER_UNIT)
        ]
        held_out = simulate(
            PRESET, profile="chamber", duration_s=RUN_DURATION_S, rate_hz=RATE_HZ, seed=1000 * unit + 7, unit=unit
        ).recording
        short = _short_run(unit, 1000 * unit + 9)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the short run alone: its narrow span is warned about
            reference = _held_out_drift(fit_channels(full), held_out)
            alone.append(_held_out_drift(fit_channels(short), held_out) / reference)
        with warnings.catch_warnings():
            warnings.simplefilter("error", DataQualityWarning)  # a run that comes back is not warned about
            with_prior.append(_held_out_drift(fit_with_prior(short, prior), held_out) / reference)
            with_truth.append(_held_out_drift(fit_with_prior(short, oracle), held_out) / reference)
    assert np.median(with_prior) < 1.2 * np.median(with_truth), (with_prior, with_truth)
    assert all(p < a / 2 for p, a in zip(with_prior, alone)), (with_prior, alone)


def test_prior_from_models_recovers_the_parts_coefficients(prior):
    """The consumer part's bias is a quadratic in T - 25 degC: on the basis u = (T - T_ref) / scale its theta is
    exactly (c1 scale, c2 scale^2, 0), so the oracle's mean and covariance are those of the parts' coefficients."""
    parts = [preset_model(PRESET, unit) for unit in range(60_000, 60_050)]
    oracle = prior_from_models(parts, like=prior)
    assert oracle.units == 50 and prior.reference_temperature_degc == parts[0].t_ref_degc
    scale = prior.temperature_scale_degc
    for j, axis in enumerate(parts[0].axes):
        theta = np.array(
            [
                [m.temperature_coefficients[j][0] * scale, m.temperature_coefficients[j][1] * scale**2, 0.0]
                for m in parts
            ]
        )
        assert np.allclose(oracle.axes[axis].mean_dps, theta.mean(axis=0), rtol=1e-9, atol=1e-12)
        assert np.allclose(oracle.axes[axis].covariance_dps2, np.cov(theta, rowvar=False), rtol=1e-7, atol=1e-15)
        assert oracle.axes[axis].lag_time_constant_s == parts[0].thermal_time_constant_s
    with pytest.raises(InputError, match=r"models: 3 part\(s\); a population prior needs at least 10"):
        prior_from_models(parts[:3], like=prior)


def test_a_run_that_only_rises_is_warned_about(prior):
    """One way (held cold, one ramp up, held hot), temperature is a function of time and slow drift looks like the
    bias curve: the fit says so."""
    one_way = _short_run(NEW_UNITS[0], 1, "chamber")
    with pytest.warns(
        DataQualityWarning,
        match=r"recordings: the temperature only rises or only falls in every "
        r"run \(.*\): slow drift cannot be told from the temperature curve",
    ):
        fit_with_prior(one_way, prior)
    with warnings.catch_warnings():
        warnings.simplefilter("error", DataQualityWarning)
        fit_with_prior([one_way, _short_run(NEW_UNITS[0], 2)], prior)  # one run that comes back is enough


@pytest.mark.parametrize(
    ("temperature", "expected"),
    [
        (np.linspace(10, 40, 500), False),  # up
        (np.linspace(40, 10, 500), False),  # down
        (np.r_[np.linspace(10, 40, 250), np.linspace(40, 10, 250)], True),  # up and down again
        (np.r_[np.linspace(10, 40, 250), np.linspace(40, 30, 100)], False),  # back by a third of the span only
        (np.r_[np.linspace(10, 40, 250), np.linspace(40, 24, 100)], True),  # back by more than half
        (np.full(100, 25.0), False),  # no span
        (np.array([25.0]), False),
    ],
)
def test_comes_back_needs_a_return_of_half_the_span(temperature, expected):
    assert comes_back(temperature) is expected


def test_comes_back_is_not_fooled_by_whole_degree_steps_and_noise():
    rng = np.random.default_rng(3)
    ramp = np.linspace(10, 40, 5000)
    assert not comes_back(np.round(ramp + rng.normal(0, 0.3, ramp.size)))
    cycle = np.r_[ramp, ramp[::-1]]
    assert comes_back(np.round(cycle + rng.normal(0, 0.3, cycle.size)))


@pytest.mark.parametrize("profile_name", ["cycle", "chamber"])
def test_the_stated_uncertainty_covers_the_true_curve(prior, profile_name):
    """Over the population's range, the fitted curve's largest error against the truth is within three of its
    stated standard deviations, on every axis of every new unit, whether its short run comes back or not."""
    grid = np.linspace(prior.temperature_min_degc, prior.temperature_max_degc, 91)
    for unit in NEW_UNITS:
        model = preset_model(PRESET, unit)
        truth = model.temperature_error_dps(grid)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the one-way run is warned about
            calibration = fit_with_prior(_short_run(unit, 1000 * unit + 9, profile_name), prior)
        for j, (axis, fitted) in enumerate(calibration.axes.items()):
            error = np.abs(fitted.shape_dps(grid) - truth[:, j])
            stated = calibration.fit_report["prior"][axis]["curve_sd_max_dps"]
            assert error.max() < 3 * stated, (unit, axis, error.max(), stated)


def test_fleet_fit_with_the_prior_on_the_command_line(fleet_run, prior, tmp_path):
    out, _, _ = fleet_run
    for unit, profile_name in zip(NEW_UNITS[:2], ("cycle", "chamber")):  # the second unit's run goes one way
        (tmp_path / "new" / f"SN{unit}").mkdir(parents=True)
        write_recording(
            _short_run(unit, 1000 * unit + 9, profile_name), tmp_path / "new" / f"SN{unit}" / "short.parquet"
        )
    result = run(
        "fleet",
        "fit",
        tmp_path / "new",
        "--unit-from",
        "{serial}/short.parquet",
        "-o",
        tmp_path / "NEW",
        "--prior",
        out,
        "--scheduler",
        "serial",
    )
    assert result.returncode == 0, result.stderr
    assert "2 unit(s) fitted" in result.stdout
    # the one-way unit is named in the summary with its warning, the other is not
    assert "units fitted with warnings" in result.stdout and f"SN{NEW_UNITS[1]}" in result.stdout
    assert "only rises or only falls" in result.stdout
    with CalibrationStore(tmp_path / "NEW") as db:
        record = db.valid_at(f"SN{NEW_UNITS[0]}")
    expected = fit_with_prior(read(tmp_path / "new" / f"SN{NEW_UNITS[0]}" / "short.parquet"), prior)
    model = record.calibration()
    assert model.axes["gyro_x"].temperature == expected.axes["gyro_x"].temperature
    figures = record.figures.axes["gyro_x"]
    assert figures.curve_sd_dps == expected.fit_report["prior"]["gyro_x"]["curve_sd_max_dps"]
    assert math.isnan(figures.held_out_drift_dps)
    assert not any("only rises or only falls" in w for w in record.warnings)
    with CalibrationStore(tmp_path / "NEW") as db:
        one_way = db.valid_at(f"SN{NEW_UNITS[1]}")
    assert any("the temperature only rises or only falls in every run" in w for w in one_way.warnings), one_way.warnings
    # a fleet of prior fits does not make a prior
    few = run(
        "fleet",
        "fit",
        tmp_path / "new",
        "--unit-from",
        "{serial}/short.parquet",
        "-o",
        tmp_path / "N2",
        "--prior",
        tmp_path / "NEW",
        "--scheduler",
        "serial",
    )
    assert few.returncode == 2 and "--prior: 0 calibrated unit(s) that are not outliers" in few.stderr


def test_fit_with_prior_refuses_runs_without_temperature(prior):
    rec = _short_run(NEW_UNITS[0], 1)
    with pytest.raises(InputError, match=r"no temperature column; a prior fit models the bias against temperature"):
        fit_with_prior(replace(rec, temperature_degc=None), prior)
    with pytest.raises(InputError, match=r"block_s: must be positive, got 0"):
        fit_with_prior(rec, prior, block_s=0)


def test_a_temperature_column_per_axis_is_read_as_each_axis_own(prior):
    rec = _short_run(NEW_UNITS[0], 1)
    per_axis = replace(rec, temperature_degc=np.column_stack([rec.temperature_degc] * 3))
    assert fit_with_prior(per_axis, prior).axes == fit_with_prior(rec, prior).axes
