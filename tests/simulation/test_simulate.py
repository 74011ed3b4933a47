"""The simulator: its noise matches the preset (Allan deviation), its effects match their parameters,
and its truth adds up to the output."""

import dataclasses
import math

import numpy as np
import pytest

from gyrocomp.allan import allan_deviation, noise_parameters
from gyrocomp.errors import InputError
from gyrocomp.measures.merit import BIAS_INSTABILITY_FACTOR
from gyrocomp.simulation import PRESETS, GyroErrorModel, Hysteresis, flicker_bank, get_profile, preset_model, simulate
from gyrocomp.simulation.profiles import TUMBLE_LEVELS_G
from gyrocomp.units import DEG_PER_S_TO_DEG_PER_H


@pytest.mark.parametrize("preset", sorted(PRESETS))
@pytest.mark.parametrize("profile", ["cycle", "tumble", "combined", "ratetable"])
def test_output_is_rate_plus_error_plus_noise(preset, profile):
    sim = simulate(preset, profile=profile, duration_s=3000, rate_hz=5, seed=3)
    t = sim.truth
    rebuilt = t.true_rate_dps + t.deterministic_error_dps + t.noise.total_dps
    np.testing.assert_allclose(sim.recording.gyro_dps, rebuilt, rtol=0, atol=1e-12)
    lsb = t.model.quantization_dps
    if lsb > 0:  # a part with an output LSB (the drifting preset has none)
        np.testing.assert_allclose(sim.recording.gyro_dps / lsb, np.round(sim.recording.gyro_dps / lsb), atol=1e-6)
    assert np.all(np.abs(t.noise.quantization_dps) <= lsb / 2 + 1e-12)


def test_same_seed_same_run_other_seed_other_turn_on():
    a, b, c = (simulate(duration_s=50, rate_hz=10, seed=s) for s in (1, 1, 2))
    np.testing.assert_array_equal(a.recording.gyro_dps, b.recording.gyro_dps)
    assert not np.allclose(a.truth.turn_on_bias_dps, c.truth.turn_on_bias_dps)
    np.testing.assert_array_equal(a.truth.temperature_error_dps, c.truth.temperature_error_dps)


def _expected_adev(model: GyroErrorModel, tau, rate_hz):
    """sigma^2 = (N^2 + q^2 / (12 f)) / tau + (0.664 B)^2 + K^2 tau / 3; the output rounding is white."""
    white = model.noise_density_dps_per_sqrt_hz**2 + model.quantization_dps**2 / (12 * rate_hz)
    floor = BIAS_INSTABILITY_FACTOR * model.bias_instability_deg_per_h / DEG_PER_S_TO_DEG_PER_H
    return np.sqrt(white / tau + floor**2 + model.rate_random_walk_dps_per_sqrt_s**2 * tau / 3)


@pytest.mark.parametrize(
    "preset, duration_s, rate_hz",
    [
        ("adxrs450", 4 * 3600, 20.0),
        ("mti10", 4 * 3600, 20.0),
        ("adis16488", 4 * 3600, 20.0),
        ("consumer", 4 * 3600, 20.0),
    ],
)
def test_static_run_has_the_presets_allan_curve(preset, duration_s, rate_hz):
    model = preset_model(preset)
    inside, total = 0, 0
    for seed in range(3):
        sim = simulate(preset, profile="static", duration_s=duration_s, rate_hz=rate_hz, seed=seed)
        res = allan_deviation(sim.recording.gyro_dps[:, 0], rate_hz, confidence=0.95)
        # from 10 samples (the Gauss-Markov bank starts at 2) to a tenth of the run
        use = (res.tau >= 10 / rate_hz) & (res.tau <= duration_s / 10)
        expected = _expected_adev(model, res.tau[use], rate_hz)
        inside += int(np.sum((expected >= res.ci_low[use]) & (expected <= res.ci_high[use])))
        total += int(use.sum())
        terms = noise_parameters(res)
        white = math.sqrt(model.noise_density_dps_per_sqrt_hz**2 + model.quantization_dps**2 / (12 * rate_hz))
        assert terms.noise_density_dps_per_sqrt_hz == pytest.approx(white, rel=0.1)
    # 95 % intervals: with correlated neighbouring taus, allow a few misses over three seeds
    assert inside >= 0.9 * total


