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


def brute_force(kind, y, rate_hz, m):
    """Each estimator term by term from averages of m rate samples (Riley, NIST SP 1065, section 5.2)."""
    tau = m / rate_hz
    avg = lambda i: y[i:i + m].mean()  # noqa: E731
    if kind in ("adev", "oadev"):
        step = m if kind == "adev" else 1
        terms = [(avg(i + m) - avg(i)) ** 2 / 2 for i in range(0, y.size - 2 * m + 1, step)]
        return np.sqrt(np.mean(terms)), len(terms)
    if kind in ("hdev", "ohdev"):
        step = m if kind == "hdev" else 1
        terms = [(avg(i + 2 * m) - 2 * avg(i + m) + avg(i)) ** 2 / 6 for i in range(0, y.size - 3 * m + 1, step)]
        return np.sqrt(np.mean(terms)), len(terms)
    # modified Allan: the Allan term of averages, itself averaged over m consecutive starts
    terms = [np.mean([avg(i + m) - avg(i) for i in range(j, j + m)]) ** 2 / 2 for j in range(y.size - 3 * m + 2)]
    mdev = np.sqrt(np.mean(terms))
    return (mdev if kind == "mdev" else tau * mdev / np.sqrt(3)), len(terms)


@pytest.mark.parametrize("kind", ["adev", "oadev", "mdev", "tdev", "hdev", "ohdev"])
def test_every_kind_matches_its_definition(kind):
    rng = np.random.default_rng(2)
    y = rng.standard_normal(300).cumsum() * 0.02 + rng.standard_normal(300)
    res = allan_deviation(y, 2.0, kind=kind, taus="all")
    assert res.kind == kind and len(res.tau) > 10
    for tau, dev, n in zip(res.tau, res.deviation, res.n):
        ref, count = brute_force(kind, y, 2.0, int(round(tau * 2.0)))
        assert n == count
        assert dev == pytest.approx(ref, rel=1e-9)


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


def load_series(path):
    """One number per line, '#' comments, gzip allowed."""
    import gzip

    opener = gzip.open if path.suffix == ".gz" else open
    with opener(path, "rt") as fh:
        return np.array([float(line.split()[0]) for line in fh if line.strip() and not line.lstrip().startswith("#")])


# (data file, data type, rate [Hz], result file, kind, relative tolerance on the deviation)
STABLE32_FILES = [
    *[("phasedat/PHASE.DAT", "phase", 1.0, f"phasedat/phase_dat_{k}_octave.txt", k, 1e-4)
      for k in ("adev", "oadev", "mdev", "tdev", "hdev", "ohdev")],
    *[("phasedat/PHASE.DAT", "phase", 1.0, f"phasedat/phase_dat_{k}.txt", k, 1e-4)
      for k in ("adev", "oadev", "mdev", "tdev", "hdev", "ohdev")],
    ("gps/gps_1pps_phase_data.txt.gz", "phase", 1.0, "gps/stable32_ADEV_decade.txt", "adev", 1e-4),
    *[("gps/gps_1pps_phase_data.txt.gz", "phase", 1.0, f"gps/stable32_{k.upper()}_octave.txt", k, 1e-4)
      for k in ("oadev", "mdev", "tdev", "hdev", "ohdev")],
    *[("Cs5071A/5071A_phase.txt.gz", "phase", 1.0, f"Cs5071A/{k}_decade.txt", k, 1e-4)
      for k in ("adev", "oadev", "mdev", "tdev", "hdev", "ohdev")],
    *[("Keysight53230A_ti_noise_floor/tic_phase.txt", "phase", 1.0, f"Keysight53230A_ti_noise_floor/tic_{k}.txt", k, 1e-4)
      for k in ("adev", "oadev", "mdev", "tdev", "hdev", "ohdev")],
    # the Stable32 input was normalised slightly differently (README: agreement about 1.2e-3)
    *[("ocxo/ocxo_frequency.txt", "ocxo", 1.0, f"ocxo/{k}_octave.txt", k, 2e-3)
      for k in ("adev", "oadev", "mdev", "tdev", "hdev", "ohdev")],
    # Stable32 ran this one with tau0 = 42 s
    *[("pink_frequency/pink_frequency.txt", "rate", 1.0 / 42, f"pink_frequency/{k}.txt", k, 1e-4)
      for k in ("adev", "oadev", "mdev", "tdev", "hdev", "ohdev")],
]
_SERIES_CACHE = {}


@pytest.mark.parametrize("data_file,data_type,rate_hz,result_file,kind,rtol", STABLE32_FILES,
                         ids=[f[3] for f in STABLE32_FILES])
def test_matches_stable32_row_by_row(data_file, data_type, rate_hz, result_file, kind, rtol):
    folder = shared_dataset("allantools-stable32")
    if data_file not in _SERIES_CACHE:
        _SERIES_CACHE[data_file] = load_series(folder / data_file)
    data = _SERIES_CACHE[data_file]
    if data_type == "ocxo":
        data, data_type = (data - 1e7) / 1e7, "rate"
    ref = read_columns(folder / result_file)
    res = allan_deviation(data, rate_hz, kind=kind, taus=ref[:, 0] / rate_hz, data_type=data_type)
    np.testing.assert_array_equal(res.n, ref[:, 2].astype(int))
    np.testing.assert_allclose(res.tau, ref[:, 0] / rate_hz, rtol=1e-12)
    np.testing.assert_allclose(res.deviation, ref[:, 5], rtol=rtol)


@pytest.mark.parametrize("kind", ["adev", "oadev", "mdev", "tdev", "hdev", "ohdev"])
@pytest.mark.parametrize("dataset,data_file,data_type", [
    ("nbs14_10", "nbs14_10point_phase.txt", "phase"),
    ("nbs14_10", "nbs14_10point_freq.txt", "rate"),
    ("nbs14_1000", "nbs14_1000point_freq.txt", "rate"),
])
def test_nbs14_published_values(kind, dataset, data_file, data_type):
    folder = shared_dataset("allantools-stable32") / "nbs14"
    data = read_columns(folder / data_file)[:, 0]
    ref = {float(t): float(v) for d, stat, t, v, *_ in
           (line.split() for line in (folder / "nbs14_reference_values.txt").read_text().splitlines()
            if line.strip() and not line.startswith("#"))
           if d == dataset and stat == kind.upper()}
    assert ref, f"no {kind.upper()} reference for {dataset}"
    res = allan_deviation(data, 1.0, kind=kind, taus=np.array(sorted(ref)), data_type=data_type)
    assert len(res.tau) == len(ref)
    for tau, dev in zip(res.tau, res.deviation):
        assert dev == pytest.approx(ref[tau], rel=1e-4), tau


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
    with pytest.raises(InputError, match=r"kind: unknown Allan estimator 'xdev'; use one of oadev, adev, mdev"):
        allan_deviation(np.zeros(10), 1.0, kind="xdev")
    with pytest.raises(InputError, match=r"taus: unknown grid 'weekly'"):
        allan_deviation(np.zeros(10), 1.0, taus="weekly")
    with pytest.raises(InputError, match=r"rate_hz: must be positive"):
        allan_deviation(np.zeros(10), 0.0)
    with pytest.raises(InputError, match=r"taus: no tau fits the data"):
        allan_deviation(np.zeros(10), 1.0, taus=np.array([100.0]))
    with pytest.raises(InputError, match=r"data_type: 'angle'"):
        allan_deviation(np.zeros(10), 1.0, data_type="angle")
