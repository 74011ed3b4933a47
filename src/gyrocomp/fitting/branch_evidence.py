"""Where the calibration data shows the branches after a temperature reversal: whether the runs heat and cool,
whether turning-point terms can be told apart from the polynomial, and the band where the branches part.

These decide which memory candidates :mod:`gyrocomp.fitting.selection` offers; they read the block means of the runs
(:class:`gyrocomp.runs.prepared.RunBlocks`) and nothing of the candidates.
"""

from __future__ import annotations

import math

import numpy as np

from ..effects import branch_position, find_turns, thermal_lag
from ..calibration.fit_report import BranchTest
from ..runs.prepared import RunBlocks
from .drift_gls import chi2_threshold, fit_drift_noise, wald_statistic
from .normal_equations import solve_normal
from .order_evidence import CoarseRuns, run_constants
from ..curves.hysteresis import parting_band_degc
from ..curves.polynomial import power_columns
from .grid_search import LAG_MAX_S, plausible_middle
from .thermal import MAX_BRANCH_ORDER
from .thermal_problem import BRANCH_WIDTHS_DEGC, SCORE_WINDOW_S


def heats_and_cools_blocks(runs: list[RunBlocks], thresholds: list[float]) -> bool:
    """Whether the runs' blocks hold both a heating and a cooling stretch."""
    directions = [find_turns(r.temperature_degc, th).direction for r, th in zip(runs, thresholds)]
    return any(np.any(d > 0) for d in directions) and any(np.any(d < 0) for d in directions)


#: the least share of a branch after a reversal (time-weighted) that must lie at temperatures the opposite
#: direction of travel also visited, for its turning-point terms to be told apart from the polynomial
BRANCH_OVERLAP = 0.75


def branches_present(runs: list[RunBlocks], thresholds: list[float]) -> bool:
    """Whether any run holds a branch after a confirmed reversal."""
    return any(np.any(~np.isnan(find_turns(r.temperature_degc, th).turn_degc)) for r, th in zip(runs, thresholds))


def branches_identified(runs: list[RunBlocks], thresholds: list[float], one_sided: bool = True) -> bool:
    """Whether turning-point terms can be told apart from the polynomial: some branch after a reversal exists,
    and for each direction that does, at least :data:`BRANCH_OVERLAP` of it (time-weighted) lies inside the
    temperature range the opposite direction of travel covers. A branch that goes where the other direction
    never went (a run cooled, then heated past its start) would fit curvature of the shape as hysteresis and
    fail on the next leg.

    ``one_sided=False`` also asks for branches after reversals in both directions. Use it when whole runs
    cannot be held out: branches of one direction only (every run cooled then warmed) differ from the rest by
    a change of slope that legs of the same runs confirm but other runs need not share (measured on the CATS
    recording: fitted on two runs, a one-sided term passed the leg folds and doubled the third run's drift)."""
    temps, after, direction, samples = [], [], [], []
    for r, th in zip(runs, thresholds):
        turns = find_turns(r.temperature_degc, th)
        temps.append(r.temperature_degc)
        after.append(~np.isnan(turns.turn_degc))
        direction.append(turns.direction)
        samples.append(r.samples.astype(float))
    t, a, d, n = map(np.concatenate, (temps, after, direction, samples))
    present = [sign for sign in (-1, 1) if np.any(a & (d == sign))]
    if not one_sided and len(present) < 2:
        return False
    for sign in present:
        ref = t[d == -sign]
        if ref.size == 0:
            return False
        branch = a & (d == sign)
        inside = branch & (t >= ref.min()) & (t <= ref.max())
        if n[inside].sum() < BRANCH_OVERLAP * n[branch].sum():
            return False
    return bool(present)


def _weighted_fit(x: np.ndarray, y: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, float]:
    """Residual and weighted residual sum of squares of the least-squares fit of ``y`` on ``x`` (weights ``w``)."""
    sw = np.sqrt(w)
    coef, *_ = np.linalg.lstsq(x * sw[:, None], y * sw, rcond=None)
    resid = y - x @ coef
    return resid, float(np.sum(w * resid**2))


