"""The noise model of static logs: the record length read back from a curve, several logs bounded together
(each log's own bound kept), one rate per model."""

from __future__ import annotations

import numpy as np
import pytest

from gyrocomp.allan import allan_deviation
from gyrocomp.errors import InputError
from gyrocomp.measures.noise import analyse_noise
from gyrocomp.measures.noise_model import MAX_TAU_FRACTION, noise_model, record_length_s
from gyrocomp.simulation import simulate


def test_the_record_length_is_read_back_from_an_overlapping_curve():
    for n, rate in ((10_000, 100.0), (3_333, 7.0)):
        curve = allan_deviation(np.random.default_rng(1).normal(size=n), rate, taus="octave")
        assert record_length_s(curve, rate) == pytest.approx(n / rate)


def test_logs_are_bounded_together_and_each_keeps_its_own():
    runs = [simulate("consumer", profile="static", duration_s=900, rate_hz=50.0, seed=s).recording for s in (1, 2)]
    analyses = [analyse_noise(r) for r in runs]
    model = noise_model(analyses, temperatures_degc=[10.0, 40.0])
    for name, axis in model.axes.items():
        assert [log.temperature_degc for log in axis.logs] == [10.0, 40.0]
        assert axis.max_tau_s == pytest.approx(MAX_TAU_FRACTION * 900.0, rel=1e-3)
        for analysis in analyses:  # at or above each log's measured curve wherever it is bounded
            curve = analysis.axes[name].allan
            bounded = curve.tau <= axis.max_tau_s
            assert np.all(axis.bound.deviation(curve.tau[bounded]) >= curve.deviation[bounded])
            assert np.all(axis.markov.deviation(curve.tau[bounded]) >= curve.deviation[bounded])
    assert model.to_dict()["axes"]["gyro_x"]["logs"][1]["temperature_degc"] == 40.0


def test_one_rate_per_model_and_shared_axes():
    a = analyse_noise(simulate("consumer", profile="static", duration_s=300, rate_hz=50.0, seed=1).recording)
    b = analyse_noise(simulate("consumer", profile="static", duration_s=300, rate_hz=20.0, seed=1).recording)
    with pytest.raises(InputError, match=r"noise: the logs have different sample rates \(20, 50 Hz\)"):
        noise_model([a, b])
    with pytest.raises(InputError, match=r"noise: give at least one static log"):
        noise_model([])


def _warming(preset: str):
    """A part whose white noise and flicker grow 1 % per degC, held at -20, 25 and 70 degC."""
    import dataclasses

    from gyrocomp.simulation import get_profile, preset_model

    model = dataclasses.replace(preset_model(preset), noise_tempco_per_degc=0.01)
    profile = get_profile("chamber", set_points_degc=(-20.0, 25.0, 70.0), dwell_s=2400.0)
    return model, simulate(model, profile=profile, rate_hz=20.0, seed=1).recording


@pytest.fixture(scope="module")
def warming_part():
    return _warming("mti10")


def test_the_dwells_of_a_chamber_run_are_found_after_settling(warming_part):
    from gyrocomp.measures.noise_model import temperature_dwells

    _, rec = warming_part
    dwells = temperature_dwells(rec)
    assert [round(float(np.mean(rec.temperature_degc[d]))) for d in dwells] == [-20, 25, 70]
    for d in dwells:
        assert rec.time_s[d.stop - 1] - rec.time_s[d.start] >= 600.0
        assert np.ptp(rec.temperature_degc[d]) < 1.0
    with pytest.raises(InputError, match=r"no dwell of 600 s after 300 s of settling"):
        from gyrocomp.measures.noise_model import noise_over_temperature

        noise_over_temperature(rec.take(slice(0, 6000)))


