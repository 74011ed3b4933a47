"""gyrocomp.fit, the one fit entry point: runs and typed options in; the other entry points wrap it."""

import warnings

import numpy as np
import pytest

import gyrocomp
from gyrocomp.errors import InputError
from gyrocomp.models.options import FitOptions
from gyrocomp.models.pipelines import fit_calibration
from gyrocomp.simulation import get_profile, simulate


@pytest.fixture(scope="module")
def runs():
    prof = get_profile("cycle", set_points_degc=(-10.0, 50.0), cycles=1)
    return [simulate("consumer", profile=prof, duration_s=3600, rate_hz=2, seed=s).recording for s in range(2)]


def _same(a, b):
    assert a.model == b.model and set(a.axes) == set(b.axes)
    for axis in a.axes:
        t = np.linspace(-10.0, 50.0, 13)
        np.testing.assert_allclose(a.axes[axis].temperature.shape(t), b.axes[axis].temperature.shape(t), atol=1e-12)
        np.testing.assert_allclose(a.axes[axis].turn_on_biases, b.axes[axis].turn_on_biases, atol=1e-12)


def test_the_entry_point_is_the_keyword_call_with_its_options_typed(runs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _same(gyrocomp.fit(runs), fit_calibration(runs))
        _same(gyrocomp.fit(runs, FitOptions(hysteresis="none")), fit_calibration(runs, hysteresis="none"))
        both = gyrocomp.fit(runs, FitOptions(hysteresis="none"), channels=("gyro", "accel"))
    assert set(both.axes) == {"gyro_x", "gyro_y", "gyro_z"} and set(both.accel_axes) == {"accel_x", "accel_y",
                                                                                            "accel_z"}


def test_the_channel_is_said_not_guessed(runs):
    with pytest.raises(InputError, match="channels"):
        gyrocomp.fit(runs, channels=("magnetometer",))
