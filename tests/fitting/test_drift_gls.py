"""Least squares under slow drift (gyrocomp.fitting.drift_gls) and the flat-profile rule of the branch width."""

import numpy as np
import pytest

from gyrocomp.fitting.drift_gls import (
    DriftNoise,
    chi2_threshold,
    coarsen,
    covariance,
    fit_drift_noise,
    wald_statistic,
    whitened,
)
from gyrocomp.fitting.grid_search import plausible_middle

K = 2e-3  # random walk [unit/sqrt(s)]
SIGMA = 0.01  # white noise per point [unit]
DT_S = 5.0


def _walk(rng, n):
    """White noise plus a random walk at DT_S spacing: (time [s], series)."""
    t = np.arange(n) * DT_S
    return t, SIGMA * rng.standard_normal(n) + np.cumsum(K * np.sqrt(DT_S) * rng.standard_normal(n))


def test_the_walk_model_recovers_the_white_noise_and_the_walk():
    rng = np.random.default_rng(3)
    runs = [_walk(rng, 4000) for _ in range(3)]
    noise = fit_drift_noise([r for _, r in runs], [t for t, _ in runs], exponents=(1.0,))
    # 12000 points, the shortest lags carry thousands of increments: a few per cent, 15 % allowed
    assert noise.walk_var_per_s == pytest.approx(K**2, rel=0.15)
    assert noise.white_var == pytest.approx(SIGMA**2, rel=0.15)
    assert noise.exponent == 1.0


@pytest.mark.parametrize("alpha", [0.5, 1.0, 1.5])
def test_the_drift_exponent_and_the_variogram_are_recovered(alpha):
    """Exact draws of white noise plus fractional Brownian motion of exponent ``alpha`` (flicker-like, a walk, a
    smooth drift): the exponent and the variogram at a lag a third of the way along the recording are recovered.
    Over 8 draws of three 1500-point recordings the exponent scatters by about 0.15 and the variogram at 500 s by
    about 25 % (measured), so the means over the draws are held to 0.15 and 25 %."""
    t = np.arange(1500) * DT_S
    truth = DriftNoise(1e-4, 1e-5, alpha)
    chol = np.linalg.cholesky(covariance(t, truth))
    rng = np.random.default_rng(1)
    fits = [fit_drift_noise([chol @ rng.standard_normal(t.size) for _ in range(3)], [t] * 3) for _ in range(8)]
    assert np.mean([f.exponent for f in fits]) == pytest.approx(alpha, abs=0.15)
    lag = np.array([500.0])
    assert np.mean([f.variogram(lag)[0] for f in fits]) == pytest.approx(truth.variogram(lag)[0], rel=0.25)


def test_the_covariance_of_exponent_one_is_the_walks():
    t = np.arange(40) * DT_S + 7.0
    tau = t - t[0]
    expected = K**2 * np.minimum.outer(tau, tau) + SIGMA**2 * np.eye(t.size)
    np.testing.assert_allclose(covariance(t, DriftNoise(SIGMA**2, K**2)), expected, rtol=1e-12, atol=1e-15)


