"""Power-law noise type of phase data at each averaging factor, as Stable32 identifies it.

With at least 30 decimated points: the lag-1 autocorrelation (W. Riley and C. Greenhall, "Power law noise
identification using the lag 1 autocorrelation", EFTF 2004). With fewer: the B1 ratio of the standard to
the Allan variance (D. Howe, R. Beard, C. Greenhall, W. Riley, "A total estimator of the Hadamard function
used for GPS operations", PTTI 2000, Tables 3-4; NIST SP 1065 section 5.6), which cannot tell white from
flicker PM, so that pair is split by R(n) = MVAR/AVAR (NIST TN 1337 A-6).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .estimators import BLOCK_SAMPLES, ESTIMATORS, PhaseGrids, second_difference_sum

#: fewest decimated points for which the lag-1 autocorrelation identifies a noise type (Riley 2004)
NOISE_ID_MIN_POINTS = 30
#: and the most it uses (a contiguous stretch from the start; see identify_noise)
NOISE_ID_MAX_POINTS = 1 << 18


@dataclass(frozen=True)
class NoiseIdentification:
    """Power-law noise type at one averaging factor.

    ``alpha`` is the integer exponent of S_y(f) ~ f^alpha. ``method`` says how it was found: "lag1" (the
    lag-1 autocorrelation; ``alpha_estimate`` is then the unrounded value, ``differences`` how often the
    decimated phase was differenced, ``rho`` the ratio r1/(1+r1)), "b1" (the B1 ratio, in ``ratio``) or
    "rn" (B1 found white or flicker PM and R(n), in ``ratio``, chose between them); the lag-1 fields are
    NaN (``differences`` -1) for those.
    """

    alpha: int
    alpha_estimate: float
    differences: int
    rho: float
    method: Literal["lag1", "b1", "rn"] = "lag1"
    ratio: float = math.nan


def _trend_gram(length: int) -> np.ndarray:
    """sum_k u^(p+q), p, q = 0..2, for u = 2k/(L-1) - 1, k = 0..L-1 (exact power sums of k, then rescaled)."""
    n = length
    power_sums = [
        n,
        n * (n - 1) // 2,
        (n - 1) * n * (2 * n - 1) // 6,
        (n * (n - 1) // 2) ** 2,
        (n - 1) * n * (2 * n - 1) * (3 * (n - 1) ** 2 + 3 * (n - 1) - 1) // 30,
    ]
    scale = 2.0 / (n - 1)
    u_sums = [
        sum(math.comb(p, j) * scale**j * (-1.0) ** (p - j) * power_sums[j] for j in range(p + 1)) for p in range(5)
    ]
    return np.array([[u_sums[p + q] for q in range(3)] for p in range(3)])


def _quadratic_trend(x: np.ndarray, u: np.ndarray, u2: np.ndarray) -> np.ndarray:
    """Least-squares coefficients of c0 + c1 u + c2 u^2 fitted to x, for u = 2k/(L-1) - 1 (k = 0..L-1), u2 = u^2."""
    moments = np.array([x.sum(), np.dot(u, x), np.dot(u2, x)])
    return np.linalg.solve(_trend_gram(len(x)), moments)


def _lag1_autocorrelations(x: np.ndarray, max_differences: int) -> list[float]:
    """Lag-1 autocorrelation of the residual of x about its quadratic trend, differenced 0..max times.

    The residual z (and each difference of it) is not centred by a pass of its own: with S = sum z and
    mu = S / L, r1 = (sum z_i z_(i+1) - mu (2 S - z_0 - z_(L-1)) + (L - 1) mu^2) / (sum z^2 - L mu^2), where mu
    is small against z (the trend has a constant; a difference's mean is its end points' difference over L)."""
    u = np.linspace(-1.0, 1.0, len(x))
    u2 = u * u
    c0, c1, c2 = _quadratic_trend(x, u, u2)
    z = np.multiply(u2, c2, out=u2)  # the trend, in u2's place
    z += u * c1
    z += c0
    np.subtract(x, z, out=z)
    result = []
    for d in range(max_differences + 1):
        if d:
            z = z[1:] - z[:-1]
        size = z.size
        total = float(z.sum())
        mean = total / size
        denominator = float(np.dot(z, z)) - size * mean * mean
        numerator = (
            float(np.dot(z[:-1], z[1:])) - mean * (2.0 * total - float(z[0]) - float(z[-1])) + (size - 1) * mean * mean
        )
        result.append(numerator / denominator if denominator > 0 else math.nan)
    return result


def identify_noise(phase, m: int, *, max_differences: int = 2) -> NoiseIdentification | None:
    """Power-law noise type of phase data at averaging factor m, by the lag-1 autocorrelation.

    The phase is decimated by m, its quadratic trend removed, and it is differenced until the
    autocorrelation ratio rho = r1 / (1 + r1) falls below 0.25 (or ``max_differences`` is reached);
    then alpha = 2 - 2 (rho + d), rounded (Riley and Greenhall 2004). Returns None with fewer than
    30 decimated points. At most the first 2^18 decimated points are used: the lag-1 estimate's
    standard error there (2e-3) is far inside the rounding margin (types change every 0.25 of rho), every
    Stable32 reference file agrees as with 2^20, and it keeps the identification a fraction of the deviations'
    cost on long series.
    """
    x = np.asarray(phase[: NOISE_ID_MAX_POINTS * m : m], dtype=np.float64)  # at most 2 MiB, whatever the phase
    if len(x) < NOISE_ID_MIN_POINTS:
        return None
    correlations = _lag1_autocorrelations(x, max_differences)
    for d, r1 in enumerate(correlations):
        if math.isnan(r1):
            return None  # a constant (or exactly polynomial) series has no noise type
        rho = r1 / (1.0 + r1)
        if rho < 0.25 or d == max_differences:
            break
    estimate = 2.0 - 2.0 * (rho + d)
    return NoiseIdentification(
        alpha=int(2 - np.round(2.0 * rho) - 2 * d), alpha_estimate=estimate, differences=d, rho=rho
    )


# --- fewer than 30 points: the B1 ratio and R(n) ------------------------------------------------------------


def b1_expected(n_points: int, mu: int) -> float:
    """Expected B1 ratio (standard over Allan variance) of ``n_points`` frequency averages of a noise whose
    Allan variance goes as tau^mu: N(1 - N^mu) / (2(N-1)(1 - 2^mu)), with its limits at mu = 0 and -1
    (Howe et al. 2000, Table 3)."""
    n = float(n_points)
    if mu == 0:
        return n * math.log(n) / (2.0 * (n - 1.0) * math.log(2.0))
    if mu == -1:
        return 1.0
    return n * (1.0 - n**mu) / (2.0 * (n - 1.0) * (1.0 - 2.0**mu))


def rn_expected(m: int, alpha: Literal[1, 2]) -> float:
    """Expected R(n) = MVAR/AVAR at averaging factor m: 1/m for white PM; 3.37 / (1.04 + 3 ln(pi m)) for
    flicker PM with the measurement bandwidth at the Nyquist frequency (NIST TN 1337, A-6, Table 2)."""
    return 1.0 / m if alpha == 2 else 3.37 / (1.04 + 3.0 * math.log(math.pi * m))


#: starts per averaging factor at which R(n)'s modified variance is evaluated (at least; see _grid_step)
RN_STARTS_PER_M = 64


def _grid_step(m: int) -> int:
    """The step g of the starts R(n) uses: m / d for the smallest divisor d of m that is at least
    ``RN_STARTS_PER_M`` (m itself when none is: every start, as the overlapping estimator has)."""
    d = next((d for d in range(RN_STARTS_PER_M, m + 1) if m % d == 0), m) if m > RN_STARTS_PER_M else m
    return m // d


def modified_variance_on_grid(phase, m: int, grids: PhaseGrids | None = None) -> float:
    """The modified Allan variance at averaging factor m (tau = m samples, per sample squared, as
    ``identify_noise_b1``'s Allan variance), its overlapping sum taken at every g-th start only (g from
    :func:`_grid_step`: at least ``RN_STARTS_PER_M`` starts per m), NaN where no term fits.

    With X the running sum of the phase about its mean, the inner sum of a modified-variance term is
    D(i) = X(i+3m) - 3 X(i+2m) + 3 X(i+m) - X(i); for starts i on a grid of step g dividing m, every X it needs is
    on the grid too, so X is needed there only: one pass over the phase gives its sums over blocks of g, and
    their running sum is X on the grid (:class:`PhaseGrids`; ``grids`` shares them between factors, so that
    nested grids cost one pass in all). Mod sigma^2 = sum D^2 / (2 m^4 count) (NIST SP 1065 eq. 14).
    """
    n = len(phase)
    if n - 3 * m + 1 < 1:
        return math.nan
    g = _grid_step(m)
    grid = (PhaseGrids(phase) if grids is None else grids).running_sum(g)
    d = m // g
    starts = (n - 3 * m) // g + 1  # grid starts i = 0, g, ... with i + 3m <= n
    x = grid[: starts + 3 * d]
    terms = x[3 * d : 3 * d + starts] - 3.0 * x[2 * d : 2 * d + starts] + 3.0 * x[d : d + starts] - x[:starts]
    return float(np.dot(terms, terms) / (2.0 * float(m) ** 4 * starts))


def identify_noise_b1(phase, m: int, grids: PhaseGrids | None = None) -> NoiseIdentification | None:
    """Noise type at averaging factor m from the B1 ratio, for series too short for the lag-1 method.

    The N = (len(phase) - 1) // m frequency averages at m have their linear drift removed (as the lag-1
    method removes the quadratic phase trend); B1 is their standard variance over their Allan variance. The
    Allan variance's exponent mu is the one whose expected B1 lies nearest on a log scale (boundaries at
    the geometric means, Howe et al. 2000, Table 4), alpha = -mu - 1. mu = -2 (white or flicker PM) is
    split by R(n) = MVAR/AVAR (MVAR of the whole series, :func:`modified_variance_on_grid`) against the geometric
    mean of the two expected values (``grids``: see :func:`modified_variance_on_grid`).
    Returns None with fewer than 3 averages or a series without variation.
    """
    n_points = (len(phase) - 1) // m
    if n_points < 3:
        return None
    x = np.asarray(phase[: n_points * m + 1 : m], dtype=np.float64)
    averages = np.diff(x) / m
    k = np.arange(n_points, dtype=np.float64)
    residual = averages - np.polyval(np.polyfit(k, averages, 1), k)
    allan = 0.5 * float(np.mean(np.diff(averages) ** 2))
    if not allan > 0:
        return None
    ratio = float(np.var(residual, ddof=1)) / allan
    mu = -2
    for candidate in (2, 1, 0, -1):
        if ratio > math.sqrt(b1_expected(n_points, candidate) * b1_expected(n_points, candidate - 1)):
            mu = candidate
            break
    if mu > -2:
        return NoiseIdentification(
            alpha=-mu - 1, alpha_estimate=math.nan, differences=-1, rho=math.nan, method="b1", ratio=ratio
        )
    rn = modified_variance_on_grid(phase, m, grids) / allan  # the ADEV at m is the Allan variance of these averages
    if not math.isfinite(rn):
        return None
    alpha = 1 if rn > math.sqrt(rn_expected(m, 1) * rn_expected(m, 2)) else 2
    return NoiseIdentification(
        alpha=alpha, alpha_estimate=math.nan, differences=-1, rho=math.nan, method="rn", ratio=rn
    )


#: a lag-1 identification from fewer decimated points than this is cross-checked with R(n) of the whole series
RN_CHECK_MAX_POINTS = 100
#: R(n) = MVAR/AVAR expected for white, flicker and random-walk FM, any long averaging factor (NIST TN 1337,
#: A-6, Table 2); phase noise's R(n) falls with m (:func:`rn_expected`)
RN_FREQUENCY_NOISE = {0: 0.50, -1: 0.67, -2: 0.82}


def overlapping_allan_variance(phase, m: int) -> float:
    """The overlapping Allan variance at averaging factor m from every term of the series (per sample squared, as
    :func:`modified_variance_on_grid`): sum of (x[i+2m] - 2 x[i+m] + x[i])^2 over 2 m^2 count; NaN where no term
    fits."""
    count = len(phase) - 2 * m
    if count < 1:
        return math.nan
    return second_difference_sum(phase, m, 1, count, np.empty(BLOCK_SAMPLES)) / (2.0 * float(m) ** 2 * count)


def _rn_checked(
    alphas: np.ndarray, methods: list[str], points: list, phase, ms: np.ndarray, lowest: int, grids: PhaseGrids
) -> np.ndarray:
    """Where a lag-1 phase-noise type (white or flicker PM) rests on few decimated points (< RN_CHECK_MAX_POINTS),
    R(n) = MVAR/AVAR of the whole series at that m (every term, not the few points) decides between the phase
    noises and frequency noise: the type whose expected R(n) lies nearest on a log scale (``methods`` then says
    so). On 56 points the lag-1 statistic can call white FM white PM, whose interval would be far too narrow;
    R(n) from half a million terms tells them apart by a factor of a thousand."""
    out = alphas.copy()
    for j, m in enumerate(int(m) for m in ms):
        if points[j] is None or points[j] >= RN_CHECK_MAX_POINTS or not alphas[j] >= 1:
            continue
        allan = overlapping_allan_variance(phase, m)
        rn = modified_variance_on_grid(phase, m, grids) / allan if allan > 0 else math.nan
        if not math.isfinite(rn) or not rn > 0:
            continue
        expected = {
            2: rn_expected(m, 2),
            1: rn_expected(m, 1),
            **{a: r for a, r in RN_FREQUENCY_NOISE.items() if a >= lowest},
        }
        nearest = min(expected, key=lambda a: abs(math.log(rn / expected[a])))
        if nearest != alphas[j]:
            out[j] = float(nearest)
            methods[j] = f"R(n) {rn:.3g} (lag-1 said {int(alphas[j]):+d})"
    return out


@dataclass(frozen=True)
class NoiseTypes:
    """The noise type at each averaging factor: ``alpha`` (NaN where none) and the ``method`` that decided it:
    ``lag-1``, ``B1/R(n)``, ``slope ...`` (the curve's slope overruled a lag-1 type on few points), ``carried``
    (the type of the next shorter tau) or ``""`` (none)."""

    alpha: np.ndarray
    method: tuple[str, ...]


def noise_types(kind: str, phase, ms: np.ndarray) -> NoiseTypes:
    """alpha at each averaging factor in ``ms`` (ascending), as Stable32 identifies it, and how.

    The lag-1 autocorrelation where 30 decimated points remain, the B1 ratio with R(n) below that. A B1
    type is capped by the type found at the next shorter tau: in a sum of independent power-law noises the
    dominant exponent can only fall as tau grows, and the lag-1 type from many points is the better
    determined. Where neither method applies the type found at the next shorter tau is carried forward.
    Types are kept within the estimator's range (alpha + 2d > 1). A lag-1 phase-noise type from fewer than
    ``RN_CHECK_MAX_POINTS`` points is cross-checked with R(n) of the whole series (:func:`_rn_checked`), the
    same evidence whatever the estimator: on 56 points the lag-1 statistic can call white FM white PM, whose
    interval would then be far too narrow.
    """
    spec = ESTIMATORS[kind]
    lowest = 2 - 2 * spec.difference_order
    alphas = np.full(len(ms), np.nan)
    methods = [""] * len(ms)
    points: list = [None] * len(ms)
    current = math.nan
    grids = PhaseGrids(phase)  # the running sums R(n) reads, shared by every factor
    for j, m in enumerate(ms):
        m = int(m)
        found = identify_noise(phase, m, max_differences=spec.difference_order)
        if found is not None:
            current = float(min(2, max(lowest, found.alpha)))
            points[j] = min((len(phase) - 1) // m + 1, NOISE_ID_MAX_POINTS)
            methods[j] = "lag-1"
        elif (few := identify_noise_b1(phase, m, grids)) is not None:
            capped = few.alpha if math.isnan(current) else min(few.alpha, current)
            current = float(min(2, max(lowest, capped)))
            methods[j] = "B1/R(n)"
        elif not math.isnan(current):
            methods[j] = "carried"
        alphas[j] = current
    alphas = _rn_checked(alphas, methods, points, phase, ms, lowest, grids)
    return NoiseTypes(alphas, tuple(methods))
