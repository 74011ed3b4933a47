"""Model choice by held-out drift (gyrocomp.fitting.selection): the rule, the folds, the quantization detector,
the tangent extension past the fitted range, and simulate-then-recover on single chamber cycles."""

import dataclasses
import json
import warnings

import numpy as np
import pytest

from gyrocomp import Polynomial, apply, fit_calibration
from gyrocomp.errors import InputError, ModelChoiceWarning
from gyrocomp.measures.merit import smoothed_residual_rms
from gyrocomp.fitting.folds import leg_labels
from gyrocomp.fitting.scores import CandidateScore
from gyrocomp.fitting.choice import unidentified_lags
from gyrocomp.fitting.selection import Candidate, prepare_axis, temperature_step_degc
from gyrocomp.fitting.grid_search import LAG_MAX_S, lag_search_top_s
from gyrocomp.models.options import curve_candidates
from gyrocomp.curves.polynomial import PolynomialCurve
from gyrocomp.recording import Recording
from gyrocomp.simulation import get_profile, preset_model, simulate
from gyrocomp.simulation.profiles import Profile
from gyrocomp.evaluation.validation import fit_plain_cubic, make_sample_folds


def test_candidate_complexity_and_labels():
    c = Candidate(3, lag=True, hysteresis_order=2, weighting="temperature-balanced")
    assert c.complexity == 3 + 1 + 4 and c.memory == "turning-point+lag"
    assert c.label == "poly:3 + lag + turning-point:2 (temperature-balanced)"
    assert not Candidate(0).has_temperature_model and Candidate(0).label == "constant (time)"


@pytest.mark.parametrize("step", [1.0, 0.5])
def test_quantized_temperature_is_detected(step):
    rng = np.random.default_rng(1)
    t = 20 + 10 * np.sin(np.linspace(0, 3, 5000)) + 0.2 * rng.standard_normal(5000)
    assert temperature_step_degc(np.round(t / step) * step) == step
    assert temperature_step_degc(np.round(t, 2)) == 0.0  # a fine register is not coarse
    assert temperature_step_degc(np.full(10, 25.0)) == 0.0


def test_legs_split_at_confirmed_reversals():
    t = np.concatenate([np.linspace(25, -20, 400), np.linspace(-20, 70, 800), np.linspace(70, -20, 800)])
    labels, directions = leg_labels(t, 0.5, 10)
    assert directions == [-1, 1, -1]
    # the splits lie just past the extremes (a reversal is confirmed 0.5 degC after it)
    assert np.all(np.diff(labels) >= 0) and abs(np.flatnonzero(np.diff(labels))[0] - 400) < 10


def test_folds_runs_legs_and_blocks():
    cycle = simulate("adxrs450", profile="cycle", duration_s=4000, rate_hz=1, seed=1).recording
    kind, folds = make_sample_folds([cycle])
    assert kind == "legs" and len(folds) >= 3
    directions = [f.name.split("(")[-1].rstrip(")") for f in folds]
    assert all(a != b for a, b in zip(directions, directions[1:]))  # heating and cooling alternate
    assert sum(f.rows.size for f in folds) == cycle.n_samples
    ramp = simulate("adxrs450", profile="chamber", duration_s=3000, rate_hz=1, seed=2).recording
    kind, folds = make_sample_folds([ramp])  # no reversal: contiguous blocks
    assert kind == "blocks" and len(folds) == 4
    kind, folds = make_sample_folds([ramp, ramp, ramp])
    assert kind == "runs" and [f.name for f in folds] == ["run 1", "run 2", "run 3"]


def _ramp(n, rate_hz=10.0):
    t = np.arange(n) / rate_hz
    temp = np.linspace(10, 40, n)
    return Recording(time_s=t, gyro_dps=1e-3 * temp, gyro_axes=("gyro_z",), temperature_degc=temp)


def test_an_order_asked_for_is_fitted_even_where_the_constant_scores_as_well():
    # a 60-s ramp: every held-out block is shorter than the smallest window, and the noise-free line scores 0
    cal = fit_calibration([_ramp(600)], temperature=Polynomial(1))
    assert cal.axes["gyro_z"].temperature.order == 1
    assert cal.fit_report["selection"]["gyro_z"]["chosen"]["order"] == 1


def test_too_little_data_to_hold_out_warns_and_writes_no_nan():
    with pytest.warns(ModelChoiceWarning, match="gyro_z: too little data to hold out time blocks; poly:1 "):
        cal = fit_calibration([_ramp(3)], temperature=Polynomial(1))
    sel = cal.fit_report["selection"]["gyro_z"]
    assert sel["validated"] is False and sel["raw_drift_dps"] is None
    json.dumps(cal.fit_report, allow_nan=False)  # a model file a strict reader accepts


def test_turning_point_asked_for_on_a_monotone_run_is_refused():
    with pytest.raises(InputError, match="hysteresis='turning-point': the temperature of gyro_z never reverses"):
        fit_calibration([_ramp(6000)], hysteresis="turning-point")


