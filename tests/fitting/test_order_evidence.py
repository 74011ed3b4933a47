"""The order test (gyrocomp.fitting.order_evidence): what all the data of one chamber cycle say of the temperature
polynomial's order beyond the drift; simulate-then-recover against a walk the data share with the temperature by
chance."""

import numpy as np
import pytest

from gyrocomp.fitting.order_evidence import ORDER_TEST_SIGMAS, order_test
from gyrocomp.recording import Recording
from gyrocomp.runs.prepared import PreparedRun

RATE_HZ = 2.0
N = 9600  # 80 minutes
#: one cycle, 40 -> -20 -> 70 -> 30 degC at one ramp rate [degC]
POINTS = np.array([40.0, -20.0, 70.0, 30.0])
TEMPERATURE = np.interp(
    np.linspace(0, 1, N), np.r_[0, np.cumsum(np.abs(np.diff(POINTS)))] / np.abs(np.diff(POINTS)).sum(), POINTS
)
U = (TEMPERATURE - 25.0) / 45.0


def _blocks(y):
    rec = Recording(
        time_s=np.arange(N) / RATE_HZ, gyro_dps=y[:, None], gyro_axes=("gyro_x",), temperature_degc=TEMPERATURE
    )
    return PreparedRun.of(rec).block_means("gyro_x", 2.0, 1.0, None)


def _walk(seed):
    """White noise (0.01 deg/s per sample) and a random walk (2e-3 deg/s/sqrt(s)) [deg/s]."""
    rng = np.random.default_rng(seed)
    return 0.01 * rng.standard_normal(N) + np.cumsum(2e-3 * np.sqrt(1 / RATE_HZ) * rng.standard_normal(N))


def _order(y):
    return order_test([_blocks(y)], (0,), 25.0, 45.0, 5, 0.0, 2.0)


@pytest.mark.slow
def test_a_walk_unrelated_to_temperature_gets_no_order():
    """Along one cycle a walk follows the temperature by chance; under the drift model each order's top term
    passes 3 sigma in 0.27 % of draws, five orders tested: about 1.4 % (measured 1 of 60); 2 of 20 allowed."""
    orders = [_order(_walk(seed)).order for seed in range(20)]
    assert sum(o > 0 for o in orders) <= 2, orders


@pytest.mark.slow
def test_a_cubic_beyond_the_drift_is_found_at_its_order():
    """A cubic of 0.3 deg/s over the range on the same walk: order 3 in 59 of 60 draws (4 in the other)."""
    tests = [_order(_walk(seed) + 0.3 * (U - 0.5 * U**2 + 0.8 * U**3)) for seed in range(20)]
    assert sum(t.order == 3 for t in tests) >= 18, [t.order for t in tests]
    first = tests[0]
    assert first.threshold == pytest.approx(ORDER_TEST_SIGMAS**2)
    assert len(first.statistics) == 5 and first.statistics[2] > first.threshold
    assert all(0.2 <= e <= 1.8 for e in first.drift_exponents)


def test_extra_columns_are_fitted_with_every_order_and_no_order_means_none():
    """A term that is not temperature (here a step, as an accelerometer column could be) is fitted with every
    order, not taken for one; with no order to test the answer is order 0."""
    step = (np.arange(N) > N // 3).astype(float)
    y = _walk(3) + 0.2 * (U - 0.5 * U**2 + 0.8 * U**3) + 0.5 * step
    blocks = _blocks(y)
    extra = [
        PreparedRun.of(
            Recording(
                time_s=np.arange(N) / RATE_HZ,
                gyro_dps=step[:, None],
                gyro_axes=("gyro_x",),
                temperature_degc=TEMPERATURE,
            )
        )
        .block_means("gyro_x", 2.0, 1.0, None)
        .value[:, None]
    ]
    assert order_test([blocks], (0,), 25.0, 45.0, 5, 0.0, 2.0, extra).order == 3
    none = order_test([blocks], (0,), 25.0, 45.0, 0, 0.0, 2.0)
    assert none.order == 0 and none.statistics == ()
