"""The turning-point hysteresis curve (thesis section 2.6) and its threshold; its fit is in test_thermal.py."""

import json

import numpy as np
import pytest

from gyrocomp.effects import find_turns
from gyrocomp.errors import InputError
from gyrocomp.curves.hysteresis import HysteresisCurve, heats_and_cools, turn_threshold_degc
from gyrocomp.recording import Recording


def test_turn_threshold_sees_noise_and_whole_degrees():
    rng = np.random.default_rng(0)
    ramp = np.linspace(20, 60, 20000)
    assert turn_threshold_degc(ramp + rng.normal(0, 0.05, ramp.size)) == pytest.approx(0.5, rel=0.1)
    assert turn_threshold_degc(np.round(ramp)) == 1.5
    assert turn_threshold_degc(ramp) == 0.1


def test_curve_offset_is_the_branch_polynomial_in_the_distance_from_the_turn():
    """Up 20 -> 80, down to 20, up to 50: on the cooling branch h_c(d), d = 80 - T; on the second heating
    branch h_h(d), d = T - 20; nothing on the first branch (the reference path) and outside the band."""
    temperature = np.concatenate([np.linspace(20, 80, 601), np.linspace(79.9, 20, 600), np.linspace(20.1, 50, 300)])
    curve = HysteresisCurve(descending=(0.01, -2e-4), ascending=(-0.005,), threshold_degc=0.5)
    offset = curve.offset(temperature, find_turns(temperature, curve.threshold_degc))
    first, cooling, heating = offset[:601], offset[601:1201], offset[1201:]
    assert np.all(first == 0.0)
    confirmed = temperature[601:1201] < 80 - 0.5  # the reversal counts once T is the threshold past the extreme
    d = 80.0 - temperature[601:1201][confirmed]
    np.testing.assert_allclose(cooling[confirmed], 0.01 * d - 2e-4 * d**2, rtol=1e-12)
    assert np.all(cooling[~confirmed] == 0.0)
    rising = temperature[1201:] > 20 + 0.5
    np.testing.assert_allclose(heating[rising], -0.005 * (temperature[1201:][rising] - 20.0), rtol=1e-12)
    banded = HysteresisCurve((0.01, -2e-4), (-0.005,), 0.5, band_degc=(55.0, 80.0))
    inside = banded.offset(temperature, find_turns(temperature, 0.5))
    np.testing.assert_array_equal(inside, np.where((temperature >= 55) & (temperature <= 80), offset, 0.0))
    assert curve.order == 2


def test_curve_dict_round_trip_and_errors():
    curve = HysteresisCurve((0.1, -0.01), (0.0, 0.0), 0.5, (55.0, 80.0))
    assert HysteresisCurve.from_dict(json.loads(json.dumps(curve.to_dict()))) == curve
    assert HysteresisCurve.from_dict(HysteresisCurve((0.1,), (0.2,), 0.3).to_dict()).band_degc is None
    reach = HysteresisCurve((0.1,), (0.2,), 0.3, None, (25.0, 12.5))
    assert HysteresisCurve.from_dict(json.loads(json.dumps(reach.to_dict()))) == reach
    assert "max_distance_degc" not in HysteresisCurve((0.1,), (0.2,), 0.3).to_dict()  # earlier files unchanged
    with pytest.raises(InputError, match="unknown hysteresis model type 'spline'"):
        HysteresisCurve.from_dict({"type": "spline"})


def test_heats_and_cools_needs_both_directions_over_the_runs():
    def run(temperature):
        n = temperature.size
        return Recording(
            time_s=np.arange(n, dtype=float),
            gyro_dps=np.zeros((n, 1)),
            gyro_axes=("gyro_z",),
            temperature_degc=temperature,
        )

    heating, cooling = run(np.linspace(20, 60, 500)), run(np.linspace(60, 20, 500))
    assert not heats_and_cools([heating], "gyro_z") and not heats_and_cools([cooling], "gyro_z")
    assert heats_and_cools([heating, cooling], "gyro_z")
