"""A file read ahead of its reader by a thread: it reads up to its window past the reader's place and no further,
skips what the reader passed, stops at the end of the file or when closed, and is a no-op where the file does not
open."""

from __future__ import annotations

import threading
import time

import pytest

from gyrocomp.io.read_ahead import ReadAhead

KIB = 1024


def _settles(ahead: ReadAhead, want: int) -> int:
    """The thread's progress once it reaches ``want`` or stops moving (waiting at most a few seconds)."""
    deadline = time.monotonic() + 10.0
    while time.monotonic() < deadline and ahead.read_to < want:
        time.sleep(0.01)
    time.sleep(0.05)  # had it gone past the window, it would have by now
    return ahead.read_to


def test_it_reads_its_window_past_the_reader_and_no_further(tmp_path):
    path = tmp_path / "big.bin"
    path.write_bytes(bytes(1024 * KIB))
    with ReadAhead(path, ahead_bytes=256 * KIB, block_bytes=64 * KIB) as ahead:
        assert _settles(ahead, 256 * KIB) == 256 * KIB
        ahead.at(512 * KIB)  # the reader jumped: the thread skips to it and reads its window from there
        assert _settles(ahead, 768 * KIB) == 768 * KIB
        ahead.at(900 * KIB)
        assert _settles(ahead, 1024 * KIB) == 1024 * KIB  # the end of the file: the thread ends
    assert not any(t.name == "gyrocomp-read-ahead" for t in threading.enumerate())


def test_closing_stops_a_waiting_thread(tmp_path):
    path = tmp_path / "big.bin"
    path.write_bytes(bytes(512 * KIB))
    ahead = ReadAhead(path, ahead_bytes=64 * KIB, block_bytes=64 * KIB)
    assert _settles(ahead, 64 * KIB) == 64 * KIB
    ahead.close()
    ahead.close()  # twice: nothing more
    assert not any(t.name == "gyrocomp-read-ahead" for t in threading.enumerate())


@pytest.mark.parametrize("path", ["no such file", None])
def test_a_file_that_does_not_open_is_left_to_the_reader(tmp_path, path):
    with ReadAhead(tmp_path / path if path else None) as ahead:
        ahead.at(10)
        assert ahead.read_to == 0
