"""The simulator's noise matches its parameters (Allan deviation), and its truth adds up."""

import numpy as np
import pytest

from gyrocomp.allan import allan_deviation
from gyrocomp.errors import InputError
from gyrocomp.metrics import BIAS_INSTABILITY_FACTOR
from gyrocomp.simulate import GyroErrorModel, flicker_bank, get_profile, simulate
from gyrocomp.units import DEG_PER_S_TO_DEG_PER_H


def test_truth_adds_up_exactly():
    sim = simulate(duration_s=200, rate_hz=10, seed=3)
    rebuilt = sim.truth.deterministic_error_dps + sim.truth.noise.total_dps
    np.testing.assert_array_equal(sim.recording.gyro_dps, rebuilt)


def test_same_seed_same_run_other_seed_other_turn_on():
    a, b, c = (simulate(duration_s=50, rate_hz=10, seed=s) for s in (1, 1, 2))
    np.testing.assert_array_equal(a.recording.gyro_dps, b.recording.gyro_dps)
    assert not np.allclose(a.truth.turn_on_bias_dps, c.truth.turn_on_bias_dps)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_white_noise_density_recovered(seed):
    model = GyroErrorModel(axes=("gyro_z",), temperature_coefficients=((0.0,),), bias_instability_deg_per_h=0.0,
                           noise_density_dps_per_sqrt_hz=0.005)
    sim = simulate(model, profile="static", duration_s=2000, rate_hz=100, seed=seed)
    res = allan_deviation(sim.recording.gyro_dps[:, 0], 100.0, taus=np.array([1.0]))
    # a 1-s overlapping estimate over 2000 s has about sqrt(2000/1.5) equivalent degrees of freedom
    assert res.deviation[0] == pytest.approx(0.005, rel=4 / np.sqrt(2 * 2000 / 1.5))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_flicker_bank_gives_a_flat_floor_at_0664_b(seed):
    rate_hz, b = 10.0, 10.0
    x = flicker_bank(400_000, rate_hz, b, np.random.default_rng(seed))
    res = allan_deviation(x, rate_hz, taus=np.array([10.0, 30.0, 100.0, 300.0, 1000.0]))
    floor = BIAS_INSTABILITY_FACTOR * b / DEG_PER_S_TO_DEG_PER_H
    np.testing.assert_allclose(res.deviation, floor, rtol=0.3)
    assert np.median(res.deviation) == pytest.approx(floor, rel=0.15)


def test_rate_random_walk_recovered():
    k = 2e-4  # [deg/s/sqrt(s)]
    model = GyroErrorModel(axes=("gyro_z",), temperature_coefficients=((0.0,),), bias_instability_deg_per_h=0.0,
                           noise_density_dps_per_sqrt_hz=1e-5, rate_random_walk_dps_per_sqrt_s=k)
    devs = []
    for seed in range(6):
        sim = simulate(model, profile="static", duration_s=20000, rate_hz=5, seed=seed)
        devs.append(allan_deviation(sim.recording.gyro_dps[:, 0], 5.0, taus=np.array([300.0])).deviation[0])
    # sigma^2 = K^2 tau / 3, averaged over seeds
    assert np.sqrt(np.mean(np.square(devs))) == pytest.approx(k * np.sqrt(300 / 3), rel=0.2)


def test_profiles():
    t = np.arange(0, 1001.0)
    chamber = get_profile("chamber").temperature_degc(t)
    assert chamber[0] == -20 and chamber[-1] == 70
    assert np.all(np.diff(chamber) >= 0)
    cycle = get_profile("cycle").temperature_degc(t)
    assert cycle[0] == -20 and cycle.max() == 70 and cycle[-1] == -20
    assert np.all(get_profile("static").temperature_degc(t) == 25)
    assert get_profile("chamber").ramp_rate_degc_per_s(1000) == pytest.approx(90 / 800)
    with pytest.raises(InputError, match=r"--profile: unknown profile 'oven'"):
        get_profile("oven")


def test_parameter_errors():
    with pytest.raises(InputError, match="temperature_coefficients: 1 sets for 3 axes"):
        GyroErrorModel(temperature_coefficients=((1.0,),))
    with pytest.raises(InputError, match="noise_density_dps_per_sqrt_hz: must not be negative"):
        GyroErrorModel(noise_density_dps_per_sqrt_hz=-1)
    with pytest.raises(InputError, match="--duration and --rate must be positive"):
        simulate(duration_s=0)
