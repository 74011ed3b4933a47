"""What real parts show beyond white noise, flicker and random walk: a non-repeatable smooth drift (part of it
following the temperature by a relation that differs from run to run), a warm-up transient after power-on, and a
bias that depends on the rate of change of the temperature; each against its definition."""

import dataclasses
import math

import numpy as np
import pytest

from gyrocomp.errors import InputError
from gyrocomp.simulation import GyroErrorModel, get_profile, simulate
from gyrocomp.simulation.error_model import smooth_process

RATE_HZ = 2.0
QUIET = GyroErrorModel(
    axes=("gyro_x",),
    temperature_coefficients=((0.0,),),
    noise_density_dps_per_sqrt_hz=0.0,
    bias_instability_deg_per_h=0.0,
    turn_on_bias_sigma_dps=0.0,
    accelerometer=None,
)


def test_the_smooth_process_has_unit_variance_and_grows_as_dt_squared_below_its_time_constant():
    """Its variance is 1 by construction (the drive scaled by the cascade's impulse response; the mean square of
    400 draws of three time constants about the known mean 0 scatters by about 5 %), and its variogram is that of
    a critically damped second-order process, 2 (1 - (1 + dt/T) exp(-dt/T)), about dt^2 / T^2 well below T."""
    rng = np.random.default_rng(0)
    t_c = 100.0
    draws = np.array([smooth_process(600, 2.0, t_c, rng) for _ in range(400)])
    assert np.mean(draws**2) == pytest.approx(1.0, rel=0.1)  # 400 x ~3 independent stretches: ~5 %
    for lag_s in (5.0, 10.0, 50.0):
        lag = int(lag_s * 2.0)
        measured = np.mean((draws[:, lag:] - draws[:, :-lag]) ** 2)
        x = lag_s / t_c
        assert measured == pytest.approx(2.0 * (1.0 - (1.0 + x) * math.exp(-x)), rel=0.15)


def test_a_part_without_the_new_terms_draws_nothing_for_them():
    sim = simulate(QUIET, profile="cycle", duration_s=600, rate_hz=RATE_HZ, seed=1)
    assert sim.truth.noise.drift_dps is None and sim.truth.noise.warm_up_dps is None
    assert not np.any(sim.truth.components_dps["temperature_rate"])


def test_the_warm_up_transient_decays_with_its_time_constant_and_differs_by_power_on():
    part = dataclasses.replace(QUIET, warm_up_sigma_dps=0.1, warm_up_time_s=300.0)
    first, second = (simulate(part, profile="static", duration_s=1200, rate_hz=RATE_HZ, seed=s) for s in (1, 2))
    w = first.truth.noise.warm_up_dps[:, 0]
    t = first.recording.time_s - first.recording.time_s[0]
    np.testing.assert_allclose(w, w[0] * np.exp(-t / 300.0), rtol=1e-12)
    assert w[0] != second.truth.noise.warm_up_dps[0, 0]
    # the output is the transient here (no other error): the truth adds up
    np.testing.assert_allclose(first.recording.gyro_dps[:, 0], w, atol=1e-15)


def test_a_bias_from_the_temperature_rate_parts_heating_from_cooling_by_twice_k_times_the_ramp():
    k = 0.02  # deg/s per degC/min
    part = dataclasses.replace(QUIET, temperature_rate_dps_per_degc_per_min=(k,))
    prof = get_profile("chamber", set_points_degc=(20.0, 60.0, 20.0), ramp_rate_degc_per_min=2.0, dwell_s=600.0)
    sim = simulate(part, profile=prof, rate_hz=RATE_HZ, seed=0)
    error = sim.truth.components_dps["temperature_rate"][:, 0]
    rate = np.gradient(sim.truth.structure_temperature_degc, sim.recording.time_s) * 60.0
    heating, cooling = rate > 1.99, rate < -1.99
    assert heating.sum() > 100 and cooling.sum() > 100
    np.testing.assert_allclose(error[heating], 2.0 * k, rtol=1e-6)
    np.testing.assert_allclose(error[cooling], -2.0 * k, rtol=1e-6)
    assert np.all(np.abs(error[np.abs(rate) < 1e-9]) < 1e-12)  # none on the holds


def test_the_non_repeatable_drift_follows_the_temperature_partly_and_differs_by_run():
    """With the temperature part alone, drift / (T_s - T_ref) is a smooth process of standard deviation sigma_c;
    with the smooth part alone it does not depend on the temperature; both differ from run to run."""
    prof = get_profile("chamber", set_points_degc=(40.0, -20.0, 70.0, 30.0), ramp_rate_degc_per_min=2.0, dwell_s=300.0)
    tempco = dataclasses.replace(QUIET, run_tempco_sigma_dps_per_degc=0.002, run_drift_time_s=600.0)
    runs = [simulate(tempco, profile=prof, rate_hz=RATE_HZ, seed=s) for s in range(12)]
    ratios = []
    for sim in runs:
        above = sim.truth.structure_temperature_degc - tempco.t_ref_degc
        keep = np.abs(above) > 5.0
        ratios.append(sim.truth.noise.drift_dps[keep, 0] / above[keep])
    assert np.sqrt(np.mean(np.concatenate(ratios) ** 2)) == pytest.approx(0.002, rel=0.3)  # 12 x ~19 stretches
    assert np.std([r.mean() for r in ratios]) > 0.0005  # a relation of its own in each run
    smooth = dataclasses.replace(QUIET, run_drift_dps=0.05, run_drift_time_s=600.0)
    a, b = (simulate(smooth, profile=prof, rate_hz=RATE_HZ, seed=s).truth.noise.drift_dps[:, 0] for s in (1, 2))
    assert not np.allclose(a, b)
    rebuilt = simulate(smooth, profile=prof, rate_hz=RATE_HZ, seed=1)
    np.testing.assert_allclose(rebuilt.recording.gyro_dps[:, 0], a, atol=1e-15)  # the same seed, the same drift


def test_the_new_terms_can_be_switched_off_and_are_checked():
    part = dataclasses.replace(
        QUIET, run_drift_dps=0.05, warm_up_sigma_dps=0.1, temperature_rate_dps_per_degc_per_min=(0.01,)
    )
    off = part.without("drift", "warm-up", "temperature-rate")
    assert off.run_drift_dps == 0 and off.warm_up_sigma_dps == 0 and off.temperature_rate_dps_per_degc_per_min is None
    with pytest.raises(InputError, match="run_drift_dps: must not be negative"):
        dataclasses.replace(QUIET, run_drift_dps=-1.0)
    with pytest.raises(InputError, match="warm_up_time_s: must be positive and finite, got 0"):
        dataclasses.replace(QUIET, warm_up_time_s=0.0)
    with pytest.raises(InputError, match=r"temperature_rate_dps_per_degc_per_min: shape \(2,\), expected \(1,\)"):
        dataclasses.replace(QUIET, temperature_rate_dps_per_degc_per_min=(0.1, 0.2))
