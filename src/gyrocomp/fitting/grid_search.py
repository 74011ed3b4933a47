"""The one-parameter searches of the thermal fit: the time constant of the die's lag (:func:`best_lag_s`, between
two blocks and :func:`lag_search_top_s`), and the middle of a grid of crossover widths or smoothings that the
data cannot tell from the best (:func:`plausible_middle`)."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

#: bounds of the thermal time constant search [s]
LAG_MIN_BLOCKS = 2.0
LAG_MAX_S = 4 * 3600.0
#: an axis whose fit at its lag the data cannot tell from the same at the bottom of the search (two blocks) by
#: more than this chi-square (about two standard errors of one parameter, as in plausible_middle) does not see it
LAG_EVIDENCE_CHI2 = 4.0


def plausible_middle(rss: np.ndarray, independent: float, chi2: float = 4.0) -> int:
    """The middle index of the grid points whose residual sum of squares ``rss`` the data cannot tell from the
    least: within ``chi2`` (about two standard errors of one parameter) of it, on the scale of the least rss per
    ``independent`` residual (the residual's independent stretches: its length over the drift window, as
    block residuals are correlated over that long)::

        plausible = {i : rss_i - min(rss) <= chi2 min(rss) / independent}

    With a sharp minimum that is the least point itself; with a flat profile (the parameter not identified) the
    middle of the grid rather than a point chance picked."""
    least = float(np.min(rss))
    plausible = np.flatnonzero(rss - least <= chi2 * max(least, 1e-300) / max(independent, 1.0))
    return int(plausible[plausible.size // 2])


def lag_search_top_s(runs, lo_s: float) -> float:
    """The longest time constant [s] a lag search tries: half the longest of ``runs`` (anything with ``time_s``
    [s]), at most :data:`LAG_MAX_S`, at least twice ``lo_s``. A die that takes longer to follow its sensor never
    settles in any run, and its lagged temperature is a smooth trend over the run that fits a slow drift as well
    as the temperature (measured: a simulated random walk unrelated to temperature, three runs of 3.1-3.75 h,
    got lags of 4,600-7,900 s, and the fourth run drifted 2.1x raw)."""
    longest = max(float(r.time_s[-1] - r.time_s[0]) for r in runs)
    return max(2.0 * lo_s, min(LAG_MAX_S, longest / 2.0))


def best_lag_s(rss: Callable[[float], float], lo_s: float, hi_s: float = LAG_MAX_S) -> float:
    """The time constant [s] that minimizes ``rss(tau)``: a 12-point log-spaced search between ``lo_s`` and
    ``hi_s`` [s], refined by a bounded scalar minimization in log(tau) around the best grid point."""
    from scipy.optimize import minimize_scalar  # slow to import; only lag fits need it

    grid = np.geomspace(lo_s, hi_s, 12)
    values = [rss(float(tau)) for tau in grid]
    best = int(np.argmin(values))
    a, b = math.log(grid[max(best - 1, 0)]), math.log(grid[min(best + 1, grid.size - 1)])
    res = minimize_scalar(lambda lt: rss(math.exp(lt)), bounds=(a, b), method="bounded", options={"xatol": 1e-2})
    return math.exp(res.x) if res.fun <= values[best] else float(grid[best])


__all__ = ["LAG_EVIDENCE_CHI2", "LAG_MAX_S", "LAG_MIN_BLOCKS", "best_lag_s", "lag_search_top_s", "plausible_middle"]
