"""One chamber cycle from real parts: the real single-cycle log (../shared/datasets/tofupilot-imu-thermal) judged
by its own protocol, and the false positives of the memory terms on real still recordings with a temperature
effect whose heating and cooling curves are the same."""

import numpy as np
import pytest

from ..conftest import shared_dataset
from .real_data import still_one_cycle_trials, tofupilot_one_cycle, tofupilot_run

pytestmark = [pytest.mark.real]


@pytest.fixture(scope="module")
def one_cycle():
    shared_dataset("tofupilot-imu-thermal")
    return tofupilot_one_cycle()


def test_the_log_is_read_as_documented():
    shared_dataset("tofupilot-imu-thermal")
    run = tofupilot_run()
    assert run.n_samples == 8400 and run.duration_s == pytest.approx(70.7 * 60, rel=0.01)
    assert run.temperature_degc.min() == pytest.approx(-17.6, abs=0.1)
    assert run.temperature_degc.max() == pytest.approx(74.0, abs=0.1)
    hot = int(np.argmax(run.temperature_degc))
    assert hot == 6194 or hot == 6193  # the README: heating to row 6194


def test_the_default_beats_the_cubic_and_leaves_no_axis_worse_than_raw(one_cycle):
    """Done-when of the real-logs issue: the mean over axes of the std over the final cooling leg at most 0.75x the
    plain cubic's, no axis above 1.05x raw. Measured: default x 0.106 (raw 0.106), y 0.039, z 0.079 deg/s, mean
    0.62x the cubic's (the cubic: 0.226, 0.040, 0.096; on main before: 0.177, 0.109, 0.123, mean 1.13x)."""
    default, cubic, raw = one_cycle["gyrocomp default"], one_cycle["plain cubic"], one_cycle["raw"]
    assert default.mean() <= 0.75 * cubic.mean(), (default, cubic)
    assert np.all(default <= 1.05 * raw), (default, raw)
    # the autopilots' cubics do no better than the plain one here
    for name in ("PX4 cubic", "ArduPilot cubic"):
        assert default.mean() <= 0.75 * one_cycle[name].mean()


@pytest.mark.slow
def test_no_memory_terms_on_real_still_noise_with_one_temperature_curve():
    """Done-when: on the shared real still recordings (six ADIS16405 sessions, a Galaxy S5, two clocks of the
    Stable32 references) with a temperature effect whose heating and cooling curves are the same, along one cycle,
    branch (or turning-point) terms go on at most 5 % of the axes. Measured: 2 of 112 (on main before: 8 of 112,
    the branch test's random walk fitted to the residual of a model that had absorbed the legs' difference)."""
    shared_dataset("smac-imudata-adis16405")
    shared_dataset("skdivemove-galaxy-s5-static")
    shared_dataset("allantools-stable32")
    trials = still_one_cycle_trials()
    memory = [t for t in trials if t["chosen"].branch or t["chosen"].hysteresis_order]
    assert len(trials) == 112
    assert len(memory) <= 0.05 * len(trials), [(t["name"], t["chosen"].label) for t in memory]
    # and the effect is compensated: where it is ten times the noise, the default's drift on the next leg is within
    # 1.5x the noise's in the mean (a cubic, the effect's own form: 1.15x)
    strong = [t for t in trials if t["amplitude_dps"] == 0.5]
    assert np.mean([t["default"] / t["perfect"] for t in strong]) <= 1.5


def test_a_kept_model_whose_mean_drift_is_above_the_constants_says_which_rule_kept_it():
    """Issue #72, item 3: fitted up to the hottest point, gyro_z's poly:2 + lag shows a mean held-out drift of
    0.091 deg/s against the constant's 0.073 on the two legs; the fit says so, and which rule kept it."""
    import warnings

    from gyrocomp import fit
    from gyrocomp.errors import ModelChoiceWarning

    shared_dataset("tofupilot-imu-thermal")
    run = tofupilot_run()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cal = fit([run.take(np.arange(int(np.argmax(run.temperature_degc)) + 1))])
    sel = cal.report.selection["gyro_z"]
    assert sel.chosen_drift > sel.raw_drift
    said = [str(w.message) for w in caught if w.category is ModelChoiceWarning and "gyro_z: poly" in str(w.message)]
    assert len(said) == 1 and "is above the constant's" in said[0] and "order test" in said[0], said
