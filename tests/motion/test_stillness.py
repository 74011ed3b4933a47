"""Stillness detection on any log: thresholds from the data's own noise, smooth rotations and knocks rejected,
gaps respected, any chunking equal to one batch."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp.errors import InputError
from gyrocomp.recording import ACCEL_AXES, GYRO_AXES, Recording
from gyrocomp.simulation import get_profile, simulate
from gyrocomp.motion.stillness import StillnessState, classify_blocks, detect_still, detection


def _moving(truth) -> np.ndarray:
    return np.any(truth.true_rate_dps != 0, axis=1)


@pytest.mark.parametrize("preset, rate_hz", [("consumer", 100.0), ("mti10", 400.0), ("adis16488", 10.0)])
def test_field_logs_still_moments_found_and_no_move_taken_for_still(preset, rate_hz):
    """Parts whose noise differs 30-fold, at 10 to 400 Hz: not one moving sample inside a segment, and at least
    90 % of the true still time found (each still period loses a block at each end to the moves)."""
    sim = simulate(preset, profile=get_profile("field", duration_s=1800.0), rate_hz=rate_hz, seed=4)
    found = detect_still(sim.recording)
    moving = _moving(sim.truth)
    assert not np.any(found.mask(sim.recording.n_samples) & moving)
    true_still_s = (~moving).sum() / rate_hz
    assert found.still_s >= 0.9 * true_still_s - 2 * len(found.segments)
    assert 0.9 * true_still_s <= found.still_s <= true_still_s
    for segment in found.segments:
        inside = slice(segment.start, segment.stop)
        bias = sim.recording.gyro_dps[inside].mean(axis=0) - sim.truth.true_rate_dps[inside].mean(axis=0)
        assert np.allclose(segment.gyro_mean_dps, bias)
        assert segment.accel_mean_g == pytest.approx(sim.recording.accel_g[inside].mean(axis=0))


def _still_log(rate_hz: float = 100.0, duration_s: float = 600.0, seed: int = 0):
    """A still unit: white gyro noise 0.05 deg/s and accelerometer noise 2 mg per sample, level."""
    rng = np.random.default_rng(seed)
    n = int(duration_s * rate_hz)
    t = np.arange(n) / rate_hz
    gyro = 0.3 + 0.05 * rng.standard_normal((n, 3))
    accel = np.array([0.0, 0.0, 1.0]) + 0.002 * rng.standard_normal((n, 3))
    return t, gyro, accel, np.full(n, 25.0)


def _recording(t, gyro, accel, temperature):
    return Recording(t, gyro, GYRO_AXES, temperature_degc=temperature, accel_g=accel, accel_axes=ACCEL_AXES)


def test_a_smooth_slow_turn_and_a_knock_are_not_still():
    """A turn at 2 deg/s about x (quiet: its variance is the noise's) moves gravity and is rejected; so is a
    knock of 0.2 s."""
    t, gyro, accel, temperature = _still_log()
    turn = (t >= 200) & (t < 260)
    gyro[turn, 0] += 2.0
    angle = np.radians(2.0 * np.clip(t - 200, 0, 60))  # gravity turns about x, then rests at 120 deg
    accel[:, 1] += -np.sin(angle)
    accel[:, 2] += np.cos(angle) - 1.0
    knock = (t >= 400) & (t < 400.2)
    gyro[knock] += 3.0
    found = detect_still(_recording(t, gyro, accel, temperature))
    mask = found.mask(t.size)
    assert not mask[turn].any() and not mask[knock].any()
    # beside a move: the block next to it (its mean differs from the move's) and the trimmed edge are left out
    assert [round(s.start_s) for s in found.segments] == [1, 262, 403]
    assert [round(s.stop_s) for s in found.segments] == [198, 398, 599]
    assert found.gyro_noise_dps2 == pytest.approx(np.full(3, 0.05**2), rel=0.1)


def test_a_gap_ends_a_segment_and_no_block_spans_it():
    t, gyro, accel, temperature = _still_log()
    t[t >= 300] += 50.0  # 50 s lost
    found = detect_still(_recording(t, gyro, accel, temperature))
    assert len(found.segments) == 2
    assert found.segments[0].stop_s <= 300.0 and found.segments[1].start_s >= 350.0
    blocks = found.blocks
    assert not np.any((blocks.start_s < 300) & (blocks.stop_s > 300))


@settings(max_examples=25, deadline=None)
@given(st.lists(st.integers(min_value=1, max_value=5000), min_size=1, max_size=30))
def test_any_chunking_gives_the_batch_blocks_and_segments(chunks):
    sim = _field_for_chunks()
    rec = sim.recording
    state = StillnessState(rec.rate_hz)
    edges = np.cumsum([0, *chunks])
    edges = np.unique(np.clip(np.concatenate([edges, [rec.n_samples]]), 0, rec.n_samples))
    for a, b in zip(edges[:-1], edges[1:]):
        state.update(rec.time_s[a:b], rec.gyro_dps[a:b], rec.accel_g[a:b], rec.temperature_degc[a:b])
    streamed = detection(state.blocks())
    batch = detect_still(rec)
    for name in (
        "start_s",
        "stop_s",
        "first",
        "count",
        "whole",
        "after_gap",
        "gyro_mean_dps",
        "gyro_var_dps2",
        "accel_mean_g",
        "accel_var_g2",
        "temperature_degc",
    ):
        assert np.allclose(getattr(streamed.blocks, name), getattr(batch.blocks, name), rtol=1e-12, atol=0), name
    assert np.array_equal(streamed.still_blocks, batch.still_blocks)
    assert [(s.start, s.stop) for s in streamed.segments] == [(s.start, s.stop) for s in batch.segments]


_FIELD = []


def _field_for_chunks():
    if not _FIELD:
        _FIELD.append(simulate("consumer", profile=get_profile("field", duration_s=900.0), rate_hz=50, seed=2))
    return _FIELD[0]


def test_bad_settings_are_refused():
    with pytest.raises(InputError, match=r"rate_hz: must be positive, got 0"):
        StillnessState(0.0)
    with pytest.raises(InputError, match=r"block_s: must be positive, got -1"):
        StillnessState(100.0, block_s=-1)
    state = StillnessState(100.0)
    t, gyro, accel, temperature = _still_log(duration_s=30)
    state.update(t, gyro, accel, temperature)
    with pytest.raises(InputError, match=r"quantile: must lie in \(0, 0.5\), got 0.7"):
        classify_blocks(state.blocks(), quantile=0.7)
    with pytest.raises(InputError, match=r"alpha: must lie in \(0, 0.5\), got 0"):
        classify_blocks(state.blocks(), alpha=0)


def test_a_log_never_still_has_no_still_segment():
    """Stops of 10 s in a vibrating log (4 % of it): its quietest blocks are the vibration, noisier than any MEMS
    sensor at rest, so nothing is taken for still (the noise level alone would have passed the moves)."""
    sim = simulate("consumer", profile=get_profile("field", position_s=10.0, duration_s=1200.0), rate_hz=25, seed=5)
    found = detect_still(sim.recording)
    assert found.segments == [] and not found.still_blocks.any()
