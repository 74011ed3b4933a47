"""A file written by a thread of its own: the same bytes in the same order, and the writing's errors raised to the
caller."""

from __future__ import annotations

import os
import threading

import numpy as np
import pytest

from gyrocomp.io.write_behind import WriteBehind, write_behind


def test_the_file_holds_every_block_in_order(tmp_path):
    rng = np.random.default_rng(3)
    blocks = [rng.integers(0, 256, int(n), dtype=np.uint8) for n in rng.integers(0, 5000, 300)]
    blocks += [b"", bytearray(b"tail")]
    with open(tmp_path / "out", "wb") as file, write_behind(file, most_blocks=2) as behind:
        for block in blocks:
            behind.write(block)
    assert (tmp_path / "out").read_bytes() == b"".join(bytes(b) for b in blocks)


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full (a device that is always full)")
def test_a_full_disk_is_raised_to_the_caller():
    with open("/dev/full", "wb", buffering=0) as file:
        behind = WriteBehind(file, most_blocks=1)
        behind.write(b"x" * 10)
        with pytest.raises(OSError, match="No space left on device"):
            for _ in range(1000):  # the error reaches a later write, or the close
                behind.write(b"x" * 10)
            behind.close()
        with pytest.raises(OSError, match="No space left on device"):
            behind.close()  # and stays


def test_the_callers_error_goes_on_and_the_writer_ends(tmp_path):
    with open(tmp_path / "out", "wb") as file:
        with pytest.raises(ValueError, match="the caller's"):
            with write_behind(file) as behind:
                behind.write(b"abc")
                raise ValueError("the caller's")
        assert behind.file is file
        assert not any(t.name == "gyrocomp-write-behind" for t in threading.enumerate())
    assert (tmp_path / "out").read_bytes() == b"abc"


def test_work_runs_in_the_writer_thread_in_order_with_the_writes(tmp_path):
    ran_in = []

    def stamp(file, text):
        ran_in.append(threading.current_thread().name)
        file.write(text)

    with open(tmp_path / "out", "wb") as file, write_behind(file, most_blocks=1) as behind:
        for k in range(50):
            behind.write(b"%d," % k)
            behind.call(stamp, file, b"[%d]" % k)
    assert (tmp_path / "out").read_bytes() == b"".join(b"%d,[%d]" % (k, k) for k in range(50))
    assert set(ran_in) == {"gyrocomp-write-behind"}


def test_an_error_of_the_work_is_raised_as_a_writes(tmp_path):
    def fails():
        raise ValueError("a checksum that could not be computed")

    with open(tmp_path / "out", "wb") as file:
        with pytest.raises(ValueError, match="a checksum that could not be computed"):
            with write_behind(file) as behind:
                behind.call(fails)
                behind.write(b"never")
        assert (tmp_path / "out").read_bytes() == b""