def test_a_step_between_two_halves_is_weighed_against_the_walk():
    """A step between the first and second half of a walk: ordinary least squares finds it 'significant' by
    chance in most runs; under the walk's covariance the statistic follows chi-square(1) (a 3-sigma threshold
    passed in about 0.3 % of runs), and a step ten times the walk's spread over the run is found."""
    rng = np.random.default_rng(5)
    n = 200
    step = (np.arange(n) >= n // 2).astype(float)
    x = np.column_stack([np.ones(n), step])
    noise = DriftNoise(SIGMA**2, K**2)
    null, ols = [], []
    for _ in range(200):
        t, y = _walk(rng, n)
        null.append(wald_statistic([x], [y], [t], noise, np.array([1])))
        ols.append(wald_statistic([x], [y], [t], DriftNoise(SIGMA**2, 0.0), np.array([1])))
    threshold = chi2_threshold(1)
    assert np.mean(np.asarray(ols) > threshold) > 0.5
    # chi-square(1): mean 1, and at 3 sigma a pass in 200 runs is rare (binomial: 4 or more has p < 0.1 %)
    assert np.mean(null) == pytest.approx(1.0, abs=0.3)
    assert np.sum(np.asarray(null) > threshold) <= 3
    t, y = _walk(rng, n)
    big = 10 * K * np.sqrt(n * DT_S)
    assert wald_statistic([x], [y + big * step], [t], noise, np.array([1])) > threshold


def test_whitening_makes_the_covariance_the_identity():
    t = np.arange(50) * DT_S
    noise = DriftNoise(SIGMA**2, K**2)
    cov = K**2 * np.minimum.outer(t - t[0], t - t[0]) + SIGMA**2 * np.eye(t.size)
    # whitened(x) = L^-1 x, so whitened(L) = I for the Cholesky factor L of the covariance
    chol = np.linalg.cholesky(cov)
    xw, yw = whitened(chol, chol[:, 0], t, noise)
    np.testing.assert_allclose(xw, np.eye(t.size), atol=1e-9)
    np.testing.assert_allclose(yw, np.eye(t.size)[:, 0], atol=1e-9)


def test_chi2_thresholds():
    assert chi2_threshold(1) == pytest.approx(9.0)
    assert chi2_threshold(2) == pytest.approx(11.829, abs=1e-3)  # -2 ln(0.0027)
    with pytest.raises(ValueError, match="dof: 1 or 2"):
        chi2_threshold(3)


def test_coarsen_averages_groups():
    np.testing.assert_allclose(coarsen(np.arange(7.0), 3), [1.0, 4.0, 6.0])
    np.testing.assert_allclose(coarsen(np.ones((5, 2)), 2), np.ones((3, 2)))


def test_a_flat_profile_takes_the_middle_and_a_sharp_one_its_least():
    assert plausible_middle(np.full(9, 10.0) + np.linspace(0, 1e-3, 9), independent=80) == 4
    sharp = 10.0 + (np.arange(9) - 2.0) ** 2
    assert plausible_middle(sharp, independent=80) == 2


@pytest.mark.parametrize("shape", ["even", "a shorter last block", "even then a gap", "jittered"])
def test_the_covariance_is_its_definition_on_even_and_uneven_times(shape):
    """Evenly spaced points take the Toeplitz path, the others the general one, and a series even up to a point
    both: each equals the formula written element by element."""
    rng = np.random.default_rng(5)
    t = 100.0 + np.arange(40) * DT_S
    if shape == "a shorter last block":
        t[-1] -= 0.4 * DT_S
    elif shape == "even then a gap":
        t[25:] += 3.3
    elif shape == "jittered":
        t += 0.4 * rng.uniform(-1, 1, 40)
    noise = DriftNoise(1e-4, 3e-6, 1.4)
    tau = t - t[0]
    expected = np.array([[0.5 * 3e-6 * (a**1.4 + b**1.4 - abs(a - b) ** 1.4) for b in tau] for a in tau]) + np.eye(
        t.size
    ) * max(1e-4, 3e-6 * np.median(np.diff(t)) ** 1.4 / 3.0)
    np.testing.assert_allclose(covariance(t, noise), expected, rtol=1e-12, atol=1e-18)


def test_whitening_twice_at_the_same_times_gives_the_same_and_leaves_the_input():
    rng = np.random.default_rng(6)
    t = np.arange(200) * DT_S
    x, y = rng.standard_normal((200, 3)), rng.standard_normal(200)
    noise = DriftNoise(SIGMA**2, K**2)
    first = whitened(x, y, t, noise)
    chol = np.linalg.cholesky(covariance(t, noise))
    np.testing.assert_allclose(first[0], np.linalg.solve(chol, x), rtol=1e-10, atol=1e-12)
    again = whitened(2.0 * x, y, t.copy(), noise)  # the factor kept for these times, applied to other columns
    np.testing.assert_allclose(again[0], 2.0 * first[0], rtol=1e-12, atol=1e-14)
