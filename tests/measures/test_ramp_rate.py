"""The runs' ramp rates (gyrocomp.measures.ramp_rate): the typical rate of analytic ramps and holds, what rates can
tell a memory that grows with the rate from one that does not, and the sentence that says so."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gyrocomp.measures.ramp_rate import (
    NEXT_RUN_RATE_FACTOR,
    SEPARATING_RAMP_RATIO,
    minute_rates,
    ramp_rate_degc_per_min,
    ramp_rates_separate,
    run_ramp_rates_degc_per_min,
    separation_sentence,
    typical_ramp_degc_per_min,
)
from gyrocomp.recording import Recording


def _cycle(ramp_degc_per_min: float, hold_s: float = 900.0, rate_hz: float = 2.0) -> tuple[np.ndarray, np.ndarray]:
    """A hold at 0 degC, a ramp to 60 degC at ``ramp_degc_per_min``, a hold, the ramp back, a hold."""
    ramp_s = 60.0 / ramp_degc_per_min * 60.0
    knots_t = np.cumsum([0.0, hold_s, ramp_s, hold_s, ramp_s, hold_s])
    t = np.arange(0.0, knots_t[-1], 1.0 / rate_hz)
    return t, np.interp(t, knots_t, [0.0, 0.0, 60.0, 60.0, 0.0, 0.0])


def _recording(t: np.ndarray, temperature: np.ndarray | None) -> Recording:
    return Recording(t, np.zeros((t.size, 1)), ("gyro_z",), temperature)


@pytest.mark.parametrize("ramp", [0.25, 1.0, 3.0, 10.0])
def test_the_typical_rate_of_a_cycle_with_holds_is_its_ramp(ramp):
    # the holds' minutes (no change) and the minutes a turn falls in are left out or outnumbered by the ramp's
    t, temperature = _cycle(ramp)
    assert typical_ramp_degc_per_min([(t, temperature)]) == pytest.approx(ramp, rel=1e-9)
    assert ramp_rate_degc_per_min([_recording(t, temperature)]) == pytest.approx(ramp, rel=1e-9)


def test_each_minute_changes_by_the_slope():
    t = np.arange(0.0, 600.0, 0.1)
    np.testing.assert_allclose(minute_rates(t, 20.0 - 0.05 * t), 3.0, rtol=1e-12)  # 0.05 degC/s
    assert minute_rates(t[:300], t[:300]).size == 0  # under two whole minutes: none


def test_a_run_that_does_not_ramp_has_no_rate():
    t = np.arange(0.0, 3600.0, 1.0)
    assert math.isnan(typical_ramp_degc_per_min([(t, np.full(t.size, 25.0))]))
    rates = run_ramp_rates_degc_per_min([_recording(t, np.full(t.size, 25.0)), _recording(t, None)])
    assert all(math.isnan(r) for r in rates)
    assert ramp_rate_degc_per_min([_recording(t, np.full(t.size, 25.0))]) == 1.0  # the planning's placeholder
    assert "do not ramp" in separation_sentence(rates)


def test_runs_at_one_rate_cannot_separate_and_the_sentence_names_the_run_that_would():
    rates = run_ramp_rates_degc_per_min([_recording(*_cycle(1.0)), _recording(*_cycle(1.2))])
    assert rates == pytest.approx((1.0, 1.2), rel=1e-9)
    assert not ramp_rates_separate(rates)
    sentence = separation_sentence(rates)
    assert "all ramp at about 1.1 degC/min" in sentence
    assert f"{NEXT_RUN_RATE_FACTOR * 1.1:.2g} degC/min (or {1.1 / NEXT_RUN_RATE_FACTOR:.2g})" in sentence


def test_runs_far_enough_apart_separate():
    slow, fast = _cycle(1.0), _cycle(SEPARATING_RAMP_RATIO * 1.01)
    still = (np.arange(0.0, 3600.0), np.full(3600, 30.0))
    rates = run_ramp_rates_degc_per_min([_recording(*slow), _recording(*still), _recording(*fast)])
    assert ramp_rates_separate(rates)  # the run that does not ramp is left out, not counted as rate 0
    assert "far enough apart" in separation_sentence(rates)
    assert not ramp_rates_separate([1.0, SEPARATING_RAMP_RATIO * 0.99])
    assert not ramp_rates_separate([])
    assert separation_sentence(()) == ""
