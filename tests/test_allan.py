"""Allan deviation: Stable32 and NBS14 references, a brute-force definition, and noise slopes."""

import numpy as np
import pytest

from gyrocomp.allan import allan_deviation, averaging_factors, to_phase
from gyrocomp.errors import InputError

from .conftest import shared_dataset


def brute_force_oadev(rate, rate_hz, m):
    """The textbook overlapping estimator, term by term, from averages of m rate samples."""
    y = np.asarray(rate, float)
    tau = m / rate_hz
    terms = []
    for i in range(y.size - 2 * m + 1):
        a = y[i:i + m].mean()
        b = y[i + m:i + 2 * m].mean()
        terms.append((b - a) ** 2)
    return np.sqrt(0.5 * np.mean(terms)), len(terms)


def test_matches_brute_force_definition():
    rng = np.random.default_rng(1)
    y = rng.standard_normal(500).cumsum() * 0.01 + rng.standard_normal(500)
    res = allan_deviation(y, 4.0, taus="all")
    for m, tau, dev, n in zip(range(1, 200), res.tau, res.deviation, res.n):
        ref, count = brute_force_oadev(y, 4.0, m)
        assert tau == pytest.approx(m / 4.0)
        assert n == count
        assert dev == pytest.approx(ref, rel=1e-10)


def read_columns(path):
    rows = [line.split() for line in path.read_text(encoding="utf-8").splitlines()
            if line.strip() and not line.lstrip().startswith("#")]
    return np.array(rows, dtype=float)


def test_stable32_phasedat_oadev_octave():
    folder = shared_dataset("allantools-stable32")
    phase = read_columns(folder / "phasedat" / "PHASE.DAT")[:, 0]
    ref = read_columns(folder / "phasedat" / "phase_dat_oadev_octave.txt")
    res = allan_deviation(phase, 1.0, taus="octave", data_type="phase")
    np.testing.assert_array_equal(res.tau, ref[:, 1])
    np.testing.assert_array_equal(res.n, ref[:, 2].astype(int))
    np.testing.assert_allclose(res.deviation, ref[:, 5], rtol=1e-4)


def test_nbs14_1000_point_oadev():
    folder = shared_dataset("allantools-stable32")
    freq = read_columns(folder / "nbs14" / "nbs14_1000point_freq.txt")[:, 0]
    ref = {float(t): float(v) for d, s, t, v, *_ in
           (line.split() for line in (folder / "nbs14" / "nbs14_reference_values.txt").read_text().splitlines()
            if line.startswith("nbs14_1000") and line.split()[1] == "OADEV")}
    res = allan_deviation(freq, 1.0, taus=np.array(sorted(ref)))
    for tau, dev in zip(res.tau, res.deviation):
        assert dev == pytest.approx(ref[tau], rel=1e-4)


def test_white_noise_slope_and_level():
    rng = np.random.default_rng(7)
    rate_hz, density = 100.0, 0.01  # [deg/s/sqrt(Hz)]
    y = rng.standard_normal(400_000) * density * np.sqrt(rate_hz)
    res = allan_deviation(y, rate_hz)
    slope = np.polyfit(np.log(res.tau[:10]), np.log(res.deviation[:10]), 1)[0]
    assert slope == pytest.approx(-0.5, abs=0.03)
    # sigma(tau) = N / sqrt(tau): at tau = 1 s the deviation is the noise density
    one = allan_deviation(y, rate_hz, taus=np.array([1.0]))
    assert one.deviation[0] == pytest.approx(density, rel=0.02)


def test_random_walk_slope():
    rng = np.random.default_rng(8)
    k = 1e-3  # [deg/s/sqrt(s)]
    y = np.cumsum(rng.standard_normal(200_000)) * k * np.sqrt(0.1)
    res = allan_deviation(y, 10.0)
    slope = np.polyfit(np.log(res.tau[4:]), np.log(res.deviation[4:]), 1)[0]
    assert slope == pytest.approx(0.5, abs=0.06)


def test_tau_grids():
    assert list(averaging_factors(1001, "octave", 1.0)) == [1, 2, 4, 8, 16, 32, 64, 128]
    assert list(averaging_factors(10001, "decade", 1.0)) == [1, 2, 4, 10, 20, 40, 100, 200, 400, 1000, 2000]
    assert averaging_factors(101, "all", 1.0)[-1] == 25


def test_phase_of_rate_has_mean_removed():
    phase = to_phase(np.array([1.0, 2.0, 3.0]), 2.0)
    np.testing.assert_allclose(phase, [0, -0.5, -0.5, 0])


def test_errors():
    with pytest.raises(InputError, match=r"kind: unknown Allan estimator 'xdev'"):
        allan_deviation(np.zeros(10), 1.0, kind="xdev")
    with pytest.raises(InputError, match=r"taus: unknown grid 'weekly'"):
        allan_deviation(np.zeros(10), 1.0, taus="weekly")
    with pytest.raises(InputError, match=r"rate_hz: must be positive"):
        allan_deviation(np.zeros(10), 0.0)
    with pytest.raises(InputError, match=r"taus: no tau fits the data"):
        allan_deviation(np.zeros(10), 1.0, taus=np.array([100.0]))
    with pytest.raises(InputError, match=r"data_type: 'angle'"):
        allan_deviation(np.zeros(10), 1.0, data_type="angle")
