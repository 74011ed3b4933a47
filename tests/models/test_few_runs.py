"""One or two chamber cycles (issue: a default that never harms, the thesis's hysteresis found by itself):
simulate-then-recover with the default call a user makes, judged on data the fit has not seen."""

import dataclasses
import warnings

import numpy as np
import pytest

from gyrocomp import Calibration, apply
from gyrocomp.errors import ModelChoiceWarning
from gyrocomp.calibration.fit_report import SelectionReport
from gyrocomp.measures.merit import smoothed_residual_rms
from gyrocomp.models.joint import fit_calibration
from gyrocomp.models.fit import fit_channels
from gyrocomp.simulation import GyroErrorModel, Hysteresis, get_profile, preset_model, simulate
from gyrocomp.evaluation.validation import fit_plain_cubic

RATE_HZ = 20.0


def _adxrs450_case(model):
    """The thesis's ADXRS450 protocol: two heat-cool runs over -30..85 and -20..80 degC (20 Hz), judged on a third
    over -25..85 degC; (calibration, default/perfect drift ratio on the third run)."""
    fit = [
        simulate(model, profile=get_profile("cycle", set_points_degc=sp, cycles=1), rate_hz=RATE_HZ, seed=s).recording
        for s, sp in ((0, (-30.0, 85.0)), (1, (-20.0, 80.0)))
    ]
    held = simulate(
        model, profile=get_profile("cycle", set_points_degc=(-25.0, 85.0), cycles=1), rate_hz=RATE_HZ, seed=7
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_channels(fit)
        comp = apply(cal, held.recording).gyro_dps[:, 0]
    w = int(60 * RATE_HZ)
    ratio = smoothed_residual_rms(comp - held.truth.true_rate_dps[:, 0], w) / smoothed_residual_rms(
        held.truth.noise.total_dps[:, 0], w
    )
    return cal, ratio


@pytest.mark.slow
@pytest.mark.parametrize("shape", ["preset", "bump"])
def test_two_runs_find_the_hysteresis_and_the_lag_by_themselves(shape):
    model = preset_model("adxrs450")  # 60 s lag; hysteresis on cooling, 55..80 degC
    if shape == "bump":  # another shape: starts at the turning point, fades out over 25 degC
        model = dataclasses.replace(model, hysteresis=Hysteresis(((0.2,),), direction="descending", fade_degc=25.0))
    cal, ratio = _adxrs450_case(model)
    ax = cal.axes["gyro_z"]
    assert ratio <= 1.35
    assert ax.lag_time_constant_s == pytest.approx(60.0, rel=0.2)
    assert ax.hysteresis is not None and ax.hysteresis.band_degc is not None
    # lag and hysteresis recovered together (on main the lag ran away to several minutes when forced)
    lo, hi = ax.hysteresis.band_degc
    d = np.linspace(0.0, 20.0, 41)  # below the 80 degC turn of the first run, inside the band
    fitted = sum(h * d ** (j + 1) for j, h in enumerate(ax.hysteresis.descending))
    if shape == "preset":
        assert lo == pytest.approx(55.0, abs=1.5) and hi == pytest.approx(80.0, abs=1.5)
        np.testing.assert_allclose(fitted, 0.032 * d - 0.00128 * d**2, atol=0.015)
    else:  # the bump (peak 0.1 deg/s), inside the band, after the first run's turn at 85 degC
        inside = (85.0 - d >= lo) & (85.0 - d <= hi)
        assert hi > 80.0 and lo < 70.0 and np.count_nonzero(inside) > 20
        np.testing.assert_allclose(fitted[inside], model.hysteresis.offset_dps(d, (0.2,))[inside], atol=0.03)
    selection = cal.report.selection["gyro_z"]
    assert selection.fold_kind == "legs" and len(selection.folds) == 4
    # every memory the data can identify was scored, the turning-point terms in the band among them
    scored = {r.candidate.memory for r in selection.candidates}
    assert {"none", "lag", "turning-point", "turning-point+lag"} <= scored


def _fit_one_cycle(model, seed):
    """One chamber run cooled, heated, cooled (2 degC/min, 2 Hz), fitted up to its hottest point: (the simulation,
    the index of its hottest sample, the default calibration, the fit's warnings)."""
    prof = get_profile("chamber", set_points_degc=(40.0, -20.0, 70.0, 30.0), ramp_rate_degc_per_min=2.0, dwell_s=300.0)
    sim = simulate(model, profile=prof, rate_hz=2.0, seed=seed)
    k = int(np.argmax(sim.recording.temperature_degc))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cal = fit_calibration([sim.recording.take(np.arange(k))])
    return sim, k, cal, [str(w.message) for w in caught]


def _one_cycle(model, seed):
    """The drift of the raw and the default's output on the cooling leg after the hottest point of
    :func:`_fit_one_cycle`'s run (the model applied to that leg alone) [deg/s], and the fit's warnings."""
    sim, k, cal, messages = _fit_one_cycle(model, seed)
    rec = sim.recording
    test = rec.take(np.arange(k, rec.n_samples))
    truth = sim.truth.true_rate_dps[k:, 0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = apply(cal, test).gyro_dps[:, 0]
    return (smoothed_residual_rms(test.gyro_dps[:, 0] - truth, 120), smoothed_residual_rms(out - truth, 120), messages)


@pytest.mark.parametrize("seed", range(6))
def test_a_random_walk_unrelated_to_temperature_is_left_alone(seed):
    # measured on main before this change: a curve fitted to the walk left the next leg 1.2-1.4x worse than raw
    walk = GyroErrorModel(
        axes=("gyro_x",),
        temperature_coefficients=((0.0,),),
        rate_random_walk_dps_per_sqrt_s=2e-3,
        noise_density_dps_per_sqrt_hz=0.005,
    )
    raw, default, messages = _one_cycle(walk, seed)
    assert default <= 1.05 * raw
    # the held-out legs (or the order test) find no temperature effect: the constant, and no test adds branch
    # terms to an axis the held-out legs left without a curve
    assert any(m.startswith("gyro_x: left with its constant only; do no harm") for m in messages), messages
    assert not any("branch terms added" in m for m in messages)
    assert any(
        "only 2 heating and cooling legs to hold out; the evidence for each axis's choice is thin" in m
        for m in messages
    )


@pytest.mark.slow
def test_no_memory_terms_for_a_drifting_part_whose_heating_and_cooling_curves_are_one():
    """Done-when of the real-logs issue: 20 seeds of one-cycle runs of the ``drifting`` preset (flicker, the
    non-repeatable drift and warm-up of the real one-cycle log, at its levels; heating and cooling follow one
    curve): branch or turning-point terms on at most 5 % of the axes. Measured: 0 of 60 (on main before: 11 of 60,
    the branch test's drift estimated from the residual of a model whose branch terms had absorbed it)."""
    added = []
    for seed in range(20):
        _, _, cal, _ = _fit_one_cycle(preset_model("drifting"), seed)
        added += [
            (seed, axis, s.chosen.label)
            for axis, s in cal.report.selection.items()
            if s.chosen.branch or s.chosen.hysteresis_order
        ]
    assert len(added) <= 3, added


def test_one_cycle_finds_heating_and_cooling_curves_that_differ(tmp_path):
    """Done-when (b): heating and cooling curves apart by far more than five times the noise's 60 s drift; one
    heating and one cooling leg cannot test a branch model on held-out legs, so a test against the drift decides:
    the default leaves at most half a cubic's drift on the cooling leg after the hottest point (the model applied
    to the whole run, which holds the turn there). Measured: 0.19-0.25x (on main before it: 1.0x, the branch
    terms were never tried with one cycle)."""
    part = GyroErrorModel(
        axes=("gyro_z",),
        temperature_coefficients=((0.01, 5e-5),),
        t_ref_degc=25.0,
        hysteresis=Hysteresis(((0.03, 0.0008),), transition_degc=5.0),
        noise_density_dps_per_sqrt_hz=0.005,
        bias_instability_deg_per_h=10.0,
    )
    prof = get_profile("chamber", set_points_degc=(40.0, -20.0, 70.0, 30.0), ramp_rate_degc_per_min=2.0, dwell_s=300.0)
    sim = simulate(part, profile=prof, rate_hz=2.0, seed=1)
    rec = sim.recording
    k = int(np.argmax(rec.temperature_degc))
    with pytest.warns(
        ModelChoiceWarning,
        match=r"gyro_z: one heating and one cooling leg cannot test a branch model"
        r".*curves differ beyond the drift .*branch terms added",
    ):
        cal = fit_calibration([rec.take(np.arange(k))])
    cubic = fit_plain_cubic([rec.take(np.arange(k))])
    truth = sim.truth.true_rate_dps[k:, 0]
    drift = {
        name: smoothed_residual_rms(apply(c, rec).gyro_dps[k:, 0] - truth, 120)
        for name, c in (("default", cal), ("cubic", cubic))
    }
    assert drift["default"] <= 0.5 * drift["cubic"]
    test = cal.report.selection["gyro_z"].branch_test
    assert test.order >= 1 and test.statistic > test.threshold
    # the test and its verdict travel with the model file
    cal.save(tmp_path / "m.json")
    assert Calibration.load(tmp_path / "m.json").report.selection["gyro_z"].branch_test == test


def test_one_cycle_of_a_part_with_a_real_tempco_is_compensated():
    raw, default, _ = _one_cycle(preset_model("consumer"), 0)
    assert default < 0.1 * raw


def test_folds_that_cannot_be_had_are_said():
    heating = simulate("consumer", profile="chamber", duration_s=3000, rate_hz=1, seed=1).recording
    with pytest.warns(
        ModelChoiceWarning,
        match=r"the temperature never reverses, so there are no heating and "
        r"cooling legs to hold out; held out 4 contiguous time blocks",
    ):
        cal = fit_calibration([heating])
    assert cal.report.selection["gyro_x"].fold_kind == "blocks"
    cycle = simulate("consumer", profile="cycle", duration_s=6000, rate_hz=1, seed=1).recording
    with pytest.warns(
        ModelChoiceWarning,
        match=r"folds='runs': one run cannot be held out against others; held "
        r"out each heating and cooling leg",
    ):
        cal = fit_calibration([cycle], folds="runs")
    assert cal.report.selection["gyro_x"].fold_kind == "legs"


def test_the_expected_held_out_drift_is_stored_and_read_back(tmp_path):
    run = simulate("consumer", profile="cycle", duration_s=6000, rate_hz=1, seed=2).recording
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration([run])
    cal.save(tmp_path / "m.json")
    selection = Calibration.load(tmp_path / "m.json").report.selection
    for sel in selection.values():
        assert isinstance(sel, SelectionReport)
        chosen = sel.result(sel.chosen.label)
        assert sel.chosen_drift_dps == pytest.approx(chosen.mean_drift)
        assert sel.chosen_standard_error == pytest.approx(chosen.standard_error)


def _next_leg_per_axis(model, seed):
    """The one-cycle protocol on every axis: (calibration, default / perfect drift per axis on the cooling leg after
    the hottest point of :func:`_fit_one_cycle`'s run, the fit's warnings); the model is applied to the whole run,
    as a memory model needs."""
    sim, k, cal, messages = _fit_one_cycle(model, seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = apply(cal, sim.recording).gyro_dps[k:]
    ratios = [
        smoothed_residual_rms(out[:, j] - sim.truth.true_rate_dps[k:, j], 120)
        / smoothed_residual_rms(sim.truth.noise.total_dps[k:, j], 120)
        for j in range(out.shape[1])
    ]
    return cal, np.array(ratios), messages


@pytest.mark.slow
@pytest.mark.parametrize("seed", [4, 8])
def test_one_cycle_gives_every_axis_the_dies_lag(seed, tmp_path):
    """The consumer part (30 s lag, tempcos of 0.025-0.035 deg/s/degC), one cycle at 2 degC/min: held-out legs
    cannot tell an axis's curve with the lag from the same without (each leg's mean is removed, and on a steady
    ramp a lag is a constant), so an axis whose sister axes found the die's lag takes it too. Measured on main
    before: gyro_x left without it drifted 4.2x (seed 4) and 5.3x (seed 8) the noise on the next leg, gyro_y
    3.7x (seed 8, where the lag's offset between the legs was taken for branch terms); with it at most 1.3x."""
    cal, ratios, messages = _next_leg_per_axis(preset_model("consumer"), seed)
    lags = {axis: cal.axes[axis].lag_time_constant_s for axis in cal.axes}
    assert len(set(lags.values())) == 1 and next(iter(lags.values())) == pytest.approx(30.0, rel=0.25), lags
    assert np.all(ratios <= 1.6), ratios
    kept = [m for m in messages if "the die's lag is kept" in m]
    assert all(m.startswith(("gyro_x", "gyro_y", "gyro_z")) for m in kept)
    selection = cal.report.selection
    if (
        seed == 8
    ):  # an axis whose legs cannot see the lag takes the die's (on seed 4 gyro_x now finds it beside a rate term)
        assert kept and any(s.lag_from_unit for s in selection.values())
    assert all(s.lag_from_unit == any(m.startswith(a + ":") for m in kept) for a, s in selection.items())
    cal.save(tmp_path / "m.json")  # the model file says which axes took the die's lag
    back = Calibration.load(tmp_path / "m.json").report.selection
    assert {a: s.lag_from_unit for a, s in back.items()} == {a: s.lag_from_unit for a, s in selection.items()}


@pytest.mark.slow
def test_a_lag_as_long_as_the_runs_is_not_taken_for_a_die():
    """Two heat-cool runs of an ADIS16488-class part (true lag 300 s; its drift, not its tempco, dominates gyro_x),
    judged on a third: on main before, gyro_x's held-out legs put its lag at the longest run (11,100 s), the
    lagged temperature stood for the runs' drift, poly:5 on it beat the constant on the legs, and the third run
    drifted 2.7x raw. Lags beyond half the longest run are not searched, and a candidate whose lag some fold puts
    at the top of the search is not chosen."""
    model = preset_model("adis16488")
    fit = [
        simulate(model, profile=get_profile("cycle", set_points_degc=sp, cycles=1), rate_hz=2.0, seed=300 + i).recording
        for i, sp in enumerate([(-20.0, 50.0), (-10.0, 40.0)])
    ]
    held = simulate(model, profile=get_profile("cycle", set_points_degc=(-15.0, 55.0), cycles=1), rate_hz=2.0, seed=399)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_channels(fit)
        out = apply(cal, held.recording).gyro_dps
    longest_s = max(float(r.time_s[-1] - r.time_s[0]) for r in fit)
    truth = held.truth.true_rate_dps
    for j, axis in enumerate(held.recording.gyro_axes):
        assert cal.axes[axis].lag_time_constant_s <= longest_s / 2, axis
        assert max(max(r.fold_lag_s) for r in cal.report.selection[axis].candidates) <= longest_s / 2, axis
        raw = smoothed_residual_rms(held.recording.gyro_dps[:, j] - truth[:, j], 120)
        left = smoothed_residual_rms(out[:, j] - truth[:, j], 120)
        assert left <= 1.05 * raw, axis


@pytest.mark.slow
def test_a_random_walk_over_three_runs_is_not_followed_through_a_long_lag():
    """A slow random walk unrelated to temperature, three runs of 3.1-3.75 h held out in turn: on main before, poly:4
    with branch terms through a 4,600-7,900 s lag beat the constant on the three held-out runs by chance, and
    the fourth run drifted 2.1x raw. Measured now: the constant, 1.0x raw."""
    walk = GyroErrorModel(
        axes=("gyro_x",),
        temperature_coefficients=((0.0,),),
        rate_random_walk_dps_per_sqrt_s=2e-3,
        noise_density_dps_per_sqrt_hz=0.005,
    )
    fit = [
        simulate(walk, profile=get_profile("cycle", set_points_degc=r, cycles=1), rate_hz=2.0, seed=900 + i).recording
        for i, r in enumerate([(-20.0, 70.0), (-10.0, 60.0), (-15.0, 70.0)])
    ]
    held = simulate(walk, profile=get_profile("cycle", set_points_degc=(-15.0, 75.0), cycles=1), rate_hz=2.0, seed=999)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_channels(fit)
        out = apply(cal, held.recording).gyro_dps[:, 0]
    truth = held.truth.true_rate_dps[:, 0]
    raw = smoothed_residual_rms(held.recording.gyro_dps[:, 0] - truth, 120)
    assert smoothed_residual_rms(out - truth, 120) <= 1.05 * raw
    assert cal.axes["gyro_x"].lag_time_constant_s <= max(float(r.time_s[-1] - r.time_s[0]) for r in fit) / 2


#: a triad behind a 40 s thermal lag whose z axis heats and cools along curves 0.03 deg/s (+ 0.0008 deg/s/degC) apart
BRANCHES_AND_LAG = GyroErrorModel(
    axes=("gyro_x", "gyro_y", "gyro_z"),
    temperature_coefficients=((0.004, 2e-5), (-0.003, 1e-5), (0.01, 5e-5)),
    t_ref_degc=25.0,
    thermal_time_constant_s=40.0,
    hysteresis=Hysteresis(((0.0, 0.0), (0.0, 0.0), (0.03, 0.0008)), transition_degc=5.0),
    noise_density_dps_per_sqrt_hz=0.005,
    bias_instability_deg_per_h=10.0,
    turn_on_bias_sigma_dps=0.05,
)


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1])
def test_a_fast_single_cycle_finds_the_branches_behind_the_dies_lag(seed):
    """A single cycle shaped like the issue's real one (52 -> -18 -> 74 -> 36 degC at 3.5 degC/min, 2 Hz), fitted up
    to its hottest point, judged on the cooling leg after it. Its heating leg follows a turn, so turning-point
    terms are offered, but no held-out leg can judge them (each fold trains on one direction of travel): they are
    scored as their polynomial there, and the branch test decides. Measured on main before: turning-point terms
    chosen on gyro_z, 8.4-12.7x perfect (a cubic 8.2-12.8x); now branch terms beyond the die's lag, 1.6-3.9x over
    six seeds."""
    prof = get_profile("chamber", set_points_degc=(52.0, -18.0, 74.0, 36.0), ramp_rate_degc_per_min=3.5, dwell_s=120.0)
    sim = simulate(BRANCHES_AND_LAG, profile=prof, rate_hz=2.0, seed=seed)
    rec = sim.recording
    k = int(np.argmax(rec.temperature_degc))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration([rec.take(np.arange(k))])
        cubic = fit_plain_cubic([rec.take(np.arange(k))])
        out = {name: apply(c, rec).gyro_dps[k:, 2] for name, c in (("default", cal), ("cubic", cubic))}
    truth = sim.truth.true_rate_dps[k:, 2]
    drift = {name: smoothed_residual_rms(v - truth, 120) for name, v in out.items()}
    assert drift["default"] <= 0.5 * drift["cubic"]
    selection = cal.report.selection["gyro_z"]
    assert selection.chosen.branch and selection.chosen.lag and not selection.chosen.hysteresis_order
    assert selection.branch_test.statistic > selection.branch_test.threshold
    assert cal.axes["gyro_z"].lag_time_constant_s == pytest.approx(40.0, rel=0.25)
    # the turning-point candidates were scored, each as its polynomial on every fold
    scores = {r.candidate: r.fold_drift for r in selection.candidates}
    turning = [c for c in scores if c.hysteresis_order]
    assert turning
    for c in turning:
        plain = dataclasses.replace(c, hysteresis_order=0, band=False)
        assert scores[c] == pytest.approx(scores[plain], rel=1e-12), c.label


@pytest.mark.slow
def test_an_axis_takes_the_dies_lag_only_where_its_own_data_see_it():
    """The consumer part without any thermal lag, one cycle (seed 0): gyro_x's folds choose a lag by chance; the die's
    lag fitted on all three axes (6.1 s) is no better than the bottom of the search on gyro_y's and gyro_z's own
    runs (chi-square 1.3 and -6.5, against 4), so they keep their own choice, without lag. Measured with the lag
    kept: gyro_z 2.2x perfect on the next leg; without it 1.1x."""
    model = dataclasses.replace(preset_model("consumer"), thermal_time_constant_s=0.0)
    cal, ratios, messages = _next_leg_per_axis(model, 0)
    assert cal.axes["gyro_y"].lag_time_constant_s == 0.0 and cal.axes["gyro_z"].lag_time_constant_s == 0.0
    assert not any(sel.lag_from_unit for sel in cal.report.selection.values())
    assert not any("the die's lag is kept" in m for m in messages)
    assert ratios[2] <= 1.3