def test_tangent_extension_past_the_range():
    curve = PolynomialCurve((0.1, -0.05, 0.02), 20.0, 10.0, 10.0, 30.0, extrapolation="linear")
    t = np.array([40.0, 5.0])
    # analytic: at the edge u=1 the value is 0.07 and the slope d/du is 0.1 - 0.1 + 0.06 = 0.06 per u
    expected_hi = 0.07 + 0.06 * (40 - 30) / 10
    lo_u = -1.0
    value_lo = 0.1 * lo_u - 0.05 * lo_u**2 + 0.02 * lo_u**3
    slope_lo = 0.1 - 0.1 * lo_u + 0.06 * lo_u**2
    np.testing.assert_allclose(curve.shape(t), [expected_hi, value_lo + slope_lo * (5 - 10) / 10], rtol=1e-12)
    held = PolynomialCurve((0.1, -0.05, 0.02), 20.0, 10.0, 10.0, 30.0)
    np.testing.assert_allclose(held.shape(t), [0.07, value_lo], rtol=1e-12)
    assert "extrapolation" not in held.to_dict() and PolynomialCurve.from_dict(curve.to_dict()) == curve
    with pytest.raises(ValueError, match="extrapolation: 'cubic'; use one of hold, linear"):
        PolynomialCurve((0.1,), 20.0, 10.0, 10.0, 30.0, extrapolation="cubic")


def _single_cycle(seed):
    """One chamber run cooled, heated, cooled again (the way PX4 and most vendors calibrate), 2 Hz."""
    prof = get_profile("chamber", set_points_degc=(25.0, -20.0, 70.0, -20.0), ramp_rate_degc_per_min=1.0, dwell_s=600.0)
    return simulate("adxrs450", profile=prof, rate_hz=2.0, seed=seed)


@pytest.mark.parametrize("seed", [3, 4])
def test_single_chamber_cycle_fit_to_the_hottest_point_holds_on_the_last_cooling_leg(seed):
    sim = _single_cycle(seed)
    rec = sim.recording
    hottest = int(np.argmax(rec.temperature_degc))
    # the last cooling leg starts where the temperature leaves the hot dwell
    leaves = hottest + int(np.argmax(rec.temperature_degc[hottest:] < rec.temperature_degc[hottest] - 1.0))
    train = rec.take(slice(0, hottest + 1))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        default = fit_calibration([train])
        cubic = fit_plain_cubic([train])
        comp = {name: apply(cal, rec).gyro_dps[leaves:] for name, cal in (("default", default), ("cubic", cubic))}
    # two legs (cooling, heating): each is held out (never silently time blocks), and the evidence is said thin
    assert default.fit_report["selection"]["gyro_z"]["fold_kind"] == "legs"
    w = 600 * 2
    truth = sim.truth.true_rate_dps[leaves:]
    drift = {k: smoothed_residual_rms(v[:, 0] - truth[:, 0], w) for k, v in comp.items()}
    raw = smoothed_residual_rms(rec.gyro_dps[leaves:, 0] - truth[:, 0], w)
    assert drift["default"] <= drift["cubic"]
    assert drift["default"] < raw


SIX_POSITIONS_G = ((1.0, 0, 0), (-1.0, 0, 0), (0, 1.0, 0), (0, -1.0, 0), (0, 0, 1.0), (0, 0, -1.0))


def _consumer_runs(seed):
    """The issue's consumer-class part (whole-degree register, 20 s lag, ~0.1 deg/s/g): a warm-up, a
    ramp-and-hold and a heat-cool cycle of 40-60 min, six orientations each, and a held-out cycle with a
    different range and rate."""
    model = dataclasses.replace(preset_model("consumer"), thermal_time_constant_s=20.0)
    kw = dict(positions_g=SIX_POSITIONS_G, position_s=300.0, move_s=10.0)
    profiles = [
        Profile(
            "warmup",
            set_points_degc=(20.0,),
            warmup_rise_degc=25.0,
            warmup_time_constant_s=600.0,
            duration_s=2400.0,
            **kw,
        ),
        Profile("chamber", set_points_degc=(10.0, 50.0), ramp_rate_degc_per_min=2.0, dwell_s=600.0, **kw),
        Profile("cycle", set_points_degc=(10.0, 50.0), ramp_rate_degc_per_min=2.0, dwell_s=300.0, **kw),
    ]
    held = Profile("cycle", set_points_degc=(15.0, 45.0), ramp_rate_degc_per_min=1.5, dwell_s=200.0, **kw)
    runs = [simulate(model, profile=p, rate_hz=10.0, seed=10 * seed + k).recording for k, p in enumerate(profiles)]
    return runs, simulate(model, profile=held, rate_hz=10.0, seed=10 * seed + 9)