class _ProjectedFit:
    """The weighted residual sum of squares of ``y`` fitted on ``[x, extra]`` for many ``extra`` columns beside one
    fixed ``x``: ``x`` is projected out once (its left singular vectors of non-negligible singular value, the rank
    rule of ``np.linalg.lstsq``), so each :meth:`rss` fits only the extra columns' residuals (Frisch-Waugh-Lovell:
    the same minimum as the fit on all the columns)."""

    def __init__(self, x: np.ndarray, y: np.ndarray, w: np.ndarray):
        self.sw = np.sqrt(w)
        u, s, _ = np.linalg.svd(x * self.sw[:, None], full_matrices=False)
        self.basis = u[:, s > s.max() * max(x.shape) * np.finfo(float).eps] if s.size else u[:, :0]
        self.y = self._residual(y * self.sw)

    def _residual(self, z: np.ndarray) -> np.ndarray:
        return z - self.basis @ (self.basis.T @ z)

    def rss(self, extra: np.ndarray) -> float:
        """The weighted residual sum of squares with the columns ``extra`` (n, m) added."""
        e = self._residual(extra * self.sw[:, None])
        gram = e.T @ e
        scale = np.sqrt(np.maximum(np.diag(gram), 1e-300))
        coef = solve_normal(gram / np.outer(scale, scale), (e.T @ self.y) / scale)
        resid = self.y - e @ (coef / scale)
        return float(resid @ resid)


def observed_band(
    runs: list[RunBlocks],
    groups: tuple[int, ...],
    thresholds: list[float],
    t_ref_degc: float,
    t_scale_degc: float,
    order: int,
    block_s: float | None = None,
) -> tuple[float, float] | None:
    """The band where the branches after a reversal part [degC] (:func:`parting_band_degc`), in the residual of
    a polynomial of ``order`` with one constant per run, fitted by time-weighted least squares on the blocks.

    With ``block_s`` [s], the polynomial is also fitted through a thermal lag, its time constant the one of a
    log-spaced grid that leaves the least residual: a lag parts the heating and cooling branches everywhere by
    about tempco x ramp rate x lag, which would otherwise hide a band of hysteresis of similar size. Each edge
    of the band is then moved, within one temperature bin, to where a fit of the polynomial with turning-point
    terms of order 2 inside the band leaves the least residual, at each lag of the grid; the band of the least
    is returned: bins place an edge up to a bin off, and a bump that ends sharply leaves a step of its height
    there."""
    group_ids = sorted(set(groups))
    onehot = np.zeros((sum(r.value.size for r in runs), len(group_ids)))
    start = 0
    for r, g in zip(runs, groups):
        onehot[start : start + r.value.size, group_ids.index(g)] = 1.0
        start += r.value.size
    y = np.concatenate([r.value for r in runs])
    w = np.concatenate([r.samples.astype(float) for r in runs])
    taus = (
        [0.0]
        if block_s is None
        else [
            0.0,
            *np.geomspace(2 * block_s, min(LAG_MAX_S, max(float(r.time_s[-1] - r.time_s[0]) for r in runs)) / 4, 8),
        ]
    )
    fits = []
    for tau in taus:
        temps = [
            thermal_lag(r.time_s, r.temperature_degc, tau, period_s=block_s)[0] if tau > 0 else r.temperature_degc
            for r in runs
        ]
        u = (np.concatenate(temps) - t_ref_degc) / t_scale_degc
        x = np.hstack([onehot, power_columns(u, 1, order)])
        resid, rss = _weighted_fit(x, y, w)
        fits.append((rss, temps, resid, x))
    _, temps, resid, x = min(fits, key=lambda f: f[0])
    turns = [find_turns(t, th) for t, th in zip(temps, thresholds)]
    t = np.concatenate(temps)
    after = ~np.isnan(np.concatenate([tr.turn_degc for tr in turns]))
    direction = np.concatenate([tr.direction for tr in turns])
    band = parting_band_degc(t, resid, after, direction, tail=block_s is not None)
    if band is None:
        return None
    step = max(1.0, float(np.ptp(t)) / 40.0)  # parting_band_degc's bin
    # the edges at every lag of the grid: an edge a little off is a jump at the wrong temperature, which a longer
    # or shorter lag moves back in time, so the lag that fits the polynomial best need not be the band's (measured
    # on the ADXRS450-like part with a 30 s lag: upper edge 80.7 degC at 61 s, 80.0 degC at the truth)
    return min(
        (_refined_edges(band, step, f[1], f[3], y, w, thresholds, t_scale_degc) for f in fits), key=lambda e: e[0]
    )[1]


