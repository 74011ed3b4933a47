"""Thermal lag and turning-point hysteresis: simulate, fit on some runs, test on a held-out run heated
three times faster than the fit runs, against the truth and against a cubic-only fit."""

import dataclasses
import json
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp import Calibration, Compensator, Polynomial, apply, fit_calibration
from gyrocomp.errors import InputError, NotFittedError
from gyrocomp.measures.merit import smoothed_residual_rms
from gyrocomp.fitting.thermal import ThermalHysteresisModel
from gyrocomp.simulation import Hysteresis, get_profile, preset_model, simulate

from ..conftest import assert_streaming_equals_batch

RANGE = (-30.0, 80.0)
WINDOW_S = 60.0


def _experiment(model, **fit_options):
    """Three 1 degC/min cycles to fit on, one 3 degC/min cycle held out (1 Hz)."""
    slow = get_profile("cycle", set_points_degc=RANGE, cycles=1)
    fast = get_profile("cycle", set_points_degc=RANGE, cycles=1, ramp_rate_degc_per_min=3.0)
    runs = [simulate(model, profile=slow, rate_hz=1.0, seed=s) for s in range(3)]
    held = simulate(model, profile=fast, rate_hz=1.0, seed=50)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chosen = fit_calibration([r.recording for r in runs], **fit_options)
        cubic = fit_calibration([r.recording for r in runs], temperature=Polynomial(3), hysteresis="none")
    w = int(WINDOW_S * 1.0)

    def drift(cal):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            comp = apply(cal, held.recording).gyro_dps[:, 0]
        return smoothed_residual_rms(comp - held.truth.true_rate_dps[:, 0], w)

    perfect = smoothed_residual_rms(held.truth.noise.total_dps[:, 0], w)
    return chosen, held, drift(chosen) / perfect, drift(cubic) / drift(chosen)


@pytest.fixture(scope="module")
def both_effects():
    """The ADXRS450 preset: 60 s thermal lag and hysteresis on cooling between 55 and 80 degC."""
    return _experiment(preset_model("adxrs450"), hysteresis_band_degc=(55.0, 80.0))


def test_both_effects_recovered_and_generalize_to_a_faster_ramp(both_effects):
    cal, _, vs_perfect, cubic_over_chosen = both_effects
    ax = cal.axes["gyro_z"]
    assert cal.fit_report["hysteresis"]["axes"]["gyro_z"]["chosen"].startswith("turning-point+lag")
    assert ax.lag_time_constant_s == pytest.approx(60.0, rel=0.2)
    d = np.linspace(0, 25, 26)  # the preset: 0.032 d - 0.00128 d^2 below an 80 degC turn
    fitted = sum(h * d ** (j + 1) for j, h in enumerate(ax.hysteresis.descending))
    np.testing.assert_allclose(fitted, 0.032 * d - 0.00128 * d**2, atol=0.02)
    assert ax.hysteresis.band_degc == (55.0, 80.0)
    # the bar where both effects are present: within 35 % of perfect, 2x better than a cubic
    assert vs_perfect < 1.35
    assert cubic_over_chosen > 2.0
    scores = cal.fit_report["hysteresis"]["axes"]["gyro_z"]["scores_dps"]
    assert scores["turning-point+lag"] < min(scores["none"], scores["lag"], scores["turning-point"])


def test_lag_alone_generalizes_to_a_faster_ramp():
    cal, _, vs_perfect, cubic_over_chosen = _experiment(preset_model("adxrs450").without("hysteresis"))
    assert cal.axes["gyro_z"].lag_time_constant_s > 30
    assert vs_perfect < 1.2 and cubic_over_chosen > 2.0


def test_turning_point_hysteresis_alone():
    model = dataclasses.replace(
        preset_model("adxrs450").without("lag"), hysteresis=Hysteresis(((0.0, 3e-5),), direction="descending")
    )
    cal, _, vs_perfect, cubic_over_chosen = _experiment(model)
    assert cal.fit_report["hysteresis"]["axes"]["gyro_z"]["chosen"].startswith("turning-point")
    assert vs_perfect < 1.2 and cubic_over_chosen > 2.0


@settings(max_examples=25, deadline=None)
@given(st.lists(st.integers(min_value=1, max_value=5000), min_size=1, max_size=12))
def test_streaming_equals_batch_with_lag_and_hysteresis(both_effects, cuts):
    cal, held, _, _ = both_effects
    assert_streaming_equals_batch(cal, held.recording, cuts)


