"""The turning-point table (issue #70, item 2: a memory of the last turn of any shape): its offset against the
table read by hand, its columns times its values, the model file, the streaming compensator; fitted on runs
written from the physics (a smooth bump in the die temperature below its hottest point, the die behind the
chamber: no table and no polynomial in the distance from the turn) and judged at another ramp rate, through the
library and the command line."""

import json
import warnings

import numpy as np
import pytest

from gyrocomp import Calibration, FitOptions, fit
from gyrocomp.curves.turning_table import (
    TurningTableCurve,
    largest_turn_distance_degc,
    turning_table_columns,
    turning_table_knots_degc,
)
from gyrocomp.effects import find_turns
from gyrocomp.errors import InputError

from ..conftest import assert_streaming_equals_batch, run
from .conftest import drift_over_noise, runs_at_two_rates

#: up 20 -> 80, down to 20, up to 50 degC in 0.1 degC steps
PATH_DEGC = np.concatenate([np.linspace(20, 80, 601), np.linspace(79.9, 20, 600), np.linspace(20.1, 50, 300)])
CURVE = TurningTableCurve((10.0, 20.0, 40.0), (0.01, 0.03, -0.02), (-0.005, 0.0, 0.004), threshold_degc=0.5)


def test_the_offset_is_the_table_read_at_the_distance_from_the_last_turn():
    offset = CURVE.offset(PATH_DEGC, find_turns(PATH_DEGC, CURVE.threshold_degc))
    first, cooling, heating = offset[:601], offset[601:1201], offset[1201:]
    assert np.all(first == 0.0)  # the first branch is the reference path
    t_cool, t_heat = PATH_DEGC[601:1201], PATH_DEGC[1201:]
    confirmed = t_cool < 80 - 0.5  # the reversal counts once T is the threshold past the extreme
    # by hand: 0 at the turn, 0.01 at 10 degC, 0.03 at 20, -0.02 at 40, held past it
    d = 80 - t_cool[confirmed]
    by_hand = np.where(
        d <= 10,
        0.001 * d,
        np.where(d <= 20, 0.01 + 0.002 * (d - 10), np.where(d <= 40, 0.03 - 0.0025 * (d - 20), -0.02)),
    )
    np.testing.assert_allclose(cooling[confirmed], by_hand, atol=1e-15)
    d = t_heat[t_heat > 20 + 0.5] - 20
    by_hand = np.where(d <= 10, -0.0005 * d, np.where(d <= 20, -0.005 + 0.0005 * (d - 10), 0.0002 * (d - 20)))
    np.testing.assert_allclose(heating[t_heat > 20 + 0.5], by_hand, atol=1e-15)


def test_the_curve_is_its_columns_times_its_values_and_its_knots_reach_the_farthest_distance():
    turns = find_turns(PATH_DEGC, 0.5)
    x = turning_table_columns(PATH_DEGC, turns, CURVE.knots_degc)
    assert x.shape == (PATH_DEGC.size, 6)
    np.testing.assert_allclose(x @ np.r_[CURVE.descending, CURVE.ascending], CURVE.offset(PATH_DEGC, turns), atol=0)
    # every row of a branch is a partition of one between two neighbouring knots (or the last knot held)
    on = ~np.isnan(turns.turn_degc)
    assert np.allclose(x[on].sum(axis=1)[np.abs(PATH_DEGC[on] - turns.turn_degc[on]) >= 10.0], 1.0)
    reach = largest_turn_distance_degc([PATH_DEGC], 0.5)
    assert reach == pytest.approx(60.0)  # from the turn at 80 down to 20
    assert turning_table_knots_degc(reach, 4) == pytest.approx((15.0, 30.0, 45.0, 60.0))
    assert largest_turn_distance_degc([np.linspace(20, 80, 100)], 0.5) == 0.0