@pytest.mark.parametrize("seed", [0, 1])
def test_consumer_part_held_out_within_1_3x_of_perfect_compensation(seed):
    runs, held = _consumer_runs(seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit_calibration(runs)
        comp = apply(cal, held.recording).gyro_dps
    w = 60 * 10
    for j, axis in enumerate(held.recording.gyro_axes):
        # perfect compensation leaves the sensor's own noise; its drift is the yardstick
        perfect = smoothed_residual_rms(held.truth.noise.total_dps[:, j], w)
        left = smoothed_residual_rms(comp[:, j] - held.truth.true_rate_dps[:, j], w)
        assert left <= 1.3 * perfect, axis
        # one die behind one temperature register: the die's lag near the truth, or a rate term that makes the lag's
        # offset on a ramp, -f'(T) tau dT/dt (f' the axis's tempco at mid-range; the part's curve is nearly
        # straight, so the two are one on every ramp)
        ax = cal.axes[axis]
        if ax.rate_term is None or ax.lag_time_constant_s:
            assert ax.lag_time_constant_s == pytest.approx(20.0, rel=0.25)
        else:
            c1, c2 = preset_model("consumer").temperature_coefficients[j]
            slope = c1 + 2.0 * c2 * (30.0 - 25.0)  # [deg/s per degC] at 30 degC, the runs' middle
            assert ax.rate_term.coefficient_per_degc_per_s == pytest.approx(-slope * 20.0, rel=0.25)


@pytest.mark.parametrize("accel", [False, True])
def test_lag_residuals_from_the_shape_columns_equal_those_of_the_full_normal_matrices(accel):
    """lag_rss reads the poly + lag residuals from the normal matrices of the polynomial (and accelerometer)
    columns alone; they equal the same candidates' residuals in the matrices with every hysteresis and branch
    column, at every lag of the grid and for every fold."""
    model = preset_model("adxrs450")
    runs = [
        simulate(model, profile=get_profile("cycle", set_points_degc=sp, cycles=1), rate_hz=2.0, seed=s).recording
        for s, sp in ((0, (-30.0, 85.0)), (1, (-20.0, 80.0)), (2, (-25.0, 85.0)))
    ]
    problem = prepare_axis(
        runs,
        "gyro_z",
        groups=(0, 1, 2),
        max_order=3,
        hysteresis_orders=(1, 2),
        branch_orders=(1, 2),
        other_curves=curve_candidates(Polynomial()).others,
    )
    assert problem.columns(0, problem.runs[0].temperature_degc).shape[1] > 3 + 2 * 2  # hysteresis, branch columns
    if accel:  # the triad as if the part had been turned between blocks (at rest it would add nothing)
        rng = np.random.default_rng(3)
        problem.runs = [dataclasses.replace(r, accel_g=rng.normal(0.0, 0.6, (r.value.size, 3))) for r in problem.runs]
        problem.accel_cols, problem.square_cols = (0, 2), (1,)
    grid = problem.lag_grid_s()
    for order in (1, 3):
        got = problem.lag_rss(order, "time", grid)
        idx = problem.column_index(Candidate(order, True, 0, "time"))
        full = np.array(
            [
                [problem.solve(problem.training_matrices(float(tau), "time")[0][f], idx)[1] for tau in grid]
                for f in range(problem.folds.count)
            ]
        )
        np.testing.assert_allclose(got, full / full.min(axis=1, keepdims=True), rtol=1e-9)


def test_a_lag_some_fold_puts_at_the_top_of_the_search_is_not_identified():
    top_s = 5400.0
    at_top = CandidateScore(Candidate(2, True), (1.0, 1.0), (30.0, top_s))
    inside = CandidateScore(Candidate(3, True), (1.0, 1.0), (30.0, 0.6 * top_s))
    no_lag = CandidateScore(Candidate(2), (1.0, 1.0), (0.0, 0.0))
    assert unidentified_lags([at_top, inside, no_lag], top_s) == {Candidate(2, True)}


def test_the_lag_search_stops_at_half_the_longest_run_on_the_grid_it_had():
    """The fold lags are the points of the grid from two blocks to the longest run (at most 4 h) that lie within
    half the longest run; the final fit searches up to the same half."""
    runs = [
        simulate(
            "consumer",
            profile=get_profile("cycle", set_points_degc=(-10.0, 40.0), cycles=1),
            rate_hz=1.0,
            duration_s=d,
            seed=1,
        ).recording
        for d in (3000.0, 7200.0)
    ]
    problem = prepare_axis(runs, "gyro_x")
    lo = 2.0 * problem.block_s
    longest = max(float(r.time_s[-1] - r.time_s[0]) for r in problem.runs)  # of the blocks' times
    assert longest == pytest.approx(7200.0, abs=5.0)
    full = np.geomspace(lo, longest, 16)
    grid = problem.lag_grid_s()
    np.testing.assert_allclose(grid, full[full <= longest / 2])
    assert lag_search_top_s(problem.runs, lo) == pytest.approx(longest / 2)
    assert (
        lag_search_top_s([dataclasses.replace(problem.runs[0], time_s=np.array([0.0, 3.0 * LAG_MAX_S]))], lo)
        == LAG_MAX_S
    )
    assert lag_search_top_s([dataclasses.replace(problem.runs[0], time_s=np.array([0.0, 1.0]))], lo) == 2 * lo