def _refined_edges(band, step, temps, x, y, w, thresholds, t_scale_degc) -> tuple[float, tuple[float, float]]:
    """(least weighted rss, band): each edge of ``band`` [degC] moved within one ``step`` [degC] to where a fit of
    ``x`` with turning-point terms of order 2 inside the band (model temperatures ``temps``) leaves the least
    residual, the lower edge first, then the upper one."""
    turns = [find_turns(t, th) for t, th in zip(temps, thresholds)]
    t = np.concatenate(temps)
    turn_degc = np.concatenate([tr.turn_degc for tr in turns])
    after = ~np.isnan(turn_degc)
    direction = np.concatenate([tr.direction for tr in turns])
    d = np.where(after, np.abs(t - np.where(after, turn_degc, 0.0)), 0.0) / t_scale_degc
    projected = _ProjectedFit(x, y, w)
    powers = np.column_stack([np.where(direction == sign, d**j, 0.0) for sign in (-1, 1) for j in (1, 2)])

    tried: dict[tuple[float, float], float] = {}  # the unmoved lower edge and the final band come up twice

    def rss(lo, hi):
        if (lo, hi) not in tried:
            inside = after & (t >= lo) & (t <= hi)
            tried[lo, hi] = projected.rss(np.where(inside[:, None], powers, 0.0))
        return tried[lo, hi]

    offsets = np.linspace(-step, step, 9)
    lo = min(band[0] + offsets, key=lambda v: rss(v, band[1]))
    hi = min(band[1] + offsets, key=lambda v: rss(lo, v))
    return rss(lo, hi), (float(lo), float(hi))


def band_offer(
    runs: list[RunBlocks],
    groups: tuple[int, ...],
    thresholds: list[float],
    folds,
    t_ref: float,
    t_scale: float,
    order: int,
    block_s: float,
    both_directions: bool,
):
    """(band, band only) with the folds ``folds`` (a :class:`gyrocomp.fitting.folds.Folds`): the band where the
    branches part [degC] or None, and whether turning-point candidates are offered only inside it.

    Branches of one direction only, held out by legs of the same runs: an unbounded turning-point term is a change
    of slope that the legs confirm but other runs need not share (measured on the CATS recording: fitted on two
    runs, it doubled the third run's drift); one confined to a band where the branches visibly part (the thesis's
    form) is offered. The band is found once on all the runs, so its candidates' scores are somewhat optimistic;
    it must stand out by three standard errors per bin (:func:`parting_band_degc`). It is found through a fitted
    lag only with one or two runs, where that is what finds it (the ADXRS450 case); with whole runs held out, it
    moved the choice of the demo's MTi-10-class part to a worse gyro_y (measured: 0.0067 against 0.0019 deg/s)."""
    band_only = both_directions and folds.kind != "runs" and not branches_identified(runs, thresholds, one_sided=False)
    band = observed_band(runs, groups, thresholds, t_ref, t_scale, order, block_s if folds.kind != "runs" else None)
    return band, band_only


#: how many standard deviations (of a normal law, two-sided) the branch terms must stand out by
BRANCH_TEST_SIGMAS = 3.0


def branch_test(
    runs: list[RunBlocks],
    groups: tuple[int, ...],
    threshold_degc: float,
    t_ref_degc: float,
    t_scale_degc: float,
    order: int,
    tau_s: float,
    block_s: float,
    extra: list[np.ndarray] | None = None,
) -> BranchTest:
    """Do the heating and cooling curves differ by more than the drift explains?

    For data where every held-out leg leaves one direction of travel only in training (one cooling and one
    heating leg: a single chamber cycle), leg folds cannot judge a branch model. Its terms ``s(T) u^j``
    (:func:`gyrocomp.effects.branch_position`, ``u = (T - t_ref) / t_scale``) are judged instead by their Wald
    statistic in a generalized least-squares fit of the run constants, the polynomial of ``order`` (at least 1)
    and the branch terms, under a white plus power-law drift model (:mod:`gyrocomp.fitting.drift_gls`) estimated
    from the residual of the same fit without the branch terms (the null hypothesis). A slow drift moves the bias
    between the legs by about sqrt(c dt^alpha); that is what the covariance says, so a step between two legs counts
    only where it is larger than the drift the data shows.

    Terms are kept from the lowest: a constant difference where its statistic exceeds
    :func:`gyrocomp.fitting.drift_gls.chi2_threshold` (1 degree of freedom, :data:`BRANCH_TEST_SIGMAS`), and a
    slope too where that term alone does in the fit with both; both when only together they exceed the threshold
    of 2 degrees of freedom. The crossover width is the middle of those the data cannot tell apart
    (:func:`gyrocomp.fitting.grid_search.plausible_middle`).

    Parameters: ``runs`` the block means of each recording (one axis), ``groups`` the run of each (one constant
    each), ``threshold_degc`` the turning-point threshold [degC], ``t_ref_degc`` and ``t_scale_degc`` the centre
    and half-range of the polynomial's variable [degC], ``order`` the polynomial order of the model the branch
    terms are added to (at least 1 is used), ``tau_s`` its thermal lag [s] (0: none), ``block_s`` the block
    length [s], ``extra`` further columns fitted with it in each recording (n_k, m) (the accelerations of G).
    """
    order = max(order, 1)
    coarse = CoarseRuns.of(runs, tau_s, block_s)
    y, t = coarse.value, coarse.time_s
    designs = [
        coarse.coarse(
            _branch_design(
                runs, coarse.temperature_degc, groups, threshold_degc, t_ref_degc, t_scale_degc, order, w, extra
            )
        )
        for w in BRANCH_WIDTHS_DEGC
    ]
    ys = np.concatenate(y)
    pick = _middle_width(runs, designs, ys)
    x, width = designs[pick], BRANCH_WIDTHS_DEGC[pick]
    first = x[0].shape[1] - MAX_BRANCH_ORDER  # the branch columns come last: s, then s u
    # the drift model from the residual of the model without branch terms (the null hypothesis): a difference
    # between the legs that is drift shows there as the drift's growth over long lags (measured on the real
    # one-cycle log tofupilot: from the residual with the branch terms, which absorb that difference, gyro_x's
    # statistic was 53 against a threshold of 11.8; from the null's, 9.2)
    null = _weighted_fit(np.vstack([xk[:, :first] for xk in x]), ys, np.ones(ys.size))[0]
    noise = fit_drift_noise(np.split(null, np.cumsum([v.size for v in y])[:-1]), t)
    return _kept_terms(x, y, t, noise, first, width)