def test_consumer_rate_random_walk_recovered():
    model = preset_model("consumer")
    k = model.rate_random_walk_dps_per_sqrt_s
    rates = []
    # K^2 tau / 3 rises above the 20 deg/h floor only past about 16000 s: runs of three days
    for seed in range(5):
        sim = simulate("consumer", profile="static", duration_s=72 * 3600, rate_hz=1.0, seed=seed)
        res = allan_deviation(sim.recording.gyro_dps[:, 2], 1.0)
        rates.append(noise_parameters(res).rrw_dps_sqrt_hz)  # deg/s*sqrt(Hz) = deg/s/sqrt(s)
    assert np.median(rates) == pytest.approx(k, rel=0.3)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_white_noise_density_recovered(seed):
    model = GyroErrorModel(
        axes=("gyro_z",),
        temperature_coefficients=((0.0,),),
        bias_instability_deg_per_h=0.0,
        noise_density_dps_per_sqrt_hz=0.005,
    )
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


def test_flicker_bank_drawn_coarse_for_slow_processes_has_the_same_floor():
    """The slow Gauss-Markov processes are drawn on coarse grids; over seeds the floor stays 0.664 B."""
    rate_hz, b, n = 20.0, 10.0, 216_000
    taus = np.array([1.0, 5.0, 20.0, 100.0])
    var = np.mean(
        [
            allan_deviation(
                flicker_bank(n, rate_hz, b, np.random.default_rng(s)), rate_hz, taus=taus, confidence=None
            ).deviation
            ** 2
            for s in range(8)
        ],
        axis=0,
    )
    floor = BIAS_INSTABILITY_FACTOR * b / DEG_PER_S_TO_DEG_PER_H
    np.testing.assert_allclose(np.sqrt(var), floor, rtol=0.08)


def test_rate_random_walk_recovered():
    k = 2e-4  # [deg/s/sqrt(s)]
    model = GyroErrorModel(
        axes=("gyro_z",),
        temperature_coefficients=((0.0,),),
        bias_instability_deg_per_h=0.0,
        noise_density_dps_per_sqrt_hz=1e-5,
        rate_random_walk_dps_per_sqrt_s=k,
    )
    devs = []
    for seed in range(6):
        sim = simulate(model, profile="static", duration_s=20000, rate_hz=5, seed=seed)
        devs.append(allan_deviation(sim.recording.gyro_dps[:, 0], 5.0, taus=np.array([300.0])).deviation[0])
    # sigma^2 = K^2 tau / 3, averaged over seeds
    assert np.sqrt(np.mean(np.square(devs))) == pytest.approx(k * np.sqrt(300 / 3), rel=0.2)


def _branch_means(temp, value, direction, centres, half_width=0.5):
    out = []
    for c in centres:
        sel = (np.abs(temp - c) <= half_width) & direction
        out.append(value[sel].mean())
    return np.array(out)


def test_cycle_shows_the_presets_hysteresis_between_branches():
    model = dataclasses.replace(preset_model("adxrs450"), thermal_time_constant_s=0.0)
    sim = simulate(model, profile=get_profile("cycle", set_points_degc=(-30.0, 80.0), cycles=1), rate_hz=5, seed=1)
    rec = sim.recording
    temp, gyro = rec.temperature_degc, rec.gyro_dps[:, 0]
    rising = np.gradient(sim.truth.reported_temperature_degc) > 0
    falling = np.gradient(sim.truth.reported_temperature_degc) < 0
    centres = np.arange(40.0, 78.0, 2.5)
    gap = _branch_means(temp, gyro, falling, centres) - _branch_means(temp, gyro, rising, centres)
    d = 80.0 - centres
    expected = np.where(centres >= 55, 0.032 * d - 0.00128 * d**2, 0.0)
    # each branch mean averages ~300 samples of 0.015 deg/s/sqrt(Hz) noise plus the 25 deg/h floor
    np.testing.assert_allclose(gap, expected, atol=0.03)
    assert gap[centres == 67.5][0] == pytest.approx(0.2, abs=0.03)


