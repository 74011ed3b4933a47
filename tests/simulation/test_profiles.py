"""Test profiles: temperatures, orientations, rotation and recording pauses."""

import numpy as np
import pytest

from gyrocomp.errors import InputError
from gyrocomp.simulation import PROFILES, get_profile, resolve_profile, tumble_positions
from gyrocomp.simulation.profiles import TUMBLE_LEVELS_G


def test_chamber_ramps_at_the_set_rate_between_dwells():
    prof = get_profile("chamber", set_points_degc=(-20.0, 70.0), ramp_rate_degc_per_min=2.0, dwell_s=600.0)
    assert prof.natural_duration_s == 600 + 90 / 2 * 60 + 600
    traj = prof.trajectory(1.0)
    t, temp = traj.time_s, traj.temperature_degc
    assert temp[0] == -20 and temp[-1] == 70 and np.all(np.diff(temp) >= 0)
    ramp = (t > 700) & (t < 3000)
    np.testing.assert_allclose(np.diff(temp[ramp]), 2.0 / 60)
    assert traj.recorded.all() and np.all(traj.angular_rate_dps == 0)
    np.testing.assert_array_equal(traj.specific_force_g, np.tile([0, 0, 1.0], (t.size, 1)))


def test_cycle_repeats_cold_hot_cold():
    traj = get_profile("cycle", cycles=3, dwell_s=0.0, ramp_rate_degc_per_min=90.0).trajectory(10.0)
    temp = traj.temperature_degc
    assert traj.time_s[-1] == 6 * 60
    assert temp[0] == -20 and temp[-1] == -20
    peaks = np.flatnonzero(temp == 70)
    assert len(peaks) == 3  # one hot turn per cycle


def test_a_set_duration_stretches_the_profile():
    prof = get_profile("chamber").with_duration(3600.0)
    traj = prof.trajectory(2.0)
    assert traj.time_s[-1] == 3600.0
    assert traj.temperature_degc[0] == -20 and traj.temperature_degc[-1] == 70
    # stretched by 7200 / 3600: the 1 degC/min ramp becomes 2 degC/min
    assert np.max(np.diff(traj.temperature_degc)) * 2 * 60 == pytest.approx(2.0)


def test_warmup_approaches_exponentially():
    traj = get_profile("warmup", warmup_rise_degc=15.0, warmup_time_constant_s=300.0).trajectory(1.0)
    t, temp = traj.time_s, traj.temperature_degc
    np.testing.assert_allclose(temp, 25 + 15 * (1 - np.exp(-t / 300)), rtol=1e-12)


def test_tumble_visits_every_level_on_every_axis():
    traj = get_profile("tumble").trajectory(1.0)
    still = ~np.any(traj.angular_rate_dps, axis=1)
    force = traj.specific_force_g
    np.testing.assert_allclose(np.linalg.norm(force, axis=1), 1.0, atol=1e-12)
    for axis in range(3):
        levels = np.unique(np.round(force[still, axis], 9))
        assert set(TUMBLE_LEVELS_G) <= set(levels)
        # about five minutes at each level of its own group
        for level in TUMBLE_LEVELS_G:
            assert np.sum(still & np.isclose(force[:, axis], level)) >= 300
    assert traj.recorded.all()  # the moves are recorded
    assert len(tumble_positions()) == 27


def test_tumble_moves_turn_gravity_consistently_with_the_rate():
    traj = get_profile("tumble", move_s=20.0).trajectory(50.0)
    moving = np.any(traj.angular_rate_dps, axis=1)
    assert moving.any()
    f, w = traj.specific_force_g, np.radians(traj.angular_rate_dps)
    # a vector fixed in the world, seen from the body: df/dt = -w x f
    dfdt = np.gradient(f, traj.time_s, axis=0)
    inner = moving & np.roll(moving, 1) & np.roll(moving, -1)
    np.testing.assert_allclose(dfdt[inner], -np.cross(w[inner], f[inner]), atol=2e-3)


