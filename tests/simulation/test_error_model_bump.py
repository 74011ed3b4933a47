"""The simulator's bump-shaped hysteresis (Hysteresis(fade_degc=F)): analytic values of the shape."""

import math

import numpy as np
import pytest

from gyrocomp.errors import InputError
from gyrocomp.simulation import GyroErrorModel, Hysteresis


def test_bump_starts_at_the_turn_peaks_and_fades_to_zero():
    h = Hysteresis(((0.2,),), direction="descending", fade_degc=25.0)
    d = np.array([0.0, 5.0, 25.0, 40.0])
    out = h.offset_dps(d, (0.2,))
    assert out[0] == 0.0 and out[2] == 0.0 and out[3] == 0.0
    assert out[1] == pytest.approx(0.2 * (1 - math.exp(-8 * 5 / 25)) * (1 - 5 / 25) ** 2, rel=1e-12)


def test_polynomial_shape_unchanged_and_bump_only_on_the_branch_after_a_cooling_turn():
    h = Hysteresis(((0.01, -0.001),), direction="descending")
    assert h.offset_dps(np.array([3.0]), (0.01, -0.001))[0] == pytest.approx(0.01 * 3 - 0.001 * 9, rel=1e-12)
    model = GyroErrorModel(
        axes=("gyro_z",),
        temperature_coefficients=((0.0,),),
        hysteresis=Hysteresis(((0.2,),), direction="descending", fade_degc=25.0),
    )
    temp = np.concatenate([np.linspace(20, 80, 601), np.linspace(80, 20, 601)[1:]])
    out = model.hysteresis_error_dps(temp)[:, 0]
    assert np.all(out[:601] == 0.0)  # heating: no turn yet
    assert out[601:].max() > 0.09 and out[-1] == 0.0  # after the turn at 80 degC, gone 25 degC below it


def test_bump_refuses_a_non_positive_fade():
    with pytest.raises(InputError, match=r"hysteresis fade_degc: must be positive and finite, got 0"):
        Hysteresis(((0.2,),), fade_degc=0.0)
