"""Runs prepared for fitting: what a fit derives from a run is the same as computing it afresh, is computed once per
run and settings however many stages ask, is read-only, and is not carried to a copy with other data."""

import dataclasses
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gyrocomp.runs.prepared as prepared_module
from gyrocomp.errors import InputError
from gyrocomp.models.fit import fit_channels
from gyrocomp.runs.prepared import PreparedRun, block_means, fit_axes, prefix_sums_at, prepare
from gyrocomp.recording import Recording
from gyrocomp.simulation import simulate
from gyrocomp.motion.positions import static_segments, still_mask


@pytest.fixture(scope="module")
def session():
    """A chamber run that visits six positions (the ``combined`` profile), with its pauses (time gaps)."""
    return simulate("mti10", profile="combined", duration_s=6000, rate_hz=5, seed=4).recording


@pytest.mark.parametrize(
    ("window_s", "min_duration_s", "factor"), [(1.0, 10.0, 4.0), (2.0, 30.0, 3.0), (0.5, 5.0, 8.0)]
)
def test_kept_segments_equal_those_found_afresh(session, window_s, min_duration_s, factor):
    run = PreparedRun.of(session)
    kept = run.static_segments(window_s=window_s, min_duration_s=min_duration_s, factor=factor)
    fresh = static_segments(session, window_s=window_s, min_duration_s=min_duration_s, factor=factor)
    assert len(kept) == len(fresh) > 0
    for a, b in zip(kept, fresh):
        assert (a.start, a.stop, a.start_s, a.duration_s, a.temperature_degc) == (
            b.start,
            b.stop,
            b.start_s,
            b.duration_s,
            b.temperature_degc,
        )
        assert np.array_equal(a.gravity_g, b.gravity_g)
    assert np.array_equal(
        run.still_mask(window_s=window_s, factor=factor), still_mask(session, window_s=window_s, factor=factor)
    )


def test_block_means_equal_those_computed_afresh_and_are_kept_read_only(session):
    run = PreparedRun.of(session)
    pieces = [slice(s.start, s.stop) for s in run.static_segments()]
    kept = run.block_means("gyro_x", 2.0, 0.5, pieces)
    fresh = block_means(session, "gyro_x", 2.0, 0.5, pieces)
    for f in dataclasses.fields(fresh):
        assert np.array_equal(getattr(kept, f.name), getattr(fresh, f.name)), f.name
    assert run.block_means("gyro_x", 2.0, 0.5, list(pieces)) is kept  # equal pieces, even in another list
    assert run.block_means("gyro_x", 2.0, 0.5) is not kept  # other pieces, other blocks
    with pytest.raises(ValueError, match="read-only"):
        kept.value[0] = 0.0
    with pytest.raises(ValueError, match="read-only"):
        run.still_mask()[0] = False


def test_a_run_is_prepared_once_and_shares_its_data(session):
    run = PreparedRun.of(session)
    assert PreparedRun.of(run) is run
    assert isinstance(run, Recording) and run.gyro_dps is session.gyro_dps and run.rate_hz == session.rate_hz
    assert run.static_segments() == run.static_segments() and run.static_segments() is not run.static_segments()
    assert run.still_mask() is run.still_mask()