@pytest.mark.parametrize("ramp", [1.0, 3.0])
def test_thermal_lag_opens_a_branch_gap_in_proportion_to_the_ramp_rate(ramp):
    base = preset_model("consumer")
    # a strong tempco and little noise, so that the gap stands out from the drift between branches
    model = dataclasses.replace(
        base,
        hysteresis=None,
        temperature_coefficients=((0.1,), (0.0,), (0.0,)),
        temperature_quantization_degc=0.0,
        temperature_noise_degc=0.0,
        bias_instability_deg_per_h=1.0,
        rate_random_walk_dps_per_sqrt_s=0.0,
    )
    prof = get_profile("cycle", set_points_degc=(-20.0, 70.0), cycles=1, ramp_rate_degc_per_min=ramp, dwell_s=600.0)
    sim = simulate(model, profile=prof, rate_hz=2, seed=5)
    temp, gyro = sim.recording.temperature_degc, sim.recording.gyro_dps[:, 0]
    slope = np.gradient(temp)
    centres = np.arange(0.0, 55.0, 5.0)
    gap = _branch_means(temp, gyro, slope > 0, centres, 1.0) - _branch_means(temp, gyro, slope < 0, centres, 1.0)
    # the structure lags by r tau on both branches: heating reads low, cooling high, by 0.1 r tau each
    expected = 2 * 0.1 * (ramp / 60.0) * model.thermal_time_constant_s
    assert np.median(gap) == pytest.approx(-expected, rel=0.05)


def test_tumble_offsets_are_the_g_sensitivity_matrix():
    # with the preset's 18 deg/h the flicker drift between the axis groups is as large as G itself;
    # at 1 deg/h and 20 minutes a position the white noise sets the error: 0.03 / sqrt(1200) per
    # position, about 4e-4 deg/s/g on each element of G
    model = dataclasses.replace(preset_model("mti10"), bias_instability_deg_per_h=1.0)
    sim = simulate(model, profile=get_profile("tumble", position_s=1200.0), rate_hz=2, seed=2)
    rec, t = sim.recording, sim.truth
    still = ~np.any(t.true_rate_dps, axis=1)
    force = t.specific_force_g[still]
    gyro = rec.gyro_dps[still]
    accel = rec.accel_g[still]
    # the accelerometer reads the tumble levels (plus its bias) on each axis
    for axis in range(3):
        for level in TUMBLE_LEVELS_G:
            sel = np.isclose(force[:, axis], level)
            assert accel[sel, axis].mean() == pytest.approx(level + model.accelerometer.bias_g[axis], abs=2e-4)
    # least squares of the gyro output on [1, f] recovers G; noise per 5-minute position ~ 0.03/sqrt(300)
    design = np.column_stack([np.ones(len(force)), force])
    coef, *_ = np.linalg.lstsq(design, gyro, rcond=None)
    np.testing.assert_allclose(coef[1:].T, np.asarray(model.g_sensitivity_dps_per_g), atol=1.5e-3)


def test_ratetable_shows_scale_factor_and_misalignment():
    model = preset_model("mti10")
    sim = simulate(model, profile="ratetable", rate_hz=10, seed=4)
    t = sim.truth
    spin_x = t.true_rate_dps[:, 0] == 100.0
    err = t.components_dps["scale_misalignment"][spin_x]
    sf = model.scale_factor_error_ppm[0] * 1e-6 + model.scale_factor_tempco_ppm_per_degc[0] * 1e-6 * (
        t.structure_temperature_degc[spin_x] - model.t_ref_degc
    )
    np.testing.assert_allclose(err[:, 0], 100.0 * sf, rtol=1e-12)
    np.testing.assert_allclose(err[:, 1], 100.0 * model.misalignment_rad[1][0], rtol=1e-12)
    measured = sim.recording.gyro_dps[spin_x, 0].mean() - t.turn_on_bias_dps[0]
    g_x = model.g_sensitivity_dps_per_g[0][0]  # x is mounted up while it spins
    # one minute of 0.03 deg/s/sqrt(Hz) white noise and the 18 deg/h floor: about 0.006 deg/s
    assert measured == pytest.approx(100.0 * (1 + sf.mean()) + g_x, abs=0.02)


def test_whole_degree_temperature_and_sensor_noise():
    sim = simulate("consumer", profile="chamber", duration_s=1800, rate_hz=2, seed=0)
    temp = sim.recording.temperature_degc
    np.testing.assert_array_equal(temp, np.round(temp))
    assert np.ptp(temp) >= 85
    sim = simulate("mti10", profile="static", duration_s=600, rate_hz=10, seed=0)
    assert np.std(sim.recording.temperature_degc) == pytest.approx(0.05, rel=0.15)


