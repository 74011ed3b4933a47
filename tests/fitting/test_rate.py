"""The temperature-rate term (a bias in the smoothed dT/dt, issue #70): its rate against the analytic ramp, batch
equal to any chunking, its columns equal to its offset, fitted on runs written from the physics (a bias in the
die's instantaneous rate of change, not our smoothed one) and recovered, carried by the model file."""

import dataclasses
import json
import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp import Calibration, FitOptions, apply, fit
from gyrocomp.curves.rate import TemperatureRateTerm, rate_columns
from gyrocomp.effects import temperature_rate
from gyrocomp.errors import InputError
from gyrocomp.evaluation.validation import fit_plain_cubic
from gyrocomp.measures.merit import smoothed_residual_rms
from gyrocomp.models.options import Network
from gyrocomp.recording import ACCEL_AXES
from gyrocomp.report.html import build_report

from ..conftest import assert_streaming_equals_batch, chamber_run, run

#: the rate gains of conftest.chamber_run's axes [deg/s per degC/s] (its physics: a term in the die's rate)
TRUE_RATE_GAINS = (0.4, 0.2, -0.5)


def test_the_rate_of_a_ramp_is_its_slope_after_the_smoothing():
    # T = 2 degC/min from rest at 0 s: r(t) = rho (1 - exp(-t / s)) exactly (the filter is exact for a linear input)
    t = np.arange(0.0, 3000.0, 0.5)
    rho = 2.0 / 60.0
    r, _ = temperature_rate(t, 20.0 + rho * t, 300.0)
    np.testing.assert_allclose(r, rho * -np.expm1(-t / 300.0), rtol=0, atol=1e-12)
    # at a hold it fades with the same time constant
    hold = np.where(t < 1500.0, rho * t, rho * 1500.0)
    r, _ = temperature_rate(t, hold, 300.0)
    after = t >= 1500.0
    expected = rho * -math.expm1(-1500.0 / 300.0) * np.exp(-(t[after] - 1500.0) / 300.0)
    np.testing.assert_allclose(r[after], expected, rtol=1e-9)


@settings(max_examples=25, deadline=None)
@given(st.lists(st.integers(1, 400), min_size=1, max_size=6), st.floats(5.0, 2000.0))
def test_the_rate_in_chunks_is_the_rate_at_once(cuts, smoothing_s):
    rng = np.random.default_rng(1)
    t = np.arange(1000) * 0.5
    temp = 20.0 + np.cumsum(rng.normal(0.0, 0.05, t.size))
    whole, _ = temperature_rate(t, temp, smoothing_s)
    parts, state, start = [], None, 0
    for c in [*cuts, t.size]:
        stop = min(start + c, t.size)
        if stop > start:
            piece, state = temperature_rate(t[start:stop], temp[start:stop], smoothing_s, period_s=0.5, state=state)
            parts.append(piece)
        start = stop
    np.testing.assert_allclose(np.concatenate(parts), whole, rtol=0, atol=1e-13)


def test_the_term_is_its_column_times_its_coefficient():
    t = np.arange(0.0, 4000.0, 2.0)
    temp = 25.0 + 30.0 * np.sin(t / 700.0)
    term = TemperatureRateTerm(0.9, 120.0)
    rate, _ = temperature_rate(t, temp, 120.0, period_s=2.0)
    np.testing.assert_allclose(rate_columns(t, temp, (120.0,), 2.0)[:, 0] * 0.9, term.offset(rate), atol=1e-15)
    with pytest.raises(InputError, match="smoothing_s must be positive"):
        TemperatureRateTerm(0.9, 0.0)
    with pytest.raises(InputError, match="smoothing"):
        temperature_rate(t, temp, -1.0)


