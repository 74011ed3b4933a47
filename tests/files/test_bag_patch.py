"""The in-place compensation's batching: a batch falls due, found for a whole chunk at once, after the message
where the message-by-message pass's rule (:func:`gyrocomp.files.apply_bag._batch_due`) says so."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import gyrocomp.files.apply_bag as apply_bag
from gyrocomp.files.bag_patch import due_at


@given(
    messages=st.lists(st.tuples(st.integers(-1, 2), st.integers(0, 400)), max_size=60),
    held=st.lists(st.integers(0, 6), min_size=3, max_size=3),
    held_bytes=st.integers(0, 2000),
    ready=st.lists(st.booleans(), min_size=3, max_size=3),
    chunk_rows=st.integers(1, 12),
    window_bytes=st.integers(1, 3000),
    first_samples=st.integers(1, 8),
)
@settings(max_examples=300, deadline=None)
def test_a_batch_is_due_where_the_message_by_message_rule_says(
    messages, held, held_bytes, ready, chunk_rows, window_bytes, first_samples
):
    topics = ["a", "b", "c"]
    copiers = {t: SimpleNamespace(comp=object() if r else None) for t, r in zip(topics, ready)}
    raws = {t: [b""] * n for t, n in zip(topics, held)}
    expected, count = None, held_bytes
    original = (apply_bag.WINDOW_BYTES, apply_bag.FIRST_SAMPLES)
    apply_bag.WINDOW_BYTES, apply_bag.FIRST_SAMPLES = window_bytes, first_samples
    try:
        for i, (topic, length) in enumerate(messages):
            if topic >= 0:
                raws[topics[topic]].append(b"")
            count += length
            most = max(len(m) for m in raws.values())
            if apply_bag._batch_due(copiers, raws, most, count, chunk_rows):
                expected = i
                break
    finally:
        apply_bag.WINDOW_BYTES, apply_bag.FIRST_SAMPLES = original
    topic_of = np.array([t for t, _ in messages], dtype=np.int64)
    lengths = np.array([n for _, n in messages], dtype=np.int64)
    found = due_at(
        topic_of, lengths, np.array(held), held_bytes, np.array(ready), (chunk_rows, window_bytes, first_samples)
    )
    assert found == expected
