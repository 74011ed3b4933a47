"""gyrocomp.fit, the one fit entry point: runs and typed options in; the other entry points wrap it."""

import warnings

import numpy as np
import pytest

import gyrocomp
from gyrocomp.errors import InputError
from gyrocomp.models.options import FitOptions
from gyrocomp.models.joint import fit_calibration
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
    assert set(both.axes) == {"gyro_x", "gyro_y", "gyro_z"} and set(both.accel_axes) == {
        "accel_x",
        "accel_y",
        "accel_z",
    }


def test_the_channel_is_said_not_guessed(runs):
    with pytest.raises(InputError, match="channels"):
        gyrocomp.fit(runs, channels=("magnetometer",))


def test_the_runs_are_prepared_once_per_fit_whatever_the_entry_point(runs, monkeypatch):
    """One path: every entry point prepares its runs once and the stages take them prepared; a cascade's later
    stage prepares the earlier stage's output once (new data)."""
    import gyrocomp.models.accelerometer as accelerometer
    import gyrocomp.models.fit as fit_module
    import gyrocomp.models.joint as joint
    import gyrocomp.models.pipelines as pipelines
    from gyrocomp.runs.prepared import prepare

    calls = []

    def counting(recordings):
        recordings = list(recordings)
        calls.append(len(recordings))
        return prepare(recordings)

    for module in (fit_module, joint, pipelines, accelerometer):
        monkeypatch.setattr(module, "prepare", counting)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for call, expected in (
            (lambda: gyrocomp.fit(runs, FitOptions(hysteresis="none")), 1),
            (lambda: gyrocomp.fit(runs, FitOptions(hysteresis="none"), channels=("gyro", "accel")), 1),
            (lambda: gyrocomp.fit_channels(runs, ("gyro",)), 1),
            (lambda: gyrocomp.fit_pipeline(runs, "joint", FitOptions(hysteresis="none")), 1),
            (lambda: fit_calibration(runs, hysteresis="none"), 1),
            (lambda: gyrocomp.fit(runs, FitOptions(hysteresis="none"), pipeline="poly>matrix"), 2),
        ):
            calls.clear()
            call()
            assert calls == [len(runs)] * expected