def test_units_of_a_preset_differ_and_repeat():
    a, b, a2 = preset_model("mti10", 1), preset_model("mti10", 2), preset_model("mti10", 1)
    assert a == a2 and a != b
    assert a.noise_density_dps_per_sqrt_hz == PRESETS["mti10"].model.noise_density_dps_per_sqrt_hz
    ratio = np.asarray(a.g_sensitivity_dps_per_g) / np.asarray(PRESETS["mti10"].model.g_sensitivity_dps_per_g)
    assert np.all(np.abs(ratio - 1) < 1.0) and not np.allclose(ratio, 1)


def test_axes_subset_keeps_each_axis_parameters():
    full = preset_model("mti10")
    z = full.subset(("gyro_z",))
    assert z.temperature_coefficients == (full.temperature_coefficients[2],)
    assert z.g_sensitivity_dps_per_g == (full.g_sensitivity_dps_per_g[2],)
    assert z.hysteresis.coefficients_dps == (full.hysteresis.coefficients_dps[2],)
    sim = simulate(z, profile="static", duration_s=10, rate_hz=10)
    assert sim.recording.gyro_axes == ("gyro_z",)


def test_truth_dict_names_every_parameter():
    sim = simulate("adxrs450", profile="cycle", duration_s=600, rate_hz=2, seed=7)
    d = sim.truth.to_dict()
    assert d["preset"] == "adxrs450" and d["seed"] == 7 and d["samples"] == 1201
    assert list(d["error_model"]["hysteresis"]["band_degc"]) == [55.0, 80.0]
    assert list(d["profile"]["set_points_degc"]) == [-30.0, 80.0]
    assert set(d["deterministic_error_range_dps"]) == {
        "temperature",
        "hysteresis",
        "acceleration",
        "scale_misalignment",
        "temperature_rate",
    }


def test_parameter_errors():
    with pytest.raises(InputError, match="temperature_coefficients: 1 sets for 3 axes"):
        GyroErrorModel(temperature_coefficients=((1.0,),))
    with pytest.raises(InputError, match="noise_density_dps_per_sqrt_hz: must not be negative"):
        GyroErrorModel(noise_density_dps_per_sqrt_hz=-1)
    with pytest.raises(InputError, match=r"g_sensitivity_dps_per_g: shape \(2, 3\), expected \(3, 3\)"):
        GyroErrorModel(g_sensitivity_dps_per_g=((0, 0, 0), (0, 0, 0)))
    with pytest.raises(InputError, match=r"hysteresis band_degc: \(80, 55\); give \(low, high\) with low < high"):
        Hysteresis(((1.0,),), band_degc=(80, 55))
    with pytest.raises(InputError, match="rate_hz: must be positive, got 0"):
        simulate(rate_hz=0)
    with pytest.raises(InputError, match="preset: unknown preset 'bmi'"):
        simulate("bmi")


def test_terms_switch_off_one_by_one():
    base = preset_model("mti10")
    quiet = base.without("noise", "quantization", "temperature-noise", "turn-on")
    sim = simulate(quiet.without("hysteresis", "g-sensitivity"), profile="cycle", duration_s=4000, rate_hz=1)
    t = sim.truth
    assert not np.any(t.components_dps["hysteresis"]) and not np.any(t.components_dps["acceleration"])
    np.testing.assert_allclose(sim.recording.gyro_dps, t.components_dps["temperature"], atol=1e-15)
    no_lag = simulate(quiet.without("lag"), profile="cycle", duration_s=4000, rate_hz=1)
    np.testing.assert_array_equal(no_lag.truth.structure_temperature_degc, no_lag.truth.reported_temperature_degc)
    flat = simulate(
        quiet.without("temperature", "hysteresis", "g-sensitivity"), profile="cycle", duration_s=4000, rate_hz=1
    )
    assert not np.any(flat.recording.gyro_dps)
    with pytest.raises(InputError, match="disable: unknown term 'wind'; use any of temperature, lag"):
        base.without("wind")


def test_a_simulation_larger_than_memory_is_refused_up_front():
    """1e9 s at 100 Hz (1e11 samples) would end in a MemoryError after minutes; it is refused at once, naming
    the two settings (the command line's exit 2)."""
    with pytest.raises(
        InputError,
        match=r"duration_s: 1e\+09 s at rate_hz=100 is 1e\+11 samples, about .* GB to "
        r"simulate, more than this machine's .* GB; shorten duration_s= or lower",
    ):
        simulate("mti10", duration_s=1e9, rate_hz=100.0)
