"""The lookup-table temperature model (gyrocomp.curves.lookup): the curve, its basis, the registries that make it a
model type like the others (a candidate the default can choose, stored, applied, described), on data whose
temperature curve is piecewise linear."""

import warnings

import numpy as np
import pytest

from gyrocomp import Calibration, Polynomial, apply, fit_calibration
from gyrocomp.errors import InputError
from gyrocomp.measures.merit import smoothed_residual_rms
from gyrocomp.curves.kinds import BASES, CURVES, curve_from_dict
from gyrocomp.curves.protocol import TemperatureCurve, register_curve
from gyrocomp.curves.lookup import LookupTableBasis, LookupTableCurve
from gyrocomp.recording import Recording

GRID = [-20.0, 15.0, 40.0, 60.0]
LEVELS = [0.0, -0.07, 0.05, 0.06]


def kink(temperature_degc):
    """A bias whose slope changes at 15 degC and flattens above 40 degC [deg/s]."""
    return np.interp(temperature_degc, GRID, LEVELS)


def _run(seed, lo, hi, hours=1.0, rate_hz=1.0):
    """A heat-cool cycle lo -> hi -> lo [degC] with the kinked bias, a turn-on constant and white noise."""
    rng = np.random.default_rng(seed)
    n = int(hours * 3600 * rate_hz)
    t = np.arange(n) / rate_hz
    temp = (lo + hi) / 2 - (hi - lo) / 2 * np.cos(2 * np.pi * t / t[-1])
    gyro = kink(temp) + rng.normal(0.0, 0.05) + rng.normal(0.0, 0.003, n)
    return Recording(
        time_s=t, gyro_dps=gyro[:, None], gyro_axes=("gyro_z",), temperature_degc=temp, source=f"kink{seed}"
    )


def test_the_table_interpolates_and_holds_past_its_ends():
    table = LookupTableCurve((0.0, 1.0, 0.5), 0.0, 20.0)
    np.testing.assert_allclose(
        table.shape(np.array([-5.0, 0.0, 5.0, 10.0, 15.0, 20.0, 30.0])), [0.0, 0.0, 0.5, 1.0, 0.75, 0.5, 0.5]
    )
    assert isinstance(table, TemperatureCurve) and table.order == "table:2" and table.label == "table:2"
    assert table.describe() == "lookup table, 3 points 10 degC apart"
    sloped = table.plus_slope(0.01)  # + 0.01 (T - 0)
    np.testing.assert_allclose(sloped.shape(np.array([10.0, 20.0])), [1.1, 0.7])
    assert (
        table.clamped() is table and table.outside_range(np.array([25.0])) and not table.outside_range(np.array([20.1]))
    )


def test_the_basis_columns_are_the_table():
    """sum_k v_k hat_k(T) is the table with those values, inside its range and (with a range given) held past it."""
    basis = LookupTableBasis.over(-10.0, 30.0)
    values = np.array([0.3, -0.2, 0.5, 0.1])
    t = np.linspace(-10.0, 30.0, 81)
    table = basis.curve(values, -10.0, 30.0)
    np.testing.assert_allclose(basis.columns(t, 4) @ values, table.shape(t), atol=1e-15)
    past = np.array([-15.0, 35.0])
    np.testing.assert_allclose(basis.columns(past, 4, -10.0, 30.0) @ values, table.shape(past), atol=1e-15)
    assert set(BASES) >= {"poly", "table"} and CURVES["table"] is LookupTableCurve


def test_model_files_store_and_check_the_table(tmp_path):
    table = LookupTableCurve((0.0, 0.02, -0.01), 5.0, 45.0)
    assert curve_from_dict(table.to_dict()) == table
    with pytest.raises(InputError, match="lookup table: values_dps must be a list of finite numbers"):
        curve_from_dict({"type": "table", "values_dps": [0.0, "x"], "t_min_degc": 0.0, "t_max_degc": 1.0})
    with pytest.raises(InputError, match="lookup table: at least 2 values"):
        curve_from_dict({"type": "table", "values_dps": [0.0], "t_min_degc": 0.0, "t_max_degc": 1.0})
    with pytest.raises(
        InputError, match=rf"unknown temperature model type 'spline'; known: {', '.join(sorted(CURVES))}$"
    ):
        curve_from_dict({"type": "spline"})


def test_a_kinked_curve_is_chosen_as_a_table_and_holds_on_a_held_out_run(tmp_path):
    """Simulate, fit with the defaults, judge on a run the fit has not seen: the table leaves the noise's drift
    (measured 1.0-1.05x) where a cubic leaves tens of times more."""
    fit = [_run(0, -20.0, 60.0), _run(1, -15.0, 55.0), _run(2, -20.0, 60.0)]
    held = _run(7, -18.0, 58.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration(fit)
        cubic = fit_calibration(fit, temperature=Polynomial(3), hysteresis="none")
    curve = cal.axes["gyro_z"].temperature
    assert isinstance(curve, LookupTableCurve) and cal.model.startswith("table:")
    sel = cal.report.selection["gyro_z"]
    assert sel.chosen.curve == "table" and {r.candidate.curve for r in sel.candidates} == {"poly", "table"}
    window = 120
    noise = smoothed_residual_rms(held.gyro_dps[:, 0] - kink(held.temperature_degc), window)
    default = smoothed_residual_rms(apply(cal, held).gyro_dps[:, 0], window)
    assert default <= 1.2 * noise
    assert smoothed_residual_rms(apply(cubic, held).gyro_dps[:, 0], window) > 10 * default
    cal.save(tmp_path / "m.json")  # a model file like any other
    again = Calibration.load(tmp_path / "m.json")
    assert again.axes["gyro_z"].temperature == curve
    np.testing.assert_allclose(apply(again, held).gyro_dps, apply(cal, held).gyro_dps, atol=1e-12)
    assert again.summaries()[0].model == "lookup table, 17 points 5 degC apart"


def test_a_curve_kind_is_registered_once():
    with pytest.raises(ValueError, match="a temperature curve of kind 'table' is already registered"):
        register_curve(type("Other", (), {"kind": "table"}))