@pytest.fixture(scope="module")
def rate_runs():
    """Two heat-cool runs at 1 degC/min and a third at 3 degC/min, from the physics of conftest.chamber_run."""
    fit_runs = [chamber_run([-10.0, 60.0, -10.0], 1.0, seed=s, rate_hz=2.0) for s in (1, 2)]
    held = chamber_run([-5.0, 60.0, -5.0], 3.0, seed=3, rate_hz=2.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit(fit_runs, FitOptions(hysteresis="rate"))
    return fit_runs, held, cal


def test_the_rate_gain_is_recovered_and_holds_at_another_ramp_rate(rate_runs):
    fit_runs, held, cal = rate_runs
    for axis, gain in zip(("gyro_x", "gyro_y", "gyro_z"), TRUE_RATE_GAINS):
        term = cal.axes[axis].rate_term
        assert term is not None and term.smoothing_s > 0
        # the truth's rate is the die's instantaneous one; the term's is smoothed over s: on the ramps they agree
        assert term.coefficient_per_degc_per_s == pytest.approx(gain, rel=0.15)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ours = apply(cal, held).gyro_dps
        cubic = apply(fit_plain_cubic(fit_runs), held).gyro_dps
    window = 120  # 60 s at 2 Hz
    for j in range(3):  # the truth is still: what is left is noise and the model's error
        assert smoothed_residual_rms(ours[:, j], window) < 0.25 * smoothed_residual_rms(cubic[:, j], window)


#: a g-sensitivity matrix [deg/s per g] written into the runs below (rows: gyro axes; columns: specific force)
G_SENSITIVITY = np.array([[0.05, -0.02, 0.01], [0.03, 0.06, -0.015], [-0.01, 0.02, 0.04]])


def _turned(rec, seed):
    """``rec`` turned through six orientations held in turn, its gyro biased by G_SENSITIVITY times the specific
    force (the physics of a static multi-position run; the moves themselves are not modelled)."""
    rng = np.random.default_rng(seed)
    ups = np.array([(0, 0, 1), (0, 0, -1), (1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0)], dtype=float)
    pose = np.minimum((rec.time_s - rec.time_s[0]) // 400.0, 1e9).astype(int) % len(ups)
    accel = ups[pose] + rng.standard_normal((rec.n_samples, 3)) * 1e-3
    return dataclasses.replace(
        rec, gyro_dps=rec.gyro_dps + accel @ G_SENSITIVITY.T, accel_g=accel, accel_axes=ACCEL_AXES
    )


def test_a_rate_term_beside_a_g_sensitivity_keeps_each_its_own_coefficients():
    # the final fit once read the g-sensitivity one column early (the rate term's), so with both the model was wrong
    runs = [_turned(chamber_run([-10.0, 60.0, -10.0], 1.0, seed=s, rate_hz=2.0), s) for s in (1, 2)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fit(runs, FitOptions(hysteresis="rate", acceleration="matrix"))
    for j, (axis, gain) in enumerate(zip(("gyro_x", "gyro_y", "gyro_z"), TRUE_RATE_GAINS)):
        ax = cal.axes[axis]
        assert ax.rate_term.coefficient_per_degc_per_s == pytest.approx(gain, rel=0.15)
        # each pose holds 400 s of white noise of 0.005 deg/s/sqrt(Hz): a sensitivity to 2e-3 deg/s per g and better
        np.testing.assert_allclose(ax.g_sensitivity_dps_per_g, G_SENSITIVITY[j], rtol=0, atol=2e-3)


def test_a_rate_model_streams_as_it_applies_and_round_trips(rate_runs, tmp_path):
    _, held, cal = rate_runs
    assert_streaming_equals_batch(cal, held, [1, 7, 300, 1999])
    path = tmp_path / "rate.json"
    cal.save(path)
    data = json.loads(path.read_text())
    assert data["schema_version"] == 7
    assert data["axes"]["gyro_z"]["temperature_rate"]["type"] == "temperature-rate"
    again = Calibration.load(path)
    assert again.axes["gyro_z"].rate_term == cal.axes["gyro_z"].rate_term
    np.testing.assert_array_equal(apply(again, held).gyro_dps, apply(cal, held).gyro_dps)
    assert cal.without("rate").axes["gyro_z"].rate_term is None


def test_a_schema_6_file_reads_without_a_rate_term_and_one_claiming_it_is_refused(rate_runs, tmp_path):
    _, _, cal = rate_runs
    data = cal.to_dict()
    data["schema_version"] = 6
    for ax in data["axes"].values():
        del ax["temperature_rate"]
    (tmp_path / "six.json").write_text(json.dumps(data))
    six = Calibration.load(tmp_path / "six.json")
    assert all(ax.rate_term is None for ax in six.axes.values())
    data["axes"]["gyro_x"]["temperature_rate"] = None
    (tmp_path / "edited.json").write_text(json.dumps(data))
    with pytest.raises(InputError, match="temperature_rate, which schema 7 added"):
        Calibration.load(tmp_path / "edited.json")


def test_a_network_with_a_rate_term_is_refused():
    with pytest.raises(InputError, match="network is trained without a temperature-rate term"):
        FitOptions(temperature=Network(), hysteresis="rate")


def test_the_command_line_fits_shows_and_exports_a_rate_term(rate_runs, tmp_path):
    from gyrocomp.io.tables import write_recording

    fit_runs, _, _ = rate_runs
    for k, rec in enumerate(fit_runs):
        write_recording(rec, tmp_path / f"run_{k}.csv")
    done = run("fit", "run_0.csv", "run_1.csv", "--hysteresis", "rate+lag", "-o", "m.json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    shown = run("show", "m.json", cwd=tmp_path)
    assert "temperature rate" in shown.stdout and "per degC/min" in shown.stdout
    refused = run("export", "m.json", "--format", "c", "-o", "c_out", cwd=tmp_path)
    assert refused.returncode == 2 and "thermal lag and a temperature-rate term" in refused.stderr
    done = run("export", "m.json", "--format", "c", "--rate", "2", "-o", "c_out", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "s->rate[" in (tmp_path / "c_out" / "gyrocomp.c").read_text()


@pytest.mark.parametrize("second_ramp", [1.0, 2.5])
def test_the_default_finds_the_rate_term_and_says_whether_the_runs_ramp_rates_could_tell_it(second_ramp, tmp_path):
    # the physics of chamber_run holds a term in the die's rate: the default offers a rate term and takes it, from
    # runs at one ramp rate (saying that one rate cannot tell it from a lag or a memory of the turn, and which run
    # would) or at two (no such warning)
    runs = [chamber_run([-10.0, 60.0, -10.0], ramp, seed=s, rate_hz=2.0) for s, ramp in ((1, 1.0), (2, second_ramp))]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cal = fit(runs)
    for axis, gain in zip(("gyro_x", "gyro_y", "gyro_z"), TRUE_RATE_GAINS):
        assert cal.axes[axis].rate_term.coefficient_per_degc_per_s == pytest.approx(gain, rel=0.15)
    one_rate = [str(w.message) for w in caught if "all ramp at about" in str(w.message)]
    if second_ramp == 1.0:
        (message,) = one_rate
        assert "about 1 degC/min" in message and "a heat-cool run at 2 degC/min (or 0.5) tells them apart" in message
        assert "gyro_x poly:" in message and "could not be checked at another rate" in message
    else:
        assert not one_rate
    cal.save(tmp_path / "m.json")
    selection = Calibration.load(tmp_path / "m.json").report.selection
    for sel in selection.values():
        assert sel.ramp_rates_degc_per_min == pytest.approx((1.0, second_ramp), rel=0.05)
        assert sel.rates_separate == (second_ramp > 1.0)
    shown = run("show", "m.json", cwd=tmp_path)
    said = "all ramp at about 1 degC/min" if second_ramp == 1.0 else "far enough apart to tell a lag"
    assert shown.returncode == 0 and said in " ".join(shown.stdout.split())  # the caption may wrap
    page = build_report(cal, runs[:1]).html
    assert (
        "Ramp rates: "
        + ("the runs all ramp at about 1 degC/min" if second_ramp == 1.0 else "the runs ramp at 1 to 2.5 degC/min")
        in page
    )
