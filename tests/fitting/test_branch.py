"""Heating and cooling branches (BranchCurve): the general form of the thesis's turning-point correction, a part
that follows one curve while heating and another while cooling; simulate-then-recover, chosen by the default
where held-out legs can judge it, streaming equal to batch, and the model file round trip."""

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp import Calibration, apply
from gyrocomp.effects import branch_position, find_turns
from gyrocomp.errors import InputError
from gyrocomp.measures.merit import smoothed_residual_rms
from gyrocomp.curves.hysteresis import BranchCurve, memory_curve_from_dict
from gyrocomp.models.fit import fit_channels
from gyrocomp.simulation import GyroErrorModel, Hysteresis, get_profile, simulate
from gyrocomp.evaluation.validation import fit_plain_cubic

from ..conftest import assert_streaming_equals_batch

RATE_HZ = 2.0
#: the half difference between the heating and the cooling curve: 0.03 deg/s at 25 degC, 0.0008 deg/s/degC more
#: per degree; the branches cross over within about 5 degC after each turn
PART = GyroErrorModel(
    axes=("gyro_z",),
    temperature_coefficients=((0.01, 5e-5),),
    t_ref_degc=25.0,
    hysteresis=Hysteresis(((0.03, 0.0008),), transition_degc=5.0),
    noise_density_dps_per_sqrt_hz=0.005,
    bias_instability_deg_per_h=10.0,
    turn_on_bias_sigma_dps=0.05,
)


def test_branch_position_crosses_over_after_each_turn():
    t = np.concatenate([np.linspace(20, 60, 401), np.linspace(60, 20, 401)[1:]])
    turns = find_turns(t, 0.1)
    s = branch_position(t, turns, 5.0)
    # heating before any turn: from midway (the history before the recording is unknown) towards +1, from where
    # the branch started (20 degC, the lowest temperature before it)
    first = (turns.direction == 1) & np.isnan(turns.turn_degc)
    np.testing.assert_allclose(s[first], 1 - np.exp(-(t[first] - 20.0) / 5.0))
    assert s[turns.direction == 0].size and np.all(s[turns.direction == 0] == 0.0)
    after = ~np.isnan(turns.turn_degc)
    d = np.abs(t - np.where(after, turns.turn_degc, t))
    np.testing.assert_allclose(s[after], -(1 - 2 * np.exp(-d[after] / 5.0)))  # from +1 at the turn towards -1
    assert s[-1] == pytest.approx(-1.0, abs=1e-3)


@pytest.fixture(scope="module")
def two_runs():
    """Two heat-cool runs (four legs) to fit on, a third to judge on."""
    fit = [
        simulate(PART, profile=get_profile("cycle", set_points_degc=sp, cycles=1), rate_hz=RATE_HZ, seed=s).recording
        for s, sp in ((0, (-20.0, 70.0)), (1, (-10.0, 60.0)))
    ]
    held = simulate(
        PART, profile=get_profile("cycle", set_points_degc=(-15.0, 65.0), cycles=1), rate_hz=RATE_HZ, seed=7
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit_channels(fit), fit_plain_cubic(fit), held


def test_the_default_finds_the_branches_and_they_hold_on_a_held_out_run(two_runs):
    cal, cubic, held = two_runs
    branch = cal.axes["gyro_z"].hysteresis
    assert isinstance(branch, BranchCurve) and cal.report.selection["gyro_z"].chosen.branch == 2
    # recovered: the half difference at 25 degC and its slope, and the crossover width
    assert branch.half_difference(np.array([25.0]))[0] == pytest.approx(0.03, abs=0.004)
    slope = (branch.half_difference(np.array([45.0])) - branch.half_difference(np.array([5.0])))[0] / 40.0
    assert slope == pytest.approx(0.0008, rel=0.15)
    assert 2.0 < branch.transition_degc < 12.0
    w = int(60 * RATE_HZ)

    def drift(c):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return smoothed_residual_rms(apply(c, held.recording).gyro_dps[:, 0] - held.truth.true_rate_dps[:, 0], w)

    perfect = smoothed_residual_rms(held.truth.noise.total_dps[:, 0], w)
    assert drift(cal) < 1.5 * perfect and drift(cal) < 0.5 * drift(cubic)


@settings(max_examples=20, deadline=None)
@given(st.lists(st.integers(min_value=1, max_value=4000), min_size=1, max_size=10))
def test_streaming_equals_batch(two_runs, cuts):
    cal, _, held = two_runs
    assert_streaming_equals_batch(cal, held.recording, cuts)


def test_model_file_round_trip_and_validation(two_runs, tmp_path):
    cal = two_runs[0]
    cal.save(tmp_path / "m.json")
    loaded = Calibration.load(tmp_path / "m.json")
    assert loaded.axes == cal.axes
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        np.testing.assert_array_equal(
            apply(loaded, two_runs[2].recording).gyro_dps, apply(cal, two_runs[2].recording).gyro_dps
        )
    entry = cal.axes["gyro_z"].hysteresis.to_dict()
    with pytest.raises(InputError, match=r"a branch model needs t_scale_degc and transition_degc above 0"):
        memory_curve_from_dict({**entry, "transition_degc": 0.0})
    with pytest.raises(InputError, match=r"hysteresis: unknown model type 'spline'; use one of turning-point, branch"):
        memory_curve_from_dict({**entry, "type": "spline"})
