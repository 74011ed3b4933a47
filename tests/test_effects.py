"""The deterministic effects: thermal lag, turning points, hysteresis, g-sensitivity, quantization."""

import math
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.signal import lfilter as scipy_lfilter

from gyrocomp.effects import (
    find_turns,
    g_sensitivity_offset,
    g_squared_products,
    hysteresis_offset,
    lag_coefficients,
    _first_order,
    moving_average,
    moving_average_range,
    quantize,
    thermal_lag,
)
from gyrocomp.errors import InputError


def test_lag_follows_a_ramp_exactly_rate_times_tau_behind():
    rate_hz, tau, ramp = 10.0, 50.0, 0.02  # [Hz], [s], [degC/s]
    t = np.arange(0, 2000, 1 / rate_hz)
    u = 20 + ramp * t
    y, _ = thermal_lag(t, u, tau)
    # analytic response from equilibrium: lag = r tau (1 - exp(-t / tau))
    np.testing.assert_allclose(u - y, ramp * tau * -np.expm1(-t / tau), atol=1e-10)


def test_lag_step_response_is_the_exponential():
    t = np.arange(0, 100, 0.5)
    u = np.where(t > 0, 1.0, 0.0)  # linear between samples 0 and 0.5 s (first-order hold)
    y, _ = thermal_lag(t, u, 10.0)
    # for a ramp from 0 to 1 over h, then constant: y(t) = 1 - (tau/h)(1 - e^{-h/tau}) e^{-(t-h)/tau}
    h, tau = 0.5, 10.0
    expected = 1 - (tau / h) * -math.expm1(-h / tau) * np.exp(-(t[1:] - h) / tau)
    np.testing.assert_allclose(y[1:], expected, rtol=1e-12)


def test_lag_coefficients_have_unit_gain_and_no_lag_without_time_constant():
    a, b0, b1 = lag_coefficients(0.01, 30.0)
    assert (b0 + b1) / (1 - a) == pytest.approx(1.0, rel=1e-12)
    assert lag_coefficients(0.01, 0.0) == (0.0, 1.0, 0.0)
    t = np.arange(5.0)
    np.testing.assert_array_equal(thermal_lag(t, t**2, 0.0)[0], t**2)


def test_lag_bridges_a_gap_as_if_the_samples_were_there():
    t = np.arange(0, 600, 0.1)
    u = 25 + 10 * np.sin(t / 60)
    full, _ = thermal_lag(t, u, 40.0)
    # drop a 30 s stretch over which u is nearly linear: the bridged value matches closely
    keep = (t < 300) | (t >= 300.1)  # a one-step gap is exact
    gapped, _ = thermal_lag(t[keep], u[keep], 40.0, period_s=0.1)
    np.testing.assert_allclose(gapped, full[keep], atol=1e-4)
    lin = 25 + 0.01 * t
    keep = (t < 200) | (t > 230)
    exact, _ = thermal_lag(t, lin, 40.0)
    bridged, _ = thermal_lag(t[keep], lin[keep], 40.0, period_s=0.1)
    np.testing.assert_allclose(bridged, exact[keep], atol=1e-9)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(min_value=1, max_value=400), min_size=1, max_size=8))
def test_lag_in_chunks_equals_one_call(cuts):
    rng = np.random.default_rng(len(cuts))
    t = np.arange(1500) * 0.1
    t[700:] += 12.0  # a gap
    u = np.cumsum(rng.standard_normal(t.size)) * 0.05 + 20
    whole, _ = thermal_lag(t, u, 7.0, period_s=0.1)
    parts, state, start = [], None, 0
    for c in cuts + [t.size]:
        stop = min(start + c, t.size)
        if stop > start:
            y, state = thermal_lag(t[start:stop], u[start:stop], 7.0, period_s=0.1, state=state)
            parts.append(y)
        start = stop
    np.testing.assert_allclose(np.concatenate(parts), whole, rtol=0, atol=1e-12)


def _cycle(n_cycles=3, samples_per_ramp=2000, lo=-20.0, hi=70.0):
    ramp_up = np.linspace(lo, hi, samples_per_ramp)
    one = np.concatenate([np.full(300, lo), ramp_up, np.full(300, hi), ramp_up[::-1]])
    return np.concatenate([one] * n_cycles + [np.full(300, lo)])


def test_turns_of_a_clean_cycle():
    temp = _cycle()
    turns = find_turns(temp)
    # hot, cold, hot, cold, hot; the last cold turn is not confirmed: the temperature never rises again
    assert len(turns.turn_index) == 5
    assert list(turns.turn_degc[turns.turn_index]) == [70, -20, 70, -20, 70]
    assert turns.direction[0] == 0 and turns.direction[400] == 1
    assert np.all(np.isnan(turns.turn_degc[: turns.turn_index[0]]))


