"""Fields read and written at records' byte offsets: runs of one stride give what reading each record's bytes gives."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gyrocomp.io.byte_fields import Places, among


def _record_offsets(lengths: list[int]) -> np.ndarray:
    """Records of these lengths one after the other from byte 3."""
    return 3 + np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(np.int64)


def _by_hand(data: bytes, at: np.ndarray, shift: int, dtype: str, count: int) -> np.ndarray:
    """Each record's field read from its own bytes."""
    size = np.dtype(dtype).itemsize * count
    return np.array(
        [np.frombuffer(data[a + shift : a + shift + size], dtype=dtype) for a in at.tolist()], dtype=dtype
    ).reshape(at.size, count)


# records mostly of one length (a topic's messages) with others between them, in the offsets' order or shuffled
lengths = st.lists(st.one_of(st.just(40), st.just(40), st.just(40), st.integers(24, 60)), min_size=0, max_size=300)


@settings(max_examples=60, deadline=None)
@given(lengths, st.integers(0, 16), st.sampled_from(["<u4", "<f8", "u1", "<i4"]), st.integers(1, 2), st.booleans())
def test_read_equals_each_records_bytes(lengths, shift, dtype, count, shuffled):
    rng = np.random.default_rng(len(lengths))
    at = _record_offsets(lengths)
    data = rng.integers(0, 256, int(at[-1] + 64) if at.size else 8, dtype=np.uint8)
    if shuffled:
        at = rng.permutation(at)
    places = Places(data, at)
    got = places.read(shift, dtype, count)
    want = _by_hand(data.tobytes(), at, shift, dtype, count)
    assert got.shape == ((at.size,) if count == 1 else (at.size, count))
    np.testing.assert_array_equal(got.reshape(at.size, count).view(np.uint8), want.view(np.uint8))


def test_runs_and_gathering_read_alike():
    """Offsets of one stride broken by other records read as a few runs; scattered ones are gathered."""
    at = _record_offsets([40] * 500 + [31] + [40] * 500 + [17] + [40] * 100)
    data = np.random.default_rng(1).integers(0, 256, int(at[-1] + 64), dtype=np.uint8)
    places = Places(data, at)
    assert places.stride == 40 and len(places.runs) == 3
    scattered = Places(data, np.random.default_rng(2).permutation(at))
    assert scattered.runs is None
    np.testing.assert_array_equal(scattered.read(4, "<f8", 3)[np.argsort(scattered.at)], places.read(4, "<f8", 3))


@settings(max_examples=40, deadline=None)
@given(lengths, st.integers(0, 16), st.booleans(), st.booleans())
def test_write_puts_each_value_at_its_record(lengths, shift, shuffled, some_rows):
    rng = np.random.default_rng(len(lengths) + 7)
    at = _record_offsets(lengths)
    data = rng.integers(0, 256, int(at[-1] + 64) if at.size else 8, dtype=np.uint8)
    if shuffled:
        at = rng.permutation(at)
    rows = np.flatnonzero(rng.random(at.size) < 0.5) if some_rows else None  # none at all, at times
    chosen = at if rows is None else at[rows]
    values = rng.normal(size=(chosen.size, 3)).astype("<f8")
    want = data.copy()
    for a, v in zip(chosen.tolist(), values):
        want[a + shift : a + shift + 24] = np.frombuffer(v.tobytes(), dtype=np.uint8)
    Places(data, at).write(shift, values, rows)
    np.testing.assert_array_equal(data, want)


def test_a_field_outside_the_buffer_is_refused():
    data = np.zeros(100, dtype=np.uint8)
    places = Places(data, np.array([0, 40, 80]))
    with pytest.raises(ValueError, match="a field of 8 bytes at 14 from a record's start lies outside the buffer"):
        places.read(14, "<f8")
    with pytest.raises(ValueError, match="lies outside the buffer"):
        places.write(-1, np.zeros((3, 1)))


def test_writing_no_rows_changes_nothing():
    data = np.arange(100, dtype=np.uint8)
    Places(data, np.array([0, 40])).write(0, np.zeros((0, 3)), np.array([], dtype=np.int64))
    Places(data, np.array([], dtype=np.int64)).write(0, np.zeros((0, 3)))
    np.testing.assert_array_equal(data, np.arange(100, dtype=np.uint8))


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(-3, 40), max_size=50), st.sets(st.integers(-3, 40), max_size=12))
def test_among_is_isin(values, ids):
    values = np.array(values, dtype=np.int64)
    np.testing.assert_array_equal(among(values, ids), np.isin(values, np.array(sorted(ids), dtype=np.int64)))