def test_the_model_file_keeps_the_table_and_refuses_one_that_is_not():
    assert TurningTableCurve.from_dict(json.loads(json.dumps(CURVE.to_dict()))) == CURVE
    bad = CURVE.to_dict()
    bad["knots_degc"] = [10.0, 5.0, 40.0]
    with pytest.raises(InputError, match="knots_degc must be positive and increasing"):
        TurningTableCurve.from_dict(bad)
    bad = {**CURVE.to_dict(), "ascending_dps": [0.0]}
    with pytest.raises(InputError, match="one descending and one ascending value per knot"):
        TurningTableCurve.from_dict(bad)
    with pytest.raises(InputError, match="needs knots_degc"):
        TurningTableCurve.from_dict({"type": "turning-table"})


def _bump_below_the_peak(die: np.ndarray) -> np.ndarray:
    """Once the die is 1 degC below the hottest point it has passed (each run passes one), a Gaussian bump 15 degC
    below it, 6 degC wide, of 0.05 deg/s."""
    peak = np.maximum.accumulate(die)
    return np.where(die < peak - 1.0, 0.05 * np.exp(-0.5 * ((die - (peak - 15.0)) / 6.0) ** 2), 0.0)


@pytest.fixture(scope="module")
def bump_runs():
    """Two heat-cool runs at 1 degC/min of a part with the bump, and a third at 3 degC/min with its noise alone."""
    return runs_at_two_rates(_bump_below_the_peak)


def test_a_bump_below_the_hottest_point_is_carried_to_another_ramp_rate(bump_runs):
    """The turning-point table leaves the third run's drift within 1.35x of the noise's on every axis at 3
    degC/min; the turning-point polynomial of order 1 to 3 leaves more than twice the noise's on some axis."""
    fit_runs, (held, noise) = bump_runs
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        table = fit(fit_runs, FitOptions(hysteresis="turning-table"))
        poly = fit(fit_runs, FitOptions(hysteresis="turning-point"))
    assert all(type(ax.hysteresis) is TurningTableCurve for ax in table.axes.values())
    assert max(drift_over_noise(table, held, noise)) < 1.35, drift_over_noise(table, held, noise)
    assert max(drift_over_noise(poly, held, noise)) > 2.0, drift_over_noise(poly, held, noise)


def test_the_table_streams_as_it_applies_and_its_model_file_reads_back(bump_runs, tmp_path):
    fit_runs, (held, _) = bump_runs
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit(fit_runs, FitOptions(hysteresis="turning-table+lag"))
    path = tmp_path / "m.json"
    cal.save(path)
    again = Calibration.load(path)
    assert again.axes["gyro_z"].hysteresis == cal.axes["gyro_z"].hysteresis
    assert again.fit_report["hysteresis"]["axes"]["gyro_z"]["memory"] == "turning-table+lag"
    short = held.take(np.arange(4000))
    assert_streaming_equals_batch(again, short, [1, 999, 37, 1500])
    # a table without its ascending values is one line naming the field
    d = json.loads(path.read_text())
    d["axes"]["gyro_z"]["hysteresis"]["ascending_dps"] = d["axes"]["gyro_z"]["hysteresis"]["ascending_dps"][:1]
    path.write_text(json.dumps(d))
    with pytest.raises(InputError, match="one descending and one ascending value per knot"):
        Calibration.load(path)


def test_fit_and_show_on_the_command_line_name_the_table(bump_runs, tmp_path):
    fit_runs, _ = bump_runs
    paths = []
    for k, rec in enumerate(fit_runs):
        p = tmp_path / f"run_{k}.csv"
        rec_table = np.column_stack([rec.time_s, rec.gyro_dps, rec.temperature_degc])
        np.savetxt(p, rec_table, delimiter=",", header="time,gyro_x,gyro_y,gyro_z,temperature", comments="")
        paths.append(p)
    result = run("--no-config", "fit", *paths, "--hysteresis", "turning-table", "-o", tmp_path / "m.json")
    assert result.returncode == 0, result.stderr
    shown = run("--no-config", "show", tmp_path / "m.json")
    assert shown.returncode == 0, shown.stderr
    assert "turning-point table of" in shown.stdout and "knots" in shown.stdout
    cal = Calibration.load(tmp_path / "m.json")
    assert all(type(ax.hysteresis) is TurningTableCurve for ax in cal.axes.values())
