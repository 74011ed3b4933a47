"""Static segment detection on multi-position runs, with and without time gaps."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp.errors import InputError
from gyrocomp.recording import Recording
from gyrocomp.simulation import simulate
from gyrocomp.simulation.profiles import TUMBLE_LEVELS_G
from gyrocomp.motion.positions import _moving_variance, orientations, segment_mask, static_segments, still_mask


@pytest.mark.parametrize("preset, rate_hz", [("mti10", 10.0), ("consumer", 10.0), ("mti10", 1.0)])
def test_tumble_segments_hold_no_motion_and_cover_the_positions(preset, rate_hz):
    sim = simulate(preset, profile="tumble", rate_hz=rate_hz, seed=1)
    rec = sim.recording
    segs = static_segments(rec)
    moving = np.any(sim.truth.true_rate_dps != 0, axis=1)
    inside = segment_mask(rec.n_samples, segs)
    assert not np.any(inside & moving)
    assert np.sum(inside & ~moving) >= 0.97 * np.sum(~moving)
    assert all(s.duration_s >= 10 for s in segs)
    found = orientations(segs)
    # 27 positions, some repeated (0 g on one axis with 1 g on z appears in each group)
    assert 20 <= len(found) <= 27
    for axis in range(3):
        levels = {round(float(g[axis]) * 4) / 4 for g, _ in found}
        assert set(TUMBLE_LEVELS_G) <= levels


def test_combined_segments_never_span_a_pause():
    sim = simulate("mti10", profile="combined", duration_s=20000, rate_hz=1, seed=2)
    rec = sim.recording
    segs = static_segments(rec)
    gap_rows = {g.after_row for g in rec.gaps}
    for s in segs:
        rows = rec.row_numbers[s.start : s.stop]
        assert not any(r in gap_rows for r in rows[:-1])
        assert np.max(np.diff(rec.time_s[s.start : s.stop])) < 2.0
    assert len(orientations(segs)) == 6  # +-1 g on each axis


def test_a_still_gyro_only_log_is_one_segment():
    rng = np.random.default_rng(0)
    t = np.arange(0, 600, 0.1)
    rec = Recording(time_s=t, gyro_dps=rng.normal(0, 0.01, (t.size, 1)), gyro_axes=("gyro_z",))
    segs = static_segments(rec)
    assert len(segs) >= 1 and segs[0].gravity_g is None
    assert sum(s.stop - s.start for s in segs) > 0.95 * t.size
    with pytest.raises(InputError, match="static detection: window -1 s must be positive and factor 4.0 above 1"):
        still_mask(rec, window_s=-1)


@given(
    n=st.integers(2, 400),
    columns=st.integers(1, 6),
    w=st.integers(5, 60),
    seed=st.integers(0, 2**32 - 1),
    scale=st.floats(1e-6, 1e3),
    rows=st.integers(1, 500),
)
@settings(max_examples=100, deadline=None)
def test_the_moving_variance_column_by_column_is_the_whole_arrays_to_the_bit(n, columns, w, seed, scale, rows):
    """The still mask's moving variance is taken a column at a time and ``rows`` rows at a time (its working
    memory a few columns of a part); the result is the one of the running sums over the whole array (the formula
    it replaced), bit for bit, however the rows are parted."""
    x = np.random.default_rng(seed).normal(size=(n, columns)) * scale + 3.0 * scale
    if n < w:
        expected = np.full(n, np.var(x, axis=0).sum())
    else:
        centred = x - x.mean(axis=0)
        c1 = np.vstack([np.zeros((1, columns)), np.cumsum(centred, axis=0)])
        c2 = np.vstack([np.zeros((1, columns)), np.cumsum(centred * centred, axis=0)])
        s1, s2 = (c1[w:] - c1[:-w]) / w, (c2[w:] - c2[:-w]) / w
        var = np.maximum(s2 - s1 * s1, 0.0).sum(axis=1)
        expected = var[np.clip(np.arange(n) - w // 2, 0, var.size - 1)]
    np.testing.assert_array_equal(_moving_variance(x, w, rows), expected)
