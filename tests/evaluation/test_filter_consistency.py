"""The attitude filter of the consistency check: told the truth's own noise it is consistent (time-averaged NEES
near 1, inside its band in most runs), told 10 times the noise it is over-cautious, told half over-confident."""

import numpy as np
import pytest

from gyrocomp.allan.bound import NoiseBound
from gyrocomp.errors import InputError
from gyrocomp.evaluation.filter_consistency import attitude_nees, nees_band

RATE_HZ, RUNS = 20.0, 200


def _told(white, walk, markov=()):
    return NoiseBound(white, walk, markov, (1.0,), 1.0, 1.0)


@pytest.fixture(scope="module")
def white_and_walk():
    """Gyro errors of exactly white noise N and random walk K: the filter's own model, so its truth."""
    n, rng = int(RATE_HZ * 1200), np.random.default_rng(1)
    white = rng.standard_normal((RUNS, n)) * 0.03 * np.sqrt(RATE_HZ)
    walk = np.cumsum(rng.standard_normal((RUNS, n)) * 2e-4 / np.sqrt(RATE_HZ), axis=1)
    return white + walk, 0.03, 2e-4


def test_the_band_is_that_of_a_mean_of_chi_square_samples():
    low, high = nees_band(1000)
    assert low == pytest.approx(1 - 1.96 * np.sqrt(2 / 1000), abs=0.005)
    assert high == pytest.approx(1 + 1.96 * np.sqrt(2 / 1000), abs=0.005)


def test_the_filter_told_the_truth_is_consistent_and_told_otherwise_is_not(white_and_walk):
    errors, n, k = white_and_walk
    truth = attitude_nees(errors, RATE_HZ, _told(n, k))
    assert np.median(truth.nees) == pytest.approx(1.0, abs=0.05)
    assert truth.inside >= 0.85  # 95 % for independent samples; the epochs' errors are correlated
    cautious = attitude_nees(errors, RATE_HZ, _told(10 * n, 10 * k))
    assert np.all(cautious.nees < cautious.band[0])
    confident = attitude_nees(errors, RATE_HZ, _told(n / 2, k / 2))
    assert np.all(confident.nees > confident.band[1])


def test_a_gauss_markov_term_the_truth_has_is_carried(white_and_walk):
    """A first-order Gauss-Markov bias added to the truth: told it, the filter stays consistent; told only the
    white noise and random walk, it is over-confident."""
    errors, n, k = white_and_walk
    sigma, tau = 0.01, 60.0
    steps = errors.shape[1]
    phi = np.exp(-1.0 / (RATE_HZ * tau))
    drive = np.random.default_rng(2).standard_normal((RUNS, steps)) * sigma * np.sqrt(1 - phi**2)
    markov = np.empty_like(drive)
    markov[:, 0] = np.random.default_rng(3).standard_normal(RUNS) * sigma
    for i in range(1, steps):
        markov[:, i] = phi * markov[:, i - 1] + drive[:, i]
    with_markov = errors + markov
    told = attitude_nees(with_markov, RATE_HZ, _told(n, k, ((sigma, tau),)))
    assert np.median(told.nees) == pytest.approx(1.0, abs=0.1)
    blind = attitude_nees(with_markov, RATE_HZ, _told(n, k))
    assert np.median(blind.nees) > told.band[1]


def test_too_short_a_record_is_refused():
    with pytest.raises(InputError, match=r"update_period_s: 2 s leaves fewer than two updates after the burn-in"):
        attitude_nees(np.zeros((2, 40)), RATE_HZ, _told(0.01, 0.0))


def test_a_filter_told_the_noise_at_each_temperature_is_consistent_where_one_constant_is_not():
    """White noise that doubles from one end of a ramp to the other: scheduled by the temperature it is told the
    truth at each period (consistent); told the hottest end's throughout, it is over-cautious."""
    n = int(RATE_HZ * 1200)
    temperature = np.linspace(0.0, 60.0, n)
    density = 0.02 * (1.0 + temperature / 60.0)
    errors = np.random.default_rng(4).standard_normal((RUNS, n)) * density * np.sqrt(RATE_HZ)
    scheduled = attitude_nees(
        errors,
        RATE_HZ,
        _told(0.04, 1e-9),
        temperature_degc=temperature,
        schedule=lambda t: _told(0.02 * (1.0 + t / 60.0), 1e-9),
    )
    assert np.median(scheduled.nees) == pytest.approx(1.0, abs=0.05)
    constant = attitude_nees(errors, RATE_HZ, _told(0.04, 1e-9))
    assert np.median(constant.nees) < constant.band[0]
    with pytest.raises(InputError, match=r"schedule: needs temperature_degc"):
        attitude_nees(errors, RATE_HZ, _told(0.04, 1e-9), schedule=lambda t: _told(0.04, 1e-9))


def test_the_band_widens_by_what_the_filter_says_its_errors_share():
    """A precise gyro (white noise 0.002 deg/s/sqrt(Hz)) against 0.01 deg updates: an update leaves much of the
    prior error, so successive NEES samples are correlated and the time average spreads wider than K independent
    samples would. The spread across runs of a filter told the truth is the one its own correlations predict
    (sqrt(2 / nu)), not sqrt(2 / K), and it is inside its band in about 95 % of runs."""
    runs, n = 600, int(RATE_HZ * 600)
    rng = np.random.default_rng(7)
    errors = rng.standard_normal((runs, n)) * 0.002 * np.sqrt(RATE_HZ) + rng.standard_normal((runs, 1)) * 0.01
    truth = attitude_nees(errors, RATE_HZ, _told(0.002, 0.0))
    assert truth.effective_epochs < 0.6 * truth.epochs
    predicted, independent = np.sqrt(2.0 / truth.effective_epochs), np.sqrt(2.0 / truth.epochs)
    assert np.std(truth.nees) == pytest.approx(predicted, rel=0.12)
    assert abs(np.std(truth.nees) - independent) > 0.25 * independent
    assert truth.inside >= 0.9
    assert truth.band == nees_band(truth.effective_epochs)


def test_white_noise_alone_gives_nearly_independent_samples(white_and_walk):
    errors, n, k = white_and_walk
    result = attitude_nees(errors, RATE_HZ, _told(n, k))
    assert result.epochs * 0.98 <= result.effective_epochs <= result.epochs


def test_a_scheduled_model_with_markov_terms_keeps_its_states():
    """Told the same model at every temperature the schedule is the constant filter, to the bit; a schedule whose
    Gauss-Markov correlation times change with temperature is refused (a filter cannot change its states)."""
    n = int(RATE_HZ * 600)
    errors = np.random.default_rng(5).standard_normal((20, n)) * 0.03 * np.sqrt(RATE_HZ)
    temperature = np.linspace(0.0, 60.0, n)
    model = _told(0.03, 1e-5, ((0.004, 30.0), (0.002, 300.0)))
    constant = attitude_nees(errors, RATE_HZ, model)
    scheduled = attitude_nees(errors, RATE_HZ, model, schedule=lambda t: model, temperature_degc=temperature)
    assert np.array_equal(constant.nees, scheduled.nees)
    with pytest.raises(InputError, match=r"schedule: the Gauss-Markov terms' correlation times change"):
        attitude_nees(
            errors,
            RATE_HZ,
            model,
            schedule=lambda t: _told(0.03, 1e-5, ((0.004, 30.0 if t < 30 else 60.0),)),
            temperature_degc=temperature,
        )