def test_combined_pauses_the_recording_between_positions_inside_a_cycle():
    prof = PROFILES["combined"]
    traj = prof.trajectory(1.0)
    temp = traj.temperature_degc
    assert temp[0] == -20 and temp.max() == 70 and temp[-1] == -20
    rec = traj.recorded
    pauses = np.flatnonzero(np.diff(rec.astype(int)) == -1)
    positions = int(prof.natural_duration_s // (prof.position_s + prof.move_s))
    assert len(pauses) == positions - 1
    assert np.all(traj.angular_rate_dps[rec] == 0)  # repositioning happens while paused
    assert np.any(traj.angular_rate_dps[~rec])
    for axis in range(3):
        assert {-1.0, 1.0} <= set(np.round(traj.specific_force_g[rec, axis], 9))


def test_ratetable_spins_each_axis_mounted_vertical():
    prof = get_profile("ratetable", rates_dps=(10.0, -50.0), position_s=30.0)
    traj = prof.trajectory(10.0)
    rate = traj.angular_rate_dps
    for axis in range(3):
        spinning = rate[:, axis] != 0
        assert set(np.unique(rate[spinning, axis])) == {10.0, -50.0}
        np.testing.assert_array_equal(traj.specific_force_g[spinning, axis], 1.0)
    assert prof.natural_duration_s == 30 * 7


def test_preset_supplies_the_chamber_range():
    assert resolve_profile("cycle", "adxrs450").set_points_degc == (-30.0, 80.0)
    assert resolve_profile("cycle", "adxrs450", set_points_degc=(0.0, 40.0)).set_points_degc == (0.0, 40.0)
    assert resolve_profile("static", "adxrs450").set_points_degc == (25.0,)


def test_profile_errors():
    with pytest.raises(InputError, match=r"profile: unknown profile 'oven'; use one of static, warmup"):
        get_profile("oven")
    with pytest.raises(InputError, match="ramp_rate_degc_per_min: must be positive, got -1"):
        get_profile("chamber", ramp_rate_degc_per_min=-1.0)
    with pytest.raises(InputError, match="cycles: must be at least 1, got 0"):
        get_profile("cycle", cycles=0)
    with pytest.raises(InputError, match="duration_s: 0.1 s is too short for two samples at 1 Hz"):
        get_profile("static").with_duration(0.1).trajectory(1.0)
    with pytest.raises(InputError, match="duration_s: must be positive, got -5"):
        get_profile("static").with_duration(-5)
    # a parameter the profile does not have is named (it was a TypeError from dataclasses.replace)
    with pytest.raises(
        InputError,
        match=r"ramp_rate: not a parameter of a profile; use any of set_points_degc, "
        r"ramp_rate_degc_per_min, dwell_s",
    ):
        get_profile("chamber", ramp_rate=3.0)
    with pytest.raises(InputError, match=r"dwell: not a parameter of a profile"):
        resolve_profile(get_profile("chamber"), dwell=10.0)
    assert resolve_profile(get_profile("chamber"), dwell_s=None) == get_profile("chamber")  # None: unchanged


def test_field_profile_warms_up_rests_and_moves():
    """Room temperature plus a self-heating rise, still position_s then moving move_s in turn; while still the
    specific force is 1 g at the attitude the last move left, and each move's rate turns it there."""
    profile = get_profile("field", duration_s=1800.0, motion_seed=3)
    traj = profile.trajectory(20.0)
    assert traj.temperature_degc[0] == 20.0
    assert traj.temperature_degc[-1] == pytest.approx(20.0 + 25.0 * (1 - np.exp(-1800.0 / 900.0)))
    moving = np.any(traj.angular_rate_dps != 0, axis=1)
    assert moving.mean() == pytest.approx(240.0 / 360.0, abs=0.01)
    still = ~moving
    assert np.allclose(np.linalg.norm(traj.specific_force_g[still], axis=1), 1.0)
    starts = np.flatnonzero(still[1:] & ~still[:-1]) + 1  # the first still sample after each move
    attitudes = traj.specific_force_g[starts]
    assert len({tuple(np.round(a, 6)) for a in attitudes}) == len(starts)  # every move leaves a new attitude
    again = profile.trajectory(20.0)  # the motion seed fixes the moves
    assert np.array_equal(traj.specific_force_g, again.specific_force_g)
    other = get_profile("field", duration_s=1800.0, motion_seed=4).trajectory(20.0)
    assert not np.array_equal(traj.specific_force_g, other.specific_force_g)
