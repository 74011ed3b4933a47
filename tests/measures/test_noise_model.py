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
        assert axis.markov.ratio_median <= axis.bound.ratio_median + 1e-9
    assert model.to_dict()["axes"]["gyro_x"]["logs"][1]["temperature_degc"] == 40.0


def test_one_rate_per_model_and_shared_axes():
    a = analyse_noise(simulate("consumer", profile="static", duration_s=300, rate_hz=50.0, seed=1).recording)
    b = analyse_noise(simulate("consumer", profile="static", duration_s=300, rate_hz=20.0, seed=1).recording)
    with pytest.raises(InputError, match=r"noise: the logs have different sample rates \(20, 50 Hz\)"):
        noise_model([a, b])
    with pytest.raises(InputError, match=r"noise: give at least one static log"):
        noise_model([])
