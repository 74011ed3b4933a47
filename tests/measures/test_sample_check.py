"""The sample checks a chunk at a time (gyrocomp.measures.sample_check): any chunking of a run gives what the whole
run gives, and that is what the checks' definitions give, written here element by element."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp.measures.sample_check import TEMPERATURE_SPIKE_DEGC, TEMPERATURE_SPIKE_SAMPLES, SampleCheck
from gyrocomp.recording import Recording


def _run(seed: int, n: int, dead: bool, twin: bool, counts: bool, spikes: int) -> Recording:
    """A chamber-like run from the physics: a die warming along a tanh, white gyro noise; optionally a dead axis,
    one column mapped twice, whole-number counts, and spikes of -40 degC at random rows."""
    rng = np.random.default_rng(seed)
    t_s = np.arange(n) * 0.5
    temperature = 25.0 + 15.0 * np.tanh((t_s - t_s.mean()) / max(t_s[-1], 1.0)) + 0.01 * rng.standard_normal(n)
    temperature[rng.choice(n, size=min(spikes, n), replace=False)] = -40.0
    gyro = 0.05 + 0.01 * rng.standard_normal((n, 3))
    if counts:
        gyro = np.round(gyro * 1000.0)
    if dead:
        gyro[:, 1] = 0.125
    if twin:
        gyro[:, 2] = gyro[:, 0]
    return Recording(t_s, gyro, ("gyro_x", "gyro_y", "gyro_z"), temperature, row_numbers=np.arange(n) + 7)


def _reference_spikes(t: np.ndarray) -> tuple[int, list[int], float]:
    """Each sample against the median of the 9 around it, the run's ends mirrored (numpy's 'reflect': the end
    sample not repeated), one sample at a time."""
    h = TEMPERATURE_SPIKE_SAMPLES // 2
    n = t.size

    def at(i: int) -> float:
        i = -i if i < 0 else i
        return t[2 * (n - 1) - i] if i > n - 1 else t[i]

    found = []
    for i in range(n):
        d = abs(t[i] - float(np.median([at(j) for j in range(i - h, i + h + 1)])))
        if d >= TEMPERATURE_SPIKE_DEGC:
            found.append((i, d))
    return len(found), [i for i, _ in found], max((d for _, d in found), default=0.0)


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**31),
    n=st.integers(TEMPERATURE_SPIKE_SAMPLES, 400),
    dead=st.booleans(),
    twin=st.booleans(),
    counts=st.booleans(),
    spikes=st.integers(0, 6),
    data=st.data(),
)
def test_any_chunking_gives_the_whole_runs_facts_and_their_definitions(seed, n, dead, twin, counts, spikes, data):
    rec = _run(seed, n, dead, twin, counts, spikes)
    whole = SampleCheck().add(rec).facts()
    edges = [0]
    for size in data.draw(st.lists(st.integers(2, 60), max_size=10)):  # parts of 2 rows or more, as recordings
        if edges[-1] + size <= n - 2:
            edges.append(edges[-1] + size)
    edges.append(n)
    checker = SampleCheck()
    for a, b in zip(edges[:-1], edges[1:]):
        checker.add(rec.take(np.arange(a, b)))
    assert checker.facts() == whole
    # the definitions
    x = rec.gyro_dps
    assert set(whole.constant_dps) == {j for j in range(3) if np.all(x[:, j] == x[0, j])}
    if twin:
        assert (0, 2) in whole.identical
    assert whole.identical == tuple(
        (j, k) for j in range(3) for k in range(j + 1, 3) if j not in whole.constant_dps and np.all(x[:, j] == x[:, k])
    )
    assert whole.whole_numbers == bool(np.all(x == np.round(x)))
    assert whole.spread_dps == float(np.max(np.ptp(x, axis=0)))
    count, at, worst = _reference_spikes(np.asarray(rec.temperature_degc))
    assert (whole.spikes, whole.spike_worst_degc) == (count, worst)
    assert whole.spike_rows == tuple(int(rec.row_numbers[i]) for i in at[:3])
    assert whole.n_samples == whole.temperature_samples == n
