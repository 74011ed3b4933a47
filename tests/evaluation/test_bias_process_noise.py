"""What a calibration buys a filter's bias process noise: on a held-out cycle of a consumer part with a large
thermal drift, the raw gyro needs a bias random walk tens of times the compensated one's, and the compensated
one's is that of the noise alone (the drift the model leaves is below it)."""

import warnings

import numpy as np
import pytest

from gyrocomp import fit_calibration
from gyrocomp.allan import allan_deviation
from gyrocomp.allan.bound import bound_noise
from gyrocomp.errors import InputError
from gyrocomp.evaluation.bias_process_noise import MAX_TAU_FRACTION, bias_process_noise
from gyrocomp.simulation import get_profile, simulate


pytestmark = pytest.mark.slow  # three simulated chamber cycles and a fit


@pytest.fixture(scope="module")
def consumer():
    profile = get_profile("cycle", set_points_degc=(-10.0, 60.0), cycles=1)
    sims = [simulate("consumer", profile=profile, rate_hz=5.0, seed=s) for s in range(3)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit_calibration([s.recording for s in sims[:2]]), sims[2]


def test_the_raw_gyro_needs_far_more_bias_process_noise_than_the_compensated(consumer):
    calibration, held_out = consumer
    benefit = bias_process_noise(calibration, held_out.recording)
    assert set(benefit) == {"gyro_x", "gyro_y", "gyro_z"}
    rec = held_out.recording
    for j, (name, b) in enumerate(benefit.items()):
        noise = held_out.truth.noise.total_dps[:, j]
        alone = bound_noise(
            allan_deviation(noise - noise.mean(), rec.rate_hz),
            markov=False,
            max_tau_s=MAX_TAU_FRACTION * rec.time_s[-1],
        ).random_walk
        assert b.random_walk_ratio > 10, name
        assert 0.8 * alone <= b.compensated.random_walk <= 1.5 * alone, name


def test_axes_the_model_and_runs_do_not_share_are_refused(consumer):
    calibration, held_out = consumer
    with pytest.raises(InputError, match=r"axes: accel_x: the model and the runs share gyro_x, gyro_y, gyro_z"):
        bias_process_noise(calibration, held_out.recording, ["accel_x"])
    with pytest.raises(InputError, match=r"bias_process_noise: give at least one static run"):
        bias_process_noise(calibration, [])
    assert np.isfinite(bias_process_noise(calibration, held_out.recording, ["gyro_z"])["gyro_z"].random_walk_ratio)