def test_turns_ignore_noise_and_whole_degree_steps():
    rng = np.random.default_rng(0)
    temp = np.round(_cycle() + rng.normal(0, 0.3, _cycle().size))
    assert len(find_turns(temp, threshold_degc=2.5).turn_index) == 5
    # without a threshold the noise makes hundreds of false reversals
    assert len(find_turns(temp).turn_index) > 100
    turns = find_turns(temp, threshold_degc=2.5)
    assert set(np.unique(turns.turn_degc[~np.isnan(turns.turn_degc)])) <= {
        -22.0,
        -21.0,
        -20.0,
        -19.0,
        69.0,
        70.0,
        71.0,
        72.0,
    }


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(min_value=1, max_value=3000), min_size=1, max_size=10), st.sampled_from([0.0, 0.5, 2.5]))
def test_turns_in_chunks_equal_one_call(cuts, threshold):
    rng = np.random.default_rng(7)
    temp = np.round(_cycle(2, 900) + rng.normal(0, 0.3, _cycle(2, 900).size), 1)
    whole = find_turns(temp, threshold)
    dirs, turn, state, start = [], [], None, 0
    for c in cuts + [temp.size]:
        stop = min(start + c, temp.size)
        if stop > start:
            part = find_turns(temp[start:stop], threshold, state=state)
            dirs.append(part.direction)
            turn.append(part.turn_degc)
            state = part.state
        start = stop
    np.testing.assert_array_equal(np.concatenate(dirs), whole.direction)
    np.testing.assert_array_equal(np.concatenate(turn), whole.turn_degc)


def test_hysteresis_offset_on_the_chosen_branches_and_band():
    temp = _cycle(1)
    turns = find_turns(temp)
    h = (0.032, -0.00128)
    off = hysteresis_offset(temp, turns, h, direction="descending", band_degc=(55.0, 80.0))
    falling = (turns.direction == -1) & (temp >= 55)
    d = 70.0 - temp[falling]
    np.testing.assert_allclose(off[falling], 0.032 * d - 0.00128 * d**2, rtol=1e-12)
    assert np.all(off[~falling] == 0)
    both = hysteresis_offset(temp, turns, (1e-3,), direction="both")
    first_turn = turns.turn_index[0]
    assert np.all(both[:first_turn] == 0)
    assert both[-1] == pytest.approx(1e-3 * 90)  # still on the cooling branch from 70 degC
    with pytest.raises(InputError, match="hysteresis direction: 'up'; use one of descending, ascending, both"):
        hysteresis_offset(temp, turns, h, direction="up")


def test_hysteresis_offset_is_held_past_the_largest_distance_fitted():
    temp = _cycle(1)
    turns = find_turns(temp)
    h = (0.01, 2e-4)
    free = hysteresis_offset(temp, turns, h, direction="descending")
    held = hysteresis_offset(temp, turns, h, direction="descending", max_distance_degc=30.0)
    falling = turns.direction == -1
    d = np.abs(temp - np.nan_to_num(turns.turn_degc))
    near, far = falling & (d <= 30.0), falling & (d > 30.0)
    assert near.any() and far.any()
    np.testing.assert_array_equal(held[near], free[near])
    np.testing.assert_allclose(held[far], 0.01 * 30 + 2e-4 * 30**2, rtol=1e-12)  # the value at d = 30 degC


def test_g_sensitivity_is_the_matrix_times_the_force():
    rng = np.random.default_rng(1)
    a = rng.normal(size=(50, 3))
    g = rng.normal(size=(2, 3)) * 0.01
    q = rng.normal(size=(2, 6)) * 0.001
    out = g_sensitivity_offset(a, g, q)
    for i in range(50):
        x, y, z = a[i]
        quad = np.array([x * x, y * y, z * z, x * y, x * z, y * z])
        np.testing.assert_allclose(out[i], g @ a[i] + q @ quad, rtol=1e-12)
    assert g_squared_products(a).shape == (50, 6)


def test_quantize_rounds_to_the_lsb():
    np.testing.assert_array_equal(quantize(np.array([0.24, 0.26, -0.74]), 0.5), [0.0, 0.5, -0.5])
    x = np.array([0.123456])
    assert quantize(x, 0.0)[0] == x[0]


