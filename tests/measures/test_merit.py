import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp.errors import InputError
from gyrocomp.measures.merit import (
    BIAS_INSTABILITY_FACTOR,
    AxisMetrics,
    bias_instability,
    bias_offset,
    evaluate_run,
    moving_average,
    window_samples,
)
from gyrocomp.recording import Recording


@settings(max_examples=50, deadline=None)
@given(x=st.lists(st.floats(-1e3, 1e3), min_size=1, max_size=60), w=st.integers(1, 60))
def test_moving_average_equals_convolution(x, w):
    x = np.array(x)
    if w > x.size:  # no full window: refused, not an empty or partial average
        with pytest.raises(InputError, match=rf"window: {w} samples is longer than the data \({x.size} samples\)"):
            moving_average(x, w)
        return
    np.testing.assert_allclose(moving_average(x, w), np.convolve(x, np.ones(w) / w, mode="valid"), atol=1e-9)


def test_bias_offset_of_a_ramp():
    x = np.linspace(0, 1, 1001)  # moving average of a ramp is the ramp, shortened by w - 1 samples
    assert bias_offset(x, 101) == pytest.approx(0.9)


def test_bias_instability_factor():
    assert BIAS_INSTABILITY_FACTOR == pytest.approx(0.6643, abs=1e-4)


def test_bias_instability_of_white_noise_is_at_the_longest_tau():
    rng = np.random.default_rng(3)
    y = rng.standard_normal(100_000) * 0.1
    bi = bias_instability(y, 100.0)
    assert bi.integration_time_s == pytest.approx(163.84)


def test_evaluate_run_on_known_drift():
    t = np.arange(0, 1000, 0.1)
    drift = 0.01 * np.sin(2 * np.pi * t / 1000)
    rng = np.random.default_rng(0)
    noise = rng.standard_normal(t.size) * 1e-3
    raw = Recording(time_s=t, gyro_dps=drift + noise, gyro_axes=("gyro_z",))
    comp = raw.with_gyro(noise)
    run = evaluate_run(raw, comp, window_s=10.0)
    m = run.axes["gyro_z"]
    assert run.window_s == 10.0
    assert m.bias_offset_raw_dps == pytest.approx(0.02, rel=0.05)
    assert m.bias_offset_comp_dps < 0.002
    assert m.offset_improvement == pytest.approx(m.bias_offset_raw_dps / m.bias_offset_comp_dps)
    assert m.residual_rms_dps == pytest.approx(1e-3 / np.sqrt(100), rel=0.2)
    assert m.bias_instability_comp_dph < m.bias_instability_raw_dph


def test_window_errors():
    with pytest.raises(InputError, match=r"window_s: must be positive, got -1"):
        window_samples(-1, 10.0, 100)
    with pytest.raises(InputError, match=r"window_s: 100 s is longer than the run \(10 s\)"):
        window_samples(100, 10.0, 100)
    with pytest.raises(InputError, match=r"window: 20 samples is longer than the data"):
        moving_average(np.zeros(10), 20)


def test_runs_with_gaps_pool_the_allan_sums_over_their_stretches():
    from gyrocomp.allan import allan_deviation_segments
    from gyrocomp.errors import DataQualityWarning
    from gyrocomp.simulation import simulate

    sim = simulate("mti10", profile="combined", duration_s=6 * 3600, rate_hz=2, seed=1)
    rec = sim.recording
    assert len(rec.gaps) > 10
    with pytest.warns(DataQualityWarning, match=r"time gap\(s\); the Allan deviation pools the \d+ stretches"):
        ev = evaluate_run(rec, rec, window_s=10.0)
    stretches = rec.contiguous_stretches()
    pooled = allan_deviation_segments([rec.gyro_dps[s, 0] for s in stretches], rec.rate_hz).minimum()
    assert ev.axes["gyro_x"].bias_instability_raw_dph == pytest.approx(
        pooled.deviation / BIAS_INSTABILITY_FACTOR * 3600, rel=1e-12
    )
    # no tau longer than a stretch: the curve stops where the positions do
    assert ev.axes["gyro_x"].integration_time_raw_s <= max(s.stop - s.start for s in stretches) / rec.rate_hz


@pytest.mark.parametrize(
    ("unit", "bi_unit", "suffix", "bi", "other"), [("deg/s", "deg/h", "dps", "dph", "g"), ("g", "ug", "g", "ug", "dps")]
)
def test_one_figures_class_reads_each_figure_under_its_units_name(unit, bi_unit, suffix, bi, other):
    """Gyro and accelerometer figures are one class with a unit: the names that carry a unit read the axis's own
    figures (distinct values, so a swap would show) and refuse the other unit's; the JSON writes those names."""
    names = [f.name for f in dataclasses.fields(AxisMetrics) if f.name != "unit"]
    figures = AxisMetrics(unit, *[float(k + 1) for k in range(len(names))])
    value = dict(zip(names, range(1, len(names) + 1)))
    assert (figures.unit, figures.bias_instability_unit) == (unit, bi_unit)
    assert getattr(figures, f"bias_offset_raw_{suffix}") == value["offset_raw"]
    assert getattr(figures, f"bias_offset_comp_{suffix}") == value["offset_comp"]
    assert getattr(figures, f"bias_instability_raw_{bi}") == value["bias_instability_raw"]
    assert getattr(figures, f"bias_instability_comp_{bi}") == value["bias_instability_comp"]
    assert getattr(figures, f"residual_rms_{suffix}") == value["residual_rms"]
    with pytest.raises(
        InputError,
        match=rf"bias_offset_raw_{other}: the axis's values are in {unit}, not .*; "
        r"read offset_raw",
    ):
        getattr(figures, f"bias_offset_raw_{other}")
    assert figures.to_dict() == {
        f"bias_offset_raw_{suffix}": 1.0,
        f"bias_offset_comp_{suffix}": 2.0,
        "offset_improvement": 3.0,
        f"bias_instability_raw_{bi}": 4.0,
        f"bias_instability_comp_{bi}": 5.0,
        "integration_time_raw_s": 6.0,
        "integration_time_comp_s": 7.0,
        f"residual_rms_{suffix}": 8.0,
    }
    with pytest.raises(InputError, match=r"unit: 'rad/s'; an axis is in one of deg/s, g"):
        AxisMetrics("rad/s", *[1.0] * len(names))
