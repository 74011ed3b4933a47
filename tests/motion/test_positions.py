"""Static segment detection on multi-position runs, with and without time gaps."""

import numpy as np
import pytest

from gyrocomp.errors import InputError
from gyrocomp.recording import Recording
from gyrocomp.simulation import simulate
from gyrocomp.simulation.profiles import TUMBLE_LEVELS_G
from gyrocomp.motion.positions import orientations, segment_mask, static_segments, still_mask


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
