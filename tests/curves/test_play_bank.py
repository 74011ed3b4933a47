"""The bank of plays (issue #70, item 2: a discrete Preisach memory whose weights are fitted linearly): the play
operator against its recursion written out sample by sample, any chunking equal to the whole, the loop's width,
its columns times its weights, the model file; fitted on runs written from the physics (a backlash of a width
not on the bank's grid, stepped sample by sample) and judged at another ramp rate, through the library, the
streaming compensator and the command line."""

import json
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp import Calibration, FitOptions, fit
from gyrocomp.curves.play_bank import PlayBankCurve, play_bank_columns, play_half_widths_degc, play_operator
from gyrocomp.errors import InputError

from ..conftest import assert_streaming_equals_batch, run
from .conftest import drift_over_noise, runs_at_two_rates


def _play_by_steps(x: np.ndarray, r: float, start: float) -> np.ndarray:
    out, y = np.empty_like(x), start
    for k, v in enumerate(x):
        y = min(max(y, v - r), v + r)
        out[k] = y
    return out


@settings(max_examples=40, deadline=None)
@given(
    st.integers(1, 700),
    st.floats(0.0, 20.0),
    st.lists(st.integers(1, 300), min_size=1, max_size=5),
    st.integers(0, 2**16),
)
def test_the_play_is_its_recursion_and_any_chunking_is_the_whole(n, r, cuts, seed):
    x = 25.0 + np.cumsum(np.random.default_rng(seed).normal(0.0, 1.0, n))
    whole, last = play_operator(x, r)
    np.testing.assert_array_equal(whole, _play_by_steps(x, r, x[0]))
    assert last == whole[-1]
    parts, state, start = [], None, 0
    for c in [*cuts, n]:
        stop = min(start + c, n)
        if stop > start:
            piece, state = play_operator(x[start:stop], r, state if state is not None else x[0])
            parts.append(piece)
        start = stop
    np.testing.assert_array_equal(np.concatenate(parts), whole)


def test_a_play_lags_a_long_ramp_by_its_half_width_and_the_bank_is_its_columns():
    up, down = np.linspace(0.0, 60.0, 601), np.linspace(59.9, 0.0, 600)
    t = np.concatenate([up, down])
    y, _ = play_operator(t, 5.0)
    np.testing.assert_allclose(y[100:601], up[100:] - 5.0)  # rising: 5 degC behind, once it has moved 5
    np.testing.assert_allclose(y[701:], down[100:] + 5.0)  # falling: 5 degC ahead, 10 degC after the turn
    np.testing.assert_allclose(y[601:700], 55.0)  # across the turn it holds
    curve = PlayBankCurve((1.0, 5.0, 20.0), (0.002, -0.001, 0.0005))
    x, last = play_bank_columns(t, curve.half_widths_degc)
    np.testing.assert_allclose(x @ np.asarray(curve.weights), curve.offset(t), atol=0)
    assert last == tuple(float(v) for v in x[-1] + t[-1])
    # from a 64th of the span (or twice the turn threshold, if wider) to a third, geometrically
    widths = np.array(play_half_widths_degc(90.0, 0.2, 4))
    assert widths[0] == pytest.approx(90.0 / 64) and widths[-1] == pytest.approx(30.0)
    np.testing.assert_allclose(widths[1:] / widths[:-1], (30.0 / (90.0 / 64)) ** (1 / 3))
    assert play_half_widths_degc(90.0, 1.0, 4)[0] == pytest.approx(2.0)


def test_the_model_file_keeps_the_bank_and_refuses_one_that_is_not():
    curve = PlayBankCurve((1.0, 5.0, 20.0), (0.002, -0.001, 0.0005))
    assert PlayBankCurve.from_dict(json.loads(json.dumps(curve.to_dict()))) == curve
    with pytest.raises(InputError, match="half_widths_degc must be positive and increasing"):
        PlayBankCurve.from_dict({**curve.to_dict(), "half_widths_degc": [1.0, 0.5, 20.0]})
    with pytest.raises(InputError, match="1 to 16 half-widths and one weight each"):
        PlayBankCurve.from_dict({**curve.to_dict(), "weights_dps": [0.0]})
    with pytest.raises(InputError, match="needs half_widths_degc and weights_dps"):
        PlayBankCurve.from_dict({"type": "play-bank"})


def _backlash(die: np.ndarray) -> np.ndarray:
    """A backlash of half-width 6.5 degC on the die temperature, started centred, 0.004 deg/s per degC of play."""
    return 0.004 * (_play_by_steps(die, 6.5, die[0]) - die)


@pytest.fixture(scope="module")
def backlash_runs():
    """Two heat-cool runs at 1 degC/min of a part with the backlash, and a third at 3 degC/min with its noise."""
    return runs_at_two_rates(_backlash)


def test_a_backlash_is_carried_to_another_ramp_rate(backlash_runs):
    """The bank leaves the third run's drift within 1.35x of the noise's on every axis at 3 degC/min; the
    turning-point polynomial (which starts each branch at 0) leaves more than twice on some axis."""
    fit_runs, (held, noise) = backlash_runs
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        bank = fit(fit_runs, FitOptions(hysteresis="play-bank"))
        poly = fit(fit_runs, FitOptions(hysteresis="turning-point"))
    assert all(type(ax.hysteresis) is PlayBankCurve for ax in bank.axes.values())
    assert max(drift_over_noise(bank, held, noise)) < 1.35, drift_over_noise(bank, held, noise)
    assert max(drift_over_noise(poly, held, noise)) > 2.0, drift_over_noise(poly, held, noise)


def test_the_bank_streams_as_it_applies_reads_back_and_shows(backlash_runs, tmp_path):
    fit_runs, (held, _) = backlash_runs
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit(fit_runs, FitOptions(hysteresis="play-bank+lag"))
    path = tmp_path / "m.json"
    cal.save(path)
    again = Calibration.load(path)
    assert again.axes["gyro_x"].hysteresis == cal.axes["gyro_x"].hysteresis
    assert again.fit_report["hysteresis"]["axes"]["gyro_x"]["memory"] == "play-bank+lag"
    assert_streaming_equals_batch(again, held.take(np.arange(5000)), [1, 1, 998, 2500])
    shown = run("--no-config", "show", path)
    assert shown.returncode == 0, shown.stderr
    assert "bank of" in shown.stdout and "plays of half-width" in shown.stdout