def test_effect_option_errors():
    with pytest.raises(InputError, match="thermal time constant: must not be negative, got -1"):
        thermal_lag(np.arange(3.0), np.arange(3.0), -1.0)
    with pytest.raises(InputError, match="turning-point threshold: must not be negative, got -0.1"):
        find_turns(np.arange(3.0), -0.1)


def _turns_sample_by_sample(x, threshold):
    """The detector's definition, one sample at a time (as the C export's turn_update does)."""
    d, extreme, turn, low, high = 0, np.nan, np.nan, np.inf, -np.inf
    direction, turns, index = [], [], []
    for i, v in enumerate(x):
        if d == 0:
            low, high = min(low, v), max(high, v)
            if high - v > threshold:
                d, extreme = -1, low
            elif v - low > threshold:
                d, extreme = 1, high
        else:
            running = max(extreme, v) if d == 1 else min(extreme, v)
            if (running - v if d == 1 else v - running) > threshold:
                turn, d, extreme = running, -d, v
                index.append(i)
            else:
                extreme = running
        direction.append(d)
        turns.append(turn)
    return np.array(direction), np.array(turns), np.array(index, dtype=int)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**31 - 1), st.sampled_from([0.0, 0.3, 2.0]), st.integers(1, 5000))
def test_find_turns_equals_its_sample_by_sample_definition(seed, threshold, n):
    rng = np.random.default_rng(seed)
    x = np.round(np.cumsum(rng.normal(0, 1, n)) + 10 * np.sin(np.arange(n) / rng.uniform(5, 500)), 1)
    direction, turn, index = _turns_sample_by_sample(x, threshold)
    got = find_turns(x, threshold)
    np.testing.assert_array_equal(got.direction, direction)
    np.testing.assert_array_equal(got.turn_degc, turn)
    np.testing.assert_array_equal(got.turn_index, index)


@pytest.mark.parametrize("n", [1, 2, 57, 5000])
def test_the_short_first_order_filter_is_scipys_to_the_bit(n):
    """lazy_lfilter runs short first-order filters in Python until scipy.signal is imported: the same numbers as
    scipy.signal.lfilter, bit for bit, with and without an initial state, for the lag's, the learner's and the
    simulator's forms."""
    rng = np.random.default_rng(n)
    x = rng.normal(25.0, 3.0, n)
    a = 0.9973
    for b, den in (([0.0015, 0.0012], [1.0, -a]), ([1 - a], [1.0, -a]), ([1.0], [1.0, -a])):
        zi = [rng.normal()]
        ours, state = _first_order(b, den, x, zi)
        theirs, their_state = scipy_lfilter(b, den, x, zi=zi)
        assert np.array_equal(ours, theirs) and np.array_equal(state, their_state)
        assert np.array_equal(_first_order(b, den, x, None), scipy_lfilter(b, den, x))


def test_a_process_that_filters_much_imports_scipy_after_its_python_budget():
    """In a new interpreter (this one has scipy.signal already): short filters run in Python, without importing
    scipy.signal, until PYTHON_FILTER_BUDGET samples; the next one imports it. Every result is scipy's."""
    code = """
import sys
import numpy as np
from gyrocomp.effects import PYTHON_FILTER_BUDGET, PYTHON_FILTER_SAMPLES, lazy_lfilter
x = np.random.default_rng(0).normal(size=PYTHON_FILTER_SAMPLES)
calls = PYTHON_FILTER_BUDGET // x.size
got = [lazy_lfilter([0.5, 0.25], [1.0, -0.75], x) for _ in range(calls)]
before = "scipy.signal" in sys.modules
got.append(lazy_lfilter([0.5, 0.25], [1.0, -0.75], x))
after = "scipy.signal" in sys.modules
from scipy.signal import lfilter
same = all(np.array_equal(g, lfilter([0.5, 0.25], [1.0, -0.75], x)) for g in got)
print(calls, before, after, same)
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert int(out[0]) >= 2 and out[1:] == ["False", "True", "True"], out


@settings(max_examples=25, deadline=None)
@given(st.integers(1, 5000), st.integers(1, 70_000), st.integers(0, 2**31 - 1))
def test_moving_average_range_is_the_peak_to_peak_of_the_moving_average(w, n, seed):
    """A part at a time (4096 samples, and parts shorter than the window), the same extremes as the whole moving
    average, to the bit."""
    x = np.cumsum(np.random.default_rng(seed).standard_normal(max(n, w))) * 0.01 + 3.0
    assert moving_average_range(x, w, rows=4096) == float(np.ptp(moving_average(x, w)))
    assert moving_average_range(x, w, rows=w // 2 + 1) == float(np.ptp(moving_average(x, w)))