def _middle_width(runs: list[RunBlocks], designs: list, ys: np.ndarray) -> int:
    """The index of the crossover width (of ``BRANCH_WIDTHS_DEGC``) in the middle of those the fits of
    ``designs`` cannot tell apart (:func:`gyrocomp.fitting.grid_search.plausible_middle`)."""
    fits = [_weighted_fit(np.vstack(x), ys, np.ones(ys.size)) for x in designs]  # (residual, rss) per width
    duration_s = sum(float(r.time_s[-1] - r.time_s[0]) for r in runs)
    return plausible_middle(np.array([rss for _, rss in fits]), duration_s / SCORE_WINDOW_S)


def _kept_terms(x: list, y: list, t: list, noise, first: int, width: float) -> BranchTest:
    """The branch terms kept, from the lowest, by their Wald statistics under the drift model ``noise``
    (``first``: the column of the constant branch term in each design of ``x``)."""
    walk = math.sqrt(noise.walk_var_per_s)
    one = wald_statistic([xk[:, : first + 1] for xk in x], y, t, noise, np.array([first]))
    both = wald_statistic(x, y, t, noise, np.array([first, first + 1]))
    alone = wald_statistic(x, y, t, noise, np.array([first + 1]))
    c1, c2 = chi2_threshold(1, BRANCH_TEST_SIGMAS), chi2_threshold(2, BRANCH_TEST_SIGMAS)
    e = noise.exponent
    if one > c1:
        return BranchTest(2, alone, c1, width, walk, e) if alone > c1 else BranchTest(1, one, c1, width, walk, e)
    return BranchTest(2 if both > c2 else 0, both, c2, width, walk, e)


def _branch_design(runs, temps, groups, threshold_degc, t_ref_degc, t_scale_degc, order, width_degc, extra):
    """Per recording: one constant per run, u^1..u^order, the ``extra`` columns, then s(T) u^0..u^(B-1)
    (:func:`gyrocomp.effects.branch_position` at crossover ``width_degc``, B = MAX_BRANCH_ORDER)."""
    out = []
    constants = run_constants([t.size for t in temps], groups)
    for k, temp in enumerate(temps):
        u = (temp - t_ref_degc) / t_scale_degc
        s = branch_position(temp, find_turns(temp, threshold_degc), width_degc)
        cols = [constants[k], power_columns(u, 1, order)]
        if extra is not None:
            cols.append(extra[k])
        cols.append(s[:, None] * power_columns(u, 0, MAX_BRANCH_ORDER - 1))
        out.append(np.hstack(cols))
    return out


__all__ = [
    "BRANCH_OVERLAP",
    "BRANCH_TEST_SIGMAS",
    "band_offer",
    "branch_test",
    "branches_identified",
    "branches_present",
    "heats_and_cools_blocks",
    "observed_band",
]
