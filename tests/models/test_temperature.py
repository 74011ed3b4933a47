"""Simulate-then-recover tests of the polynomial temperature model, with tolerances derived from the noise."""

import warnings

import numpy as np
import pytest

from gyrocomp import Curve, Network, Polynomial, apply, fit_calibration
from gyrocomp.allan import allan_deviation
from gyrocomp.errors import InputError, ModelError, NotFittedError, TemperatureRangeWarning
from gyrocomp.measures.merit import default_window_s, smoothed_residual_rms
from gyrocomp.fitting.temperature_bins import bin_by_temperature
from gyrocomp.cli.common import parse_temperature_option
from gyrocomp.fitting.polynomial_model import PolynomialTemperatureModel, simplest_within
from gyrocomp.recording import Recording
from gyrocomp.simulation import GyroErrorModel, simulate

from ..conftest import TEST_MODEL

GRID = np.linspace(-20, 70, 181)


def noise_scale(sims, axis_index, rate_hz, n_bins=100):
    """Allan deviation of the simulated noise at the time one temperature bin takes to cross [deg/s]."""
    ramp_s = 0.8 * sims[0].truth.duration_s
    tau = np.array([ramp_s / n_bins])
    return float(
        np.mean([allan_deviation(s.truth.noise.total_dps[:, axis_index], rate_hz, taus=tau).deviation[0] for s in sims])
    )


@pytest.mark.parametrize("held_out", [4, 5, 6])
def test_fitted_shape_matches_truth_within_noise(chamber_runs, held_out):
    fit_runs = [s for i, s in enumerate(chamber_runs) if i != held_out][:4]
    cal = fit_calibration([s.recording for s in fit_runs], temperature=Polynomial(3))
    truth = TEST_MODEL.temperature_error_dps(GRID)
    for j, axis in enumerate(TEST_MODEL.axes):
        err = cal.axes[axis].temperature.shape(GRID) - truth[:, j]
        err -= err.mean()  # the shape is defined up to the turn-on constant
        # the bin averages carry the noise averaged over one bin's crossing time, divided among runs
        tolerance = 4.0 * noise_scale(fit_runs, j, 20.0) / np.sqrt(len(fit_runs))
        assert np.abs(err).max() < tolerance, axis
        assert tolerance < 0.25 * np.ptp(truth[:, j])  # the check is much tighter than the effect itself


def test_least_squares_is_linear_in_the_data(chamber_runs):
    """fit(truth + noise) == fit(truth) + fit(noise): an identity that pins the estimator down exactly."""
    runs = chamber_runs[:3]
    parts = {
        "all": [s.recording for s in runs],
        "truth": [s.recording.with_gyro(s.truth.deterministic_error_dps) for s in runs],
        "noise": [s.recording.with_gyro(s.truth.noise.total_dps) for s in runs],
    }
    cal = {k: fit_calibration(v, temperature=Polynomial(3), hysteresis="none") for k, v in parts.items()}
    truth = TEST_MODEL.temperature_error_dps(GRID)
    for j, axis in enumerate(TEST_MODEL.axes):
        shape = {k: c.axes[axis].temperature.shape(GRID) for k, c in cal.items()}
        np.testing.assert_allclose(shape["all"], shape["truth"] + shape["noise"], atol=1e-13)
        consts = {k: np.array(c.axes[axis].turn_on_biases_dps) for k, c in cal.items()}
        np.testing.assert_allclose(consts["all"], consts["truth"] + consts["noise"], atol=1e-13)
        # without noise the fit is the truth, up to the bias of averaging a curve over a bin of width w:
        # |mean of f over the bin - f(mean T)| <= max|f''| w^2 / 24 per bin, twice that peak to peak
        width = 90.0 / 100
        curvature = np.abs(np.gradient(np.gradient(truth[:, j], GRID), GRID)).max()
        err = shape["truth"] - truth[:, j]
        assert np.ptp(err) < 2 * curvature * width**2 / 24 * 1.5
        t_ref = cal["truth"].axes[axis].temperature.t_ref_degc
        at_ref = TEST_MODEL.temperature_error_dps(np.array([t_ref]))[0, j]
        true_turn_on = np.array([s.truth.turn_on_bias_dps[j] for s in runs])
        np.testing.assert_allclose(consts["truth"], true_turn_on + at_ref, atol=1e-6)