@pytest.mark.parametrize("preset", ["mti10", "adis16488", "consumer"])
def test_the_bound_over_temperature_is_above_the_true_noise_at_every_dwell(preset):
    """Three parts whose noise grows 1 %/degC: the simulated truth at each dwell is the same part held at that
    temperature (the mean Allan variance of independent static draws); the bound of all dwells lies above each at
    >= 95 % of the bounded taus, and each dwell's white noise follows the part's within its interval."""
    from gyrocomp.allan import allan_deviation
    from gyrocomp.measures.noise_model import noise_over_temperature
    from gyrocomp.simulation.error_model import simulate_noise

    model, rec = _warming(preset)
    noise = noise_over_temperature(rec)
    axis = noise.axes[model.axes[0]]
    assert [round(log.temperature_degc) for log in axis.logs] == [-20, 25, 70]
    for log in axis.logs:
        low, _, high = log.white_noise_interval
        expected = model.noise_density_dps_per_sqrt_hz * float(model.noise_scale(log.temperature_degc))
        assert 0.9 * low <= expected <= 1.1 * high
    taus = np.array([t for t in axis.bound.taus_s if t <= axis.max_tau_s])
    for temperature in (-20.0, 25.0, 70.0):
        n = int(20.0 * 2100)
        truths = [simulate_noise(n, 20.0, model, np.random.default_rng(s), np.full(n, temperature)) for s in range(8)]
        draws = [t.white_dps[:, 0] + t.flicker_dps[:, 0] + t.random_walk_dps[:, 0] for t in truths]
        truth = np.sqrt(np.mean([allan_deviation(d, 20.0, taus=taus).deviation ** 2 for d in draws], axis=0))
        assert np.mean(axis.bound.deviation(taus) >= truth) >= 0.95, temperature


def test_the_scheduled_bound_is_each_dwells_at_its_temperature_and_held_past_them(warming_part):
    from gyrocomp.measures.noise_model import noise_over_temperature, scheduled_bound

    _, rec = warming_part
    axis = noise_over_temperature(rec).axes["gyro_x"]
    at = scheduled_bound(axis)
    cold, middle, hot = axis.logs
    assert at(cold.temperature_degc).white_noise_density == pytest.approx(cold.bound.white_noise_density)
    assert at(-60.0).white_noise_density == pytest.approx(cold.bound.white_noise_density)
    assert at(120.0).random_walk == pytest.approx(hot.bound.random_walk)
    halfway = 0.5 * (middle.temperature_degc + hot.temperature_degc)
    assert at(halfway).white_noise_density ** 2 == pytest.approx(
        0.5 * (middle.bound.white_noise_density**2 + hot.bound.white_noise_density**2)
    )


def test_the_scheduled_markov_bound_keeps_one_grid_and_mixes_the_dwells_variances(warming_part):
    """With Gauss-Markov terms: each dwell's own bound (on the axis's grid, at or above its curve) at its
    temperature, the same correlation times at every temperature (a filter's states), and between two dwells
    the mean of their Allan variances at every tau (so never below both)."""
    from gyrocomp.measures.noise_model import noise_over_temperature, scheduled_bound

    _, rec = warming_part
    axis = noise_over_temperature(rec).axes["gyro_x"]
    at = scheduled_bound(axis, markov=True)
    from gyrocomp.allan.bound import markov_grid

    taus = np.array(axis.markov.taus_s)
    grid = set(markov_grid(taus[0], taus[-1]).tolist())
    times = {tuple(t for _, t in at(temperature).markov) for temperature in (-40.0, -20.0, 0.0, 25.0, 47.0, 90.0)}
    assert len(times) == 1 and set(next(iter(times))) <= grid
    assert {t for _, t in axis.markov.markov} <= grid
    for log in axis.logs:
        assert {t for _, t in log.markov.markov} <= set(next(iter(times)))
        assert np.allclose(at(log.temperature_degc).deviation(taus), log.markov.deviation(taus), rtol=1e-12)
        assert log.markov.ratio_median >= 1.0  # at or above its own curve
    cold, middle, hot = axis.logs
    halfway = 0.5 * (cold.temperature_degc + middle.temperature_degc)
    mixed = 0.5 * (cold.markov.deviation(taus) ** 2 + middle.markov.deviation(taus) ** 2)
    assert np.allclose(at(halfway).deviation(taus) ** 2, mixed, rtol=1e-12)
    assert np.allclose(at(200.0).deviation(taus), hot.markov.deviation(taus), rtol=1e-12)
