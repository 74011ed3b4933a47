"""How fast the runs' temperature ramps, and whether runs at those rates can tell the memory forms apart.

A thermal lag, a bias in the rate of temperature change and a memory of the last turn all make the heating and
cooling curves differ. At one ramp rate they can make the same difference; they part at another rate (a lag's
offset and a rate term grow with the rate, a memory of the turn does not), so only runs whose ramp rates differ
enough can tell them apart (:func:`ramp_rates_separate`).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np

from ..recording import Recording

#: runs whose typical ramp rates differ by at least this factor can tell a memory that grows with the rate (a lag,
#: a rate term) from one that does not (a memory of the turn): their heating-cooling differences then part by at
#: least half the smaller one
SEPARATING_RAMP_RATIO = 1.5
#: the run suggested to tell them apart ramps this many times faster (or slower) than the runs: beyond
#: SEPARATING_RAMP_RATIO with room for a chamber that ramps less steadily than it is set to
NEXT_RUN_RATE_FACTOR = 2.0
#: the minutes a ramp rate is taken from: those whose change is at least this fraction of the fastest minutes'
MOVING_FRACTION = 0.2


def minute_rates(time_s: np.ndarray, temperature_degc: np.ndarray) -> np.ndarray:
    """The temperature's change over each whole minute of a series [degC/min] (absolute).

    Parameters
    ----------
    time_s : ndarray
        Sample times [s], increasing.
    temperature_degc : ndarray
        The temperature at those times [degC].
    """
    grid = np.arange(time_s[0], time_s[-1], 60.0)
    if grid.size < 2:
        return np.zeros(0)
    return np.abs(np.diff(np.interp(grid, time_s, temperature_degc)))


def typical_ramp_degc_per_min(series: Iterable[tuple[np.ndarray, np.ndarray]]) -> float:
    """The typical ramp rate [degC/min] of (time [s], temperature [degC]) series: the median change per minute of
    the minutes that change by more than :data:`MOVING_FRACTION` of the fastest minutes' (the 95th percentile);
    NaN where the temperature never changes.

    Parameters
    ----------
    series : iterable of (ndarray, ndarray)
        (time [s], temperature [degC]) pairs, taken together.
    """
    rates = [minute_rates(np.asarray(t, dtype=float), np.asarray(v, dtype=float)) for t, v in series]
    rates = np.concatenate(rates) if rates else np.zeros(0)
    top = float(np.percentile(rates, 95)) if rates.size else 0.0
    if top <= 0.0:
        return float("nan")
    return float(np.median(rates[rates > MOVING_FRACTION * top]))


def _die_series(recordings: Sequence[Recording]):
    return ((r.time_s, r.die_temperature_degc) for r in recordings if r.temperature_degc is not None)


def ramp_rate_degc_per_min(recordings: Sequence[Recording]) -> float:
    """The runs' typical ramp rate together [degC/min] (:func:`typical_ramp_degc_per_min`); 1 where no run's
    temperature changes (a placeholder the planning commands scale).

    Parameters
    ----------
    recordings : sequence of Recording
        The runs (those without a temperature are skipped).
    """
    rate = typical_ramp_degc_per_min(_die_series(recordings))
    return rate if np.isfinite(rate) and rate > 0 else 1.0


def run_ramp_rates_degc_per_min(recordings: Sequence[Recording]) -> tuple[float, ...]:
    """Each run's typical ramp rate [degC/min] (:func:`typical_ramp_degc_per_min`); NaN for a run whose temperature
    never changes or that has none.

    Parameters
    ----------
    recordings : sequence of Recording
    """
    return tuple(
        typical_ramp_degc_per_min([(r.time_s, r.die_temperature_degc)]) if r.temperature_degc is not None else np.nan
        for r in recordings
    )


def ramp_rates_separate(rates_degc_per_min: Sequence[float]) -> bool:
    """Whether runs ramping at these rates [degC/min] can tell a memory that grows with the ramp rate from one that
    does not: the fastest and slowest of the runs that ramp differ by at least :data:`SEPARATING_RAMP_RATIO`.

    Parameters
    ----------
    rates_degc_per_min : sequence of float
        Each run's typical ramp rate [degC/min] (NaN: a run that does not ramp, left out).
    """
    moving = [float(r) for r in rates_degc_per_min if np.isfinite(r) and r > 0]
    return bool(moving) and max(moving) >= SEPARATING_RAMP_RATIO * min(moving)


def separation_sentence(rates_degc_per_min: Sequence[float]) -> str:
    """What the runs' ramp rates [degC/min] can tell of a memory that grows with the rate (a lag, a rate term) against
    one that does not (a memory of the turn), in words, with the run that would tell where they cannot; empty where
    the rates are not known.

    Parameters
    ----------
    rates_degc_per_min : sequence of float
        Each run's typical ramp rate [degC/min] (NaN: a run that does not ramp).
    """
    if not len(rates_degc_per_min):
        return ""
    moving = sorted(float(r) for r in rates_degc_per_min if np.isfinite(r) and r > 0)
    if not moving:
        return "the runs do not ramp: no heating-cooling difference to tell a lag, a rate term or a memory by"
    if ramp_rates_separate(moving):
        return (
            f"the runs ramp at {moving[0]:.2g} to {moving[-1]:.2g} degC/min, far enough apart to tell a lag or a "
            "rate term (which grow with the ramp rate) from a memory of the turn (which does not)"
        )
    typical = float(np.median(moving))
    return (
        f"the runs all ramp at about {typical:.2g} degC/min: at one rate a lag, a rate term and a memory of the turn "
        "can leave the same heating-cooling difference, and they part at other rates; a heat-cool run at "
        f"{NEXT_RUN_RATE_FACTOR * typical:.2g} degC/min (or {typical / NEXT_RUN_RATE_FACTOR:.2g}) tells them apart"
    )


__all__ = [
    "MOVING_FRACTION",
    "NEXT_RUN_RATE_FACTOR",
    "SEPARATING_RAMP_RATIO",
    "minute_rates",
    "ramp_rate_degc_per_min",
    "ramp_rates_separate",
    "run_ramp_rates_degc_per_min",
    "separation_sentence",
    "typical_ramp_degc_per_min",
]