def test_turn_on_constants_are_recovered(chamber_runs):
    runs = chamber_runs[:4]
    cal = fit_calibration([s.recording for s in runs], temperature=Polynomial(3))
    for j, axis in enumerate(TEST_MODEL.axes):
        fitted = np.array(cal.axes[axis].turn_on_biases_dps)
        true = np.array([s.truth.turn_on_bias_dps[j] for s in runs])
        at_ref = TEST_MODEL.temperature_error_dps(np.array([cal.axes[axis].temperature.t_ref_degc]))[0, j]
        # each run's constant also absorbs that run's mean noise: its long-tau Allan deviation sets the scale
        tolerance = 4 * noise_scale(runs, j, 20.0)
        np.testing.assert_allclose(fitted, true + at_ref, atol=tolerance)


def held_out_drift(chamber_runs, temperature):
    """Residual drift of each of runs 4, 5, 6 compensated by a fit on the six others, against the noise alone.

    Returns arrays (runs x axes) of the RMS of the moving-averaged output: compensated, noise alone, raw.
    """
    achieved, perfect, raw = [], [], []
    for held_out in (4, 5, 6):
        held = chamber_runs[held_out]
        cal = fit_calibration(
            [s.recording for i, s in enumerate(chamber_runs) if i != held_out], temperature=temperature
        )
        comp = apply(cal, held.recording)
        w = int(default_window_s(held.recording) * held.recording.rate_hz)
        achieved.append([smoothed_residual_rms(comp.gyro_dps[:, j], w) for j in range(3)])
        perfect.append([smoothed_residual_rms(held.truth.noise.total_dps[:, j], w) for j in range(3)])
        raw.append([smoothed_residual_rms(held.recording.gyro_dps[:, j], w) for j in range(3)])
    return np.array(achieved), np.array(perfect), np.array(raw)


def test_held_out_residual_drift_within_15_percent_of_perfect(chamber_runs):
    achieved, perfect, raw = held_out_drift(chamber_runs, Polynomial())
    # pooled over three held-out runs (three seeds) and three axes: the held-out run's own noise enters both
    # sides, so single cases scatter by about 10% around the pooled value
    pooled = np.sqrt(np.sum(achieved**2) / np.sum(perfect**2))
    assert pooled <= 1.15
    assert np.all(achieved <= 1.35 * perfect)
    assert np.all(raw > 3 * perfect)  # there was drift worth removing


def test_a_too_low_order_fails_the_same_criterion(chamber_runs):
    """The 15% criterion has teeth: a straight line cannot meet it on this cubic truth."""
    achieved, perfect, _ = held_out_drift(chamber_runs, Polynomial(1))
    assert np.sqrt(np.sum(achieved**2) / np.sum(perfect**2)) > 1.15


def test_auto_order_uses_cross_validation_and_finds_curvature(chamber_runs):
    model = PolynomialTemperatureModel().fit([s.recording for s in chamber_runs[:6]])
    assert model.selection_ == "leave-one-run-out"
    for axis in TEST_MODEL.axes:
        assert model.curves_[axis].order >= 2
        scores = model.scores_[axis]
        assert scores[0] > 2 * min(scores.values())  # no temperature model is clearly worse


def test_single_run_uses_bic_and_recovers_linear_truth():
    model = GyroErrorModel(axes=("gyro_z",), temperature_coefficients=((2e-3,),), bias_instability_deg_per_h=2.0)
    sim = simulate(model, duration_s=3600, rate_hz=20, seed=3)
    fitted = PolynomialTemperatureModel().fit([sim.recording])
    assert fitted.selection_ == "bic"
    assert fitted.curves_["gyro_z"].order in (1, 2)
    slope = np.polyfit(GRID, fitted.curves_["gyro_z"].shape(GRID), 1)[0]
    assert slope == pytest.approx(2e-3, rel=0.03)


def test_heating_rate_does_not_weight_the_fit():
    """Binning: a run that lingers in one temperature range does not pull the curve there."""
    t = np.arange(0, 20000) / 10.0
    temp = np.where(t < 1800, -20 + 90 * t / 1800, 70.0)  # fast ramp, then a long dwell at 70 degC
    temp = np.concatenate([temp[:1800], np.linspace(-20, 70, t.size - 1800)])
    gyro = 1e-3 * (temp - 25) + 1e-5 * (temp - 25) ** 2
    rec = Recording(time_s=t, gyro_dps=gyro, gyro_axes=("gyro_z",), temperature_degc=temp)
    bins = bin_by_temperature([temp], [gyro], 1.0)
    assert bins.weight.max() == 1.0
    cal = fit_calibration([rec], temperature=Polynomial(2), hysteresis="none")
    shape = cal.axes["gyro_z"].temperature.shape(GRID)
    truth = 1e-3 * (GRID - 25) + 1e-5 * (GRID - 25) ** 2
    np.testing.assert_allclose(shape - shape.mean(), truth - truth.mean(), atol=1e-6)


