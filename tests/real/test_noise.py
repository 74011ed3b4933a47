"""Noise parameters of real static recordings (../shared/datasets), next to what their makers state."""

import warnings

import numpy as np
import pytest

from gyrocomp.allan import allan_deviation, noise_parameters

from ..conftest import shared_dataset
from .real_data import GALAXY_FIT_TAUS_S, noise_table

pytestmark = pytest.mark.real


@pytest.fixture(scope="module")
def adis():
    shared_dataset("smac-imudata-adis16405")
    pytest.importorskip("rdata", reason="reading .rda needs the [test] extra (rdata)")
    from .real_data import adis_sessions

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # rdata: no constructor for R class "imu"
        return adis_sessions()


@pytest.mark.slow
def test_adis16405_matches_its_datasheet(adis):
    """ADIS16405 datasheet: angle random walk 2 deg/sqrt(h), in-run bias stability 25 deg/h (typical)."""
    assert len(adis) == 6
    arw, readoff, bias = [], [], []
    for gyro in adis.values():
        assert gyro.shape == (1_000_000, 3)
        for n in noise_table(gyro, 100.0):
            arw.append(n.arw_deg_per_sqrt_h)
            readoff.append(60 * n.noise_density_readoff_dps_per_sqrt_hz)
            bias.append(n.bias_instability_deg_per_h)
    # white noise is measured with intervals of 0.2 % at tau = 0.01 s: every session and axis lands within
    # 25 % of the typical figure, and the fit agrees with the -1/2 read-off to 15 %
    np.testing.assert_allclose(arw, 2.0, rtol=0.25)
    np.testing.assert_allclose(arw, readoff, rtol=0.15)
    # the bias floor is "typical 25 deg/h"; these units sit between that and twice it
    assert 20.0 < min(bias) and max(bias) < 55.0
    # six sessions of one unit repeat each other: the spread of ARW per axis is a few per cent
    per_axis = np.array(arw).reshape(6, 3)
    assert (per_axis.std(axis=0) / per_axis.mean(axis=0) < 0.05).all()


def test_galaxy_s5_phone_gyro():
    folder = shared_dataset("skdivemove-galaxy-s5-static")
    pytest.importorskip("h5py", reason="reading NetCDF needs the [test] extra (h5py)")
    from .real_data import galaxy_gyro_dps

    gyro = galaxy_gyro_dps()
    assert gyro.shape == (214_800, 3) and folder.is_dir()
    whole = [noise_parameters(allan_deviation(gyro[:, j], 10.0)) for j in range(3)]
    past_filter = noise_table(gyro, 10.0, GALAXY_FIT_TAUS_S)
    for full, fitted in zip(whole, past_filter):
        # the 10 Hz decimation filter bends the short taus: over the whole curve the five-term model
        # misses by more than 50 % and its N is far below the -1/2 read-off ...
        assert full.fit_rms_log_residual > 0.5
        assert full.noise_density_dps_per_sqrt_hz < 0.2 * full.noise_density_readoff_dps_per_sqrt_hz
        # ... past the filter it fits to 10 % and agrees with the read-off to 25 %
        assert fitted.fit_rms_log_residual < 0.1
        assert fitted.noise_density_dps_per_sqrt_hz == pytest.approx(
            fitted.noise_density_readoff_dps_per_sqrt_hz, rel=0.25
        )
        assert 10.0 < fitted.bias_instability_deg_per_h < 50.0


def test_adis16405_bound_is_above_every_session_and_beside_its_datasheet(adis):
    """The noise bounds of each session and axis: at or above the measured curve up to a tenth of the record;
    white noise and random walk alone pay for the flicker floor they cannot follow (N 1.0 to 1.6 times the IEEE
    952 fit's, the angle random walk 1 to 2 times the datasheet's 2 deg/sqrt(h)), the Gauss-Markov terms bring it
    back near the curve (the table: python -m tests.real.real_data bound)."""
    from gyrocomp.allan.bound import bound_noise

    ratios = []
    for gyro in adis.values():
        for j in range(3):
            curve = allan_deviation(gyro[:, j], 100.0)
            bounded = curve.tau <= 1000.0  # a tenth of the 2.78 h record
            two = bound_noise(curve, markov=False, max_tau_s=1000.0)
            full = bound_noise(curve, max_tau_s=1000.0)
            for bound in (two, full):
                assert np.all(bound.deviation(curve.tau[bounded]) >= curve.deviation[bounded])
            ratios.append(two.white_noise_density / noise_parameters(curve).noise_density_dps_per_sqrt_hz)
            assert 2.0 <= 60 * two.white_noise_density < 4.0
            assert full.ratio_median < 1.5
    assert 1.0 <= min(ratios) and max(ratios) < 1.6