def test_model_file_round_trip_keeps_lag_and_hysteresis(both_effects, tmp_path):
    cal, held, _, _ = both_effects
    cal.save(tmp_path / "m.json")
    loaded = Calibration.load(tmp_path / "m.json")
    assert loaded.axes == cal.axes
    d = json.loads((tmp_path / "m.json").read_text())
    ax = d["axes"]["gyro_z"]
    assert ax["lag_time_constant_s"] > 0 and ax["hysteresis"]["type"] == "turning-point"
    assert d["fit_report"]["hysteresis"]["selection"] == "leave-one-run-out"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        np.testing.assert_array_equal(apply(loaded, held.recording).gyro_dps, apply(cal, held.recording).gyro_dps)


def test_heating_only_runs_get_no_hysteresis_candidates():
    runs = [simulate("adxrs450", profile="chamber", duration_s=3000, rate_hz=1, seed=s).recording for s in range(2)]
    cal = fit_calibration(runs)
    # no reversal: validated on contiguous time blocks, and no turning-point candidate was scored (a thermal lag
    # can still be chosen: the part has one)
    selection = cal.fit_report["selection"]["gyro_z"]
    assert selection["fold_kind"] in ("blocks", "legs")
    assert all(c["hysteresis_order"] == 0 for c in selection["candidates"])
    assert all(ax.hysteresis is None for ax in cal.axes.values())


def test_bad_hysteresis_options_and_not_fitted():
    runs = [simulate("adxrs450", profile="cycle", duration_s=2000, rate_hz=1, seed=1).recording]
    with pytest.raises(InputError, match=r"hysteresis: 'magic'; use one of auto, none, turning-point, lag"):
        fit_calibration(runs, hysteresis="magic")
    with pytest.raises(InputError, match=r"band_degc: \(80.0, 55.0\); give \(low, high\) with low < high"):
        ThermalHysteresisModel(order=2, band_degc=(80.0, 55.0)).fit(runs)
    with pytest.raises(InputError, match=r"hysteresis_order: 7; use 'auto' or 1..3"):
        ThermalHysteresisModel(order=2, hysteresis_order=7).fit(runs)
    with pytest.raises(NotFittedError, match="not fitted yet"):
        _ = ThermalHysteresisModel(order=2).lag_time_constants_s_


def test_a_lag_model_needs_the_stream_rate(both_effects):
    cal = both_effects[0]
    with pytest.raises(InputError, match=r"<stream>: the model has thermal lag; give the stream's sample rate"):
        Compensator(cal, ("gyro_z",))


def test_the_band_is_found_in_the_data_when_not_given():
    cal, _, vs_perfect, cubic_over_chosen = _experiment(preset_model("adxrs450"))
    ax = cal.axes["gyro_z"]
    lo, hi = ax.hysteresis.band_degc
    # the preset's hysteresis lives between 55 and 80 degC on cooling (zero at both ends)
    assert 50 < lo < 60 and 72 < hi <= 80.5
    assert ax.lag_time_constant_s == pytest.approx(60.0, rel=0.25)
    assert vs_perfect < 1.35 and cubic_over_chosen > 2.0


def test_one_temperature_column_gives_every_lagged_axis_one_time_constant():
    runs = [simulate("consumer", profile="cycle", duration_s=4000, rate_hz=1, seed=s).recording for s in range(2)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        shared = ThermalHysteresisModel(order=2, hysteresis="lag", hysteresis_order=0).fit(runs)
        own = ThermalHysteresisModel(order=2, hysteresis="lag", hysteresis_order=0, shared_lag=False).fit(runs)
        # one temperature column per axis: each axis may sit on its own die, so each keeps its own lag
        per_axis = [
            dataclasses.replace(r, temperature_degc=np.repeat(r.temperature_degc[:, None], 3, axis=1)) for r in runs
        ]
        separate = ThermalHysteresisModel(order=2, hysteresis="lag", hysteresis_order=0).fit(per_axis)
    taus = list(shared.lag_time_constants_s_.values())
    assert len(set(taus)) == 1 and taus[0] == pytest.approx(30.0, rel=0.25)  # the preset's 30 s
    assert len(set(own.lag_time_constants_s_.values())) == 3
    assert separate.lag_time_constants_s_ == own.lag_time_constants_s_
