import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp.errors import InputError
from gyrocomp.recording import GAP_FACTOR, Gap, Recording

from ..conftest import burst_stamped_recording


def make(time, gyro=None, temp=None, **kw):
    n = len(time)
    return Recording(
        time_s=np.asarray(time, float),
        gyro_dps=np.zeros(n) if gyro is None else gyro,
        gyro_axes=("gyro_z",),
        temperature_degc=temp,
        source="r.csv",
        **kw,
    )


def test_rate_and_duration():
    rec = make(np.arange(1001) / 100.0)
    assert rec.rate_hz == 100.0
    assert rec.duration_s == pytest.approx(10.0)
    assert rec.gaps == ()


def test_time_backwards_names_row():
    with pytest.raises(InputError, match=r"r.csv: row 3: time goes backwards \(0.5 s after 1 s\)"):
        make([0.0, 1.0, 0.5, 2.0])


def test_time_repeat_names_row_number_from_source():
    with pytest.raises(InputError, match=r"row 12: time repeats"):
        make([0.0, 1.0, 1.0], row_numbers=np.array([10, 11, 12]))


def test_nan_names_row_and_channel():
    with pytest.raises(
        InputError, match=r"row 2, column 'temperature': nan is not a finite number.*drop_nonfinite=True"
    ):
        make([0.0, 1.0, 2.0], temp=np.array([20.0, np.nan, 21.0]))


def test_gaps_are_found_and_kept():
    t = np.concatenate([np.arange(100) * 0.01, 5.0 + np.arange(100) * 0.01])
    rec = make(t)
    assert rec.n_samples == 200
    assert len(rec.gaps) == 1
    gap = rec.gaps[0]
    assert gap.after_row == 100
    assert gap.duration_s == pytest.approx(5.0 - 0.99)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(0.005, 0.2), min_size=2, max_size=300))
def test_the_gaps_are_every_step_over_twice_the_median_in_order(steps):
    """The gaps (kept as arrays) are, in order, each step longer than GAP_FACTOR median steps: the row before it
    (1-based), its time and length, as a list of Gap made here one by one; a sequence equal to that list."""
    t = np.concatenate([[0.0], np.cumsum(steps)])
    rec = make(t)
    dt = np.diff(t)
    expected = [Gap(k + 1, float(t[k]), float(dt[k])) for k in range(dt.size) if dt[k] > GAP_FACTOR * np.median(dt)]
    assert rec.gaps == expected and rec.gaps == tuple(expected) and list(rec.gaps) == expected
    assert len(rec.gaps) == len(expected) and bool(rec.gaps) == bool(expected)
    assert rec.gaps[1:] == expected[1:] and pickle.loads(pickle.dumps(rec.gaps)) == rec.gaps
    longest = max(expected, key=lambda g: g.duration_s) if expected else None
    assert rec.gaps.longest() == longest
    assert rec.gaps != expected[:-1] if expected else rec.gaps == ()


def test_the_gaps_of_a_day_of_burst_stamped_samples_are_arrays_not_millions_of_objects():
    """A day at 100 Hz stamped on arrival five samples at a time: 1.7 million gaps, kept as three arrays (one Gap
    object each took 3.2 s and 230 MB more here); the stretches between them and the first gap read from them."""
    rec = burst_stamped_recording(100.0, 8_640_000, 5, 2e-3)
    assert len(rec.gaps) == 8_640_000 // 5 - 1
    first = rec.gaps[0]
    assert first.after_row == 5 and first.start_s == pytest.approx(0.048) and first.duration_s == pytest.approx(0.042)
    assert rec.gaps.after_rows.nbytes + rec.gaps.starts_s.nbytes + rec.gaps.durations_s.nbytes < 50e6
    stretches = rec.contiguous_stretches()
    assert len(stretches) == len(rec.gaps) + 1 and {s.stop - s.start for s in stretches} == {5}


def test_step_of_two_periods_is_not_a_gap():
    t = np.array([0.0, 0.01, 0.02, 0.04, 0.05, 0.06])
    assert make(t).gaps == ()


def test_per_axis_temperature_and_take():
    t = np.arange(10.0)
    temps = np.column_stack([t, t + 1])
    rec = Recording(time_s=t, gyro_dps=np.zeros((10, 2)), gyro_axes=("gyro_x", "gyro_z"), temperature_degc=temps)
    assert rec.temperature_columns == ("temperature_x", "temperature_z")
    np.testing.assert_array_equal(rec.temperature_for("gyro_z"), t + 1)
    part = rec.take(slice(2, 5))
    np.testing.assert_array_equal(part.row_numbers, [3, 4, 5])
    with pytest.raises(InputError, match="no gyro axis 'gyro_y'; this recording has gyro_x, gyro_z"):
        rec.gyro("gyro_y")


def test_shape_mismatch_and_too_short():
    with pytest.raises(InputError, match=r"gyro data has shape \(3, 2\), expected \(3, 1\)"):
        make([0.0, 1.0, 2.0], gyro=np.zeros((3, 2)))
    with pytest.raises(InputError, match="at least 2 rows"):
        make([0.0])


def test_missing_temperature_message():
    with pytest.raises(InputError, match="no temperature column.*columns={'temperature': 'NAME'}"):
        make([0.0, 1.0]).temperature_for("gyro_z")


def test_temperature_column_for_axis():
    t = np.arange(5.0)
    one = Recording(time_s=t, gyro_dps=np.zeros((5, 2)), gyro_axes=("gyro_x", "gyro_z"), temperature_degc=t)
    assert one.temperature_column_for("gyro_z") == "temperature"
    per_axis = Recording(
        time_s=t, gyro_dps=np.zeros((5, 2)), gyro_axes=("gyro_x", "gyro_z"), temperature_degc=np.column_stack([t, t])
    )
    assert per_axis.temperature_column_for("gyro_z") == "temperature_z"


def test_with_gyro_checks_only_the_new_data_and_keeps_the_rest():
    time_s = np.r_[np.arange(100) * 0.1, 30.0 + np.arange(50) * 0.1]  # one gap
    rec = Recording(
        time_s, np.zeros((150, 2)), ("gyro_x", "gyro_z"), temperature_degc=np.full(150, 20.0), source="run.csv"
    )
    new = rec.with_gyro(np.ones((150, 2)))
    assert new.gyro_dps.sum() == 300 and rec.gyro_dps.sum() == 0
    assert new.time_s is rec.time_s and new.gaps == rec.gaps and new.rate_hz == rec.rate_hz
    with pytest.raises(InputError, match=r"run.csv: gyro data has shape \(150, 3\), expected \(150, 2\)"):
        rec.with_gyro(np.ones((150, 3)))
    bad = np.ones((150, 2))
    bad[120, 1] = np.nan
    with pytest.raises(InputError, match=r"run.csv: row 121, column 'gyro_z': nan is not a finite number"):
        rec.with_gyro(bad)