def test_a_copy_with_other_data_keeps_nothing(session):
    run = PreparedRun.of(session)
    before = run.static_segments()
    spiked = run.gyro_dps.copy()
    middle = (before[0].start + before[0].stop) // 2
    spiked[middle] += 50.0  # a knock in the middle of the first still segment splits it
    copy = run.with_gyro(spiked)
    assert isinstance(copy, PreparedRun)
    after = copy.static_segments()
    assert [(s.start, s.stop) for s in after] == [(s.start, s.stop) for s in static_segments(copy)]
    assert [(s.start, s.stop) for s in after] != [(s.start, s.stop) for s in before]
    piece = run.take(slice(0, run.n_samples // 2))
    assert [(s.start, s.stop) for s in piece.static_segments()] == [(s.start, s.stop) for s in static_segments(piece)]


def test_prepare_refuses_what_is_not_a_recording(session):
    with pytest.raises(
        InputError,
        match=r"recordings\[1\]: expected a Recording \(from gyrocomp.read or simulate\), "
        r"got str",
    ):
        prepare([session, "run.csv"])


def test_a_fit_finds_each_runs_still_segments_once(monkeypatch):
    """Before runs were prepared, a default fit of multi-position chamber runs computed each run's still mask
    three times (input checks, g-sensitivity stage, model choice, thermal model); now once per run."""
    calls = []

    def counted(recording, **settings):
        calls.append((id(recording.gyro_dps), tuple(sorted(settings.items()))))
        return still_mask(recording, **settings)

    monkeypatch.setattr(prepared_module, "still_mask", counted)
    runs = [simulate("consumer", profile="combined", duration_s=3600, rate_hz=10, seed=k).recording for k in range(3)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        calibration = fit_channels(runs)
    assert calibration.report.acceleration.mode == "matrix"  # the segments were used: G was fitted
    assert len(calls) == len(set(calls)), calls
    assert len({run for run, _ in calls}) == 3


def test_a_run_prepared_for_its_accelerometer_models_the_accelerometer_axes_in_g(session):
    """``channel="accel"``: the fit's axes are accel_x, accel_y, accel_z, read from the accelerometer columns [g],
    with the temperature the compensation gives them (the mean of per-axis columns); what was kept from the run is
    shared with its gyro view, and a piece of it keeps the channel."""
    gyro = PreparedRun.of(session)
    mask = gyro.still_mask()
    accel = PreparedRun.of(gyro, "accel")
    assert (gyro.channel, gyro.fit_axes) == ("gyro", session.gyro_axes)
    assert (accel.channel, accel.fit_axes) == ("accel", ("accel_x", "accel_y", "accel_z"))
    assert fit_axes([accel]) == accel.fit_axes and fit_axes([session]) == session.gyro_axes
    assert accel.still_mask() is mask  # kept once for both views
    for j, axis in enumerate(session.accel_axes):
        assert np.array_equal(accel.signal(axis), session.accel_g[:, j]) and accel.unit_of(axis) == "g"
    assert accel.unit_of("gyro_x") == "deg/s" and np.array_equal(accel.signal("gyro_x"), session.gyro("gyro_x"))
    blocks = accel.block_means("accel_z", 5.0, 1.0)
    assert abs(float(np.average(blocks.value, weights=blocks.samples)) - float(session.accel_g[:, 2].mean())) < 1e-9
    assert accel.take(slice(0, 100)).channel == "accel"
    per_axis = dataclasses.replace(
        session,
        temperature_degc=np.column_stack(
            [session.temperature_degc, session.temperature_degc + 1.0, session.temperature_degc + 2.0]
        ),
    )
    np.testing.assert_allclose(
        PreparedRun.of(per_axis, "accel").temperature_for("accel_x"), session.temperature_degc + 1.0
    )
    assert per_axis.temperature_column_for("accel_y") == "temperature"  # the mean, as the compensation reads it


def test_a_channel_is_refused_where_the_run_cannot_give_it(session):
    with pytest.raises(InputError, match=r"channel: 'mag'; use one of gyro, accel"):
        PreparedRun.of(session, "mag")
    bare = dataclasses.replace(session, accel_g=None, accel_axes=())
    with pytest.raises(InputError, match=r"channel=accel needs accel_x, accel_y and accel_z columns \[g\]"):
        PreparedRun.of(bare, "accel")
    with pytest.raises(InputError, match=r"no gyro axis 'accel_x'"):
        bare.signal("accel_x")


@given(
    n=st.integers(0, 300),
    columns=st.integers(1, 4),
    rows=st.integers(1, 400),
    seed=st.integers(0, 2**32 - 1),
    offset=st.sampled_from([0.0, 3.7]),
)
@settings(max_examples=80, deadline=None)
def test_running_sums_in_parts_are_the_whole_columns_to_the_bit(n, columns, rows, seed, offset):
    """The block means' running sums, taken ``rows`` rows at a time at indices anywhere in 0..n (in any order,
    repeated), are ``np.cumsum`` over the whole column, bit for bit."""
    rng = np.random.default_rng(seed)
    x = rng.normal(size=(n, columns)) * 1e3 + 5.0
    at = rng.integers(0, n + 1, size=50)
    whole = np.vstack([np.zeros((1, columns)), np.cumsum(x - offset if offset else x, axis=0)])
    np.testing.assert_array_equal(prefix_sums_at(x, at, offset=offset, rows=rows), whole[at])
    picked = [columns - 1, 0]
    np.testing.assert_array_equal(
        prefix_sums_at(x, at, columns=picked, rows=rows),
        np.vstack([np.zeros((1, 2)), np.cumsum(x[:, picked], axis=0)])[at],
    )
