"""The simulator's noise that changes with temperature: white noise and flicker scaled by 1 + c (T - t_ref)."""

import dataclasses

import numpy as np
import pytest

from gyrocomp.errors import InputError
from gyrocomp.simulation import preset_model
from gyrocomp.simulation.error_model import simulate_noise


def test_the_noise_scales_with_the_structure_temperature():
    model = dataclasses.replace(preset_model("mti10"), noise_tempco_per_degc=0.02)
    n, rate = 200_000, 50.0
    for temperature, scale in ((25.0, 1.0), (50.0, 1.5), (-100.0, 0.1)):  # held at 0.1 far below
        truth = simulate_noise(n, rate, model, np.random.default_rng(1), np.full(n, temperature))
        expected = model.noise_density_dps_per_sqrt_hz * np.sqrt(rate) * scale
        # the sample standard deviation of n normal draws: relative error sqrt(1 / 2n); 4 of those
        assert np.std(truth.white_dps[:, 0]) == pytest.approx(expected, rel=4 * np.sqrt(0.5 / n))
    flat = simulate_noise(1000, rate, preset_model("mti10"), np.random.default_rng(1), np.full(1000, 80.0))
    same = simulate_noise(1000, rate, preset_model("mti10"), np.random.default_rng(1))
    np.testing.assert_array_equal(flat.white_dps, same.white_dps)  # no coefficient: the draws are unchanged
    with pytest.raises(InputError, match=r"noise_tempco_per_degc: must be finite, got nan"):
        dataclasses.replace(preset_model("mti10"), noise_tempco_per_degc=float("nan"))
