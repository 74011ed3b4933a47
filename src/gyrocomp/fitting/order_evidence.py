"""What all the calibration data say of the temperature polynomial's order, under the drift model: for thin
evidence, where only two held-out legs judge the model choice (one chamber cycle).

With one cooling and one heating leg, each fold trains on one direction of travel and is judged on the other,
partly beyond its training range: two numbers per candidate, whose standard error says little. The simplest
candidate within one standard error of the best is then often too simple (measured on the real one-cycle log of
``tofupilot-imu-thermal``: gyro_y chose poly:2, 2.4x the drift of a cubic on the next leg; on real still
recordings with a cubic temperature effect added, the default left 1.6x the noise where the cubic left 1.15x).
The data hold more than the two folds use: the order of the curve is a question every sample answers, if the
drift that joins neighbouring samples is accounted for. Here each order's top term is judged by its Wald
statistic in a generalized least-squares fit of one constant per run and the polynomial, under the white plus
power-law drift model of :mod:`gyrocomp.fitting.drift_gls` estimated from that fit's own residual.

Not from the residual of the model without the term, as the branch test's drift model is
(:func:`gyrocomp.fitting.branch_evidence.branch_test`): there the residual would hold the very curve being
tested, which dwarfs the noise (measured on a simulated consumer-grade part: a strong quadratic put the linear
term at 6.1 against 9, and the axis was left at 75x its noise). The price is that a drift that follows the
temperature on one cycle by chance passes this test as easily as a temperature effect does (on the real log's
gyro_x, whose drift is not repeatable with temperature, the quadratic term stood at 80 against 9): so the test
decides how complex the curve is, and the held-out legs whether there is one
(:func:`gyrocomp.fitting.choice.choose_axis`).

References: T. W. Anderson, *The Statistical Analysis of Time Series*, 1971 (GLS); the backward order test:
T. W. Anderson, "The choice of the degree of a polynomial regression as a multiple decision problem", Ann. Math.
Statist. 33(1), 1962.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..calibration.fit_report import OrderTest
from ..curves.polynomial import power_columns
from ..effects import thermal_lag
from ..runs.prepared import RunBlocks
from .drift_gls import MAX_POINTS, chi2_threshold, coarsen, fit_drift_noise, wald_statistic

#: how many standard deviations (of a normal law, two-sided) an order's top term must stand out by
ORDER_TEST_SIGMAS = 3.0


@dataclass(frozen=True)
class CoarseRuns:
    """Block means averaged down to at most :data:`gyrocomp.fitting.drift_gls.MAX_POINTS` points in all (each
    recording's covariance is dense): per recording the value [the axis's unit], time [s] and model temperature
    [degC], and the run each belongs to."""

    value: list[np.ndarray]
    time_s: list[np.ndarray]
    temperature_degc: list[np.ndarray]
    factor: int

    @classmethod
    def of(cls, runs: list[RunBlocks], tau_s: float, block_s: float) -> "CoarseRuns":
        """``runs`` averaged over groups of blocks, the temperature through a thermal lag of ``tau_s`` [s] first
        (0: none)."""
        factor = max(1, math.ceil(sum(r.value.size for r in runs) / MAX_POINTS))
        temps = [
            thermal_lag(r.time_s, r.temperature_degc, tau_s, period_s=block_s)[0] if tau_s > 0 else r.temperature_degc
            for r in runs
        ]
        return cls([coarsen(r.value, factor) for r in runs], [coarsen(r.time_s, factor) for r in runs], temps, factor)

    def coarse(self, columns: list[np.ndarray]) -> list[np.ndarray]:
        """Per-block ``columns`` (one (n_k, p) array per recording) averaged as the values are."""
        return [coarsen(c, self.factor) for c in columns]


def run_constants(sizes: list[int], groups: tuple[int, ...]) -> list[np.ndarray]:
    """Per recording of ``sizes[k]`` rows, the one-hot columns of its run among ``groups``' runs."""
    ids = sorted(set(groups))
    out = []
    for size, g in zip(sizes, groups):
        onehot = np.zeros((size, len(ids)))
        onehot[:, ids.index(g)] = 1.0
        out.append(onehot)
    return out


def order_test(
    runs: list[RunBlocks],
    groups: tuple[int, ...],
    t_ref_degc: float,
    t_scale_degc: float,
    max_order: int,
    tau_s: float,
    block_s: float,
    extra: list[np.ndarray] | None = None,
) -> OrderTest:
    """The temperature polynomial's order that all the data support beyond the drift.

    For each order p = N..1 (N = ``max_order``), the Wald statistic of the coefficient of ``u^p``
    (``u = (T - t_ref) / t_scale``) in the generalized least-squares fit of one constant per run, ``u^1..u^p`` and
    ``extra``, under the white plus power-law drift model (:func:`gyrocomp.fitting.drift_gls.fit_drift_noise`)
    estimated from the residual of the same fit without ``u^p``. The order is the highest p whose statistic
    exceeds the chi-square threshold of :data:`ORDER_TEST_SIGMAS` (1 degree of freedom), 0 when none does (the
    backward test of polynomial regression: a term of order p is needed whatever the lower ones are).

    Parameters
    ----------
    runs : list of RunBlocks
        Block means of each recording (one axis) [s, degC, the axis's unit].
    groups : tuple of int
        The run of each recording (one constant each).
    t_ref_degc, t_scale_degc : float
        Centre and half-span of the polynomial's variable [degC].
    max_order : int
        The highest order tested.
    tau_s : float
        Thermal lag of the model temperature [s] (0: none).
    block_s : float
        Block length [s].
    extra : list of ndarray, optional
        Further columns fitted with every order, per recording (n_k, m) (the accelerations of G).
    """
    threshold = chi2_threshold(1, ORDER_TEST_SIGMAS)
    if max_order < 1:
        return OrderTest(0, (), threshold, ())
    coarse = CoarseRuns.of(runs, tau_s, block_s)
    sizes = [r.value.size for r in runs]
    base = run_constants(sizes, groups)
    if extra is not None:
        base = [np.hstack([c, e]) for c, e in zip(base, extra)]
    powers = [power_columns((t - t_ref_degc) / t_scale_degc, 1, max_order) for t in coarse.temperature_degc]
    base = coarse.coarse(base)
    powers = coarse.coarse(powers)
    y, t = coarse.value, coarse.time_s
    ys = np.concatenate(y)
    statistics, exponents = [], []
    for p in range(1, max_order + 1):
        full = [np.hstack([b, w[:, :p]]) for b, w in zip(base, powers)]
        coef, *_ = np.linalg.lstsq(np.vstack(full), ys, rcond=None)
        resid = ys - np.vstack(full) @ coef
        noise = fit_drift_noise(np.split(resid, np.cumsum([v.size for v in y])[:-1]), t)
        statistics.append(wald_statistic(full, y, t, noise, np.array([full[0].shape[1] - 1])))
        exponents.append(noise.exponent)
    passed = [p for p, s in enumerate(statistics, start=1) if s > threshold]
    return OrderTest(max(passed, default=0), tuple(statistics), threshold, tuple(exponents))


__all__ = ["CoarseRuns", "ORDER_TEST_SIGMAS", "OrderTest", "order_test", "run_constants"]