def test_clamps_outside_range_and_warns_once():
    t = np.arange(0, 600.0)
    temp = np.linspace(10, 40, t.size)
    rec = Recording(time_s=t, gyro_dps=1e-3 * temp, gyro_axes=("gyro_z",), temperature_degc=temp)
    cal = fit_calibration([rec], temperature=Polynomial(1), hysteresis="none")  # a fixed fit holds its edge
    hot = Recording(time_s=t, gyro_dps=np.zeros(t.size), gyro_axes=("gyro_z",), temperature_degc=temp + 30)
    with pytest.warns(TemperatureRangeWarning, match=r"outside the model's range 10.00..40.00 degC") as record:
        out = apply(cal, hot)
    assert len(record) == 1
    curve = cal.axes["gyro_z"].temperature
    assert np.all(out.gyro_dps[-300:, 0] == out.gyro_dps[-1, 0])  # held at the edge
    assert curve.shape(np.array([80.0])) == curve.shape(np.array([40.0]))


def test_noise_level_overshoot_of_the_range_is_not_outside_it():
    t = np.arange(0, 600.0)
    temp = np.linspace(10, 40, t.size)
    cal = fit_calibration(
        [Recording(time_s=t, gyro_dps=1e-3 * temp, gyro_axes=("gyro_z",), temperature_degc=temp)],
        temperature=Polynomial(1),
    )
    curve = cal.axes["gyro_z"].temperature
    assert curve.range_tolerance_degc == 0.5  # 1 % of a 30 degC span is less
    assert not curve.outside_range(np.array([9.6, 40.4]))
    assert curve.outside_range(np.array([40.6]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        apply(
            cal, Recording(time_s=t, gyro_dps=1e-3 * (temp + 0.3), gyro_axes=("gyro_z",), temperature_degc=temp + 0.3)
        )


def test_errors():
    with pytest.raises(NotFittedError, match=r"not fitted yet; call fit\(recordings\) first"):
        PolynomialTemperatureModel().predict_error(None)
    t = np.arange(10.0)
    flat = Recording(time_s=t, gyro_dps=np.zeros(10), gyro_axes=("gyro_z",), temperature_degc=np.full(10, 25.0))
    with pytest.raises(ModelError, match=r"gyro_z: order 3 needs 4 distinct temperature bins, the data has 1"):
        PolynomialTemperatureModel(order=3).fit([flat])
    other = Recording(time_s=t, gyro_dps=np.zeros(10), gyro_axes=("gyro_x",), temperature_degc=t)
    with pytest.raises(InputError, match=r"gyro axes gyro_x differ from .*fit runs of the same sensor together"):
        PolynomialTemperatureModel(order=1).fit([flat, other])
    with pytest.raises(InputError, match=r"order: 9; use 'auto' or a whole number from 0 to 5"):
        PolynomialTemperatureModel(order=9).fit([flat])
    with pytest.raises(InputError, match="fit: no recordings given"):
        PolynomialTemperatureModel().fit([])


@pytest.mark.parametrize(
    "text,expected",
    [
        ("auto", Polynomial()),
        ("poly", Curve("poly")),
        ("POLY:3", Polynomial(3)),
        ("none", None),
        ("poly:0", Polynomial(0)),
        ("mlp:4x2", Network((4, 2))),
        ("table", Curve("table")),
        ("table:16", Curve("table", 16)),
    ],
)
def test_parse_temperature_option(text, expected):
    assert parse_temperature_option(text) == expected


@pytest.mark.parametrize("text", ["poly:9", "poly:x", "spline"])
def test_parse_temperature_option_rejects(text):
    with pytest.raises(InputError, match=r"--temperature: "):
        parse_temperature_option(text)


def test_no_temperature_model_subtracts_run_mean():
    sim = simulate(duration_s=60, rate_hz=10, seed=2)
    cal = fit_calibration([sim.recording], temperature=None)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = apply(cal, sim.recording)
    np.testing.assert_allclose(out.gyro_dps.mean(axis=0), 0, atol=1e-12)


def test_the_parsimony_rule_takes_the_simplest_within_tolerance_of_the_best():
    scores = {0: 1.0, 1: 0.995, 2: 0.99, 3: float("nan")}
    assert simplest_within(scores, [0, 1, 2, 3]) == 1  # 0.995 <= 1.01 x 0.99; 1.0 is not
    assert simplest_within(scores, [0, 1, 2, 3], tolerance=1.02) == 0
    assert simplest_within(scores, [0, 1, 2, 3], by_bic=True) == 2  # BIC: the best itself
    memories = {"lag": 2.0, "none": 2.01, "turning-point": float("inf")}
    assert simplest_within(memories, ("none", "turning-point", "lag")) == "none"  # order is the caller's
    with pytest.raises(ModelError, match="scores: no candidate has a finite score"):
        simplest_within({0: float("nan")}, [0])
