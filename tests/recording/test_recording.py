import numpy as np
import pytest

from gyrocomp.errors import InputError
from gyrocomp.recording import Recording


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
