"""A binary file written by a thread of its own, so that the caller computes the next block while the system writes
the last.

Copying a ten-hour bag writes 13 GB: once the system's dirty pages are full, each ``write`` waits for the disk, and
a caller that decodes and compensates between its writes adds the two times. :class:`WriteBehind` hands each block
to a writer thread through a bounded queue (the blocks waiting are at most ``most_blocks``, so memory stays bounded)
and returns at once; the file's bytes are the same, in the same order. An error of the writing (a full disk) is
raised to the caller at its next write or when the writing ends, as the same exception. Work that belongs with the
writing (a checksum of the bytes written) can run in the same thread, in order with the writes
(:meth:`WriteBehind.call`).
"""

from __future__ import annotations

import contextlib
import queue
import threading


class WriteBehind:
    """Blocks written to ``file`` (an open binary file) in order by a thread of its own.

    Parameters
    ----------
    file
        An open binary file; only its ``write`` is called, from the writer thread.
    most_blocks : int
        Blocks waiting at most; :meth:`write` waits for room beyond that.
    """

    def __init__(self, file, most_blocks: int = 32):
        self.file = file
        self._blocks: queue.Queue = queue.Queue(maxsize=most_blocks)
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._run, name="gyrocomp-write-behind", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while (item := self._blocks.get()) is not None:
            if self._error is None:  # after an error the rest is taken and dropped: the caller never waits for room
                try:
                    item[0](*item[1])
                except BaseException as err:  # raised to the caller (a full disk: OSError)
                    self._error = err

    def write(self, block) -> None:
        """Hand ``block`` (bytes, or a buffer nobody changes after) over to be written; the error of an earlier
        write, if any, raised here."""
        self.call(self.file.write, block)

    def call(self, work, *args) -> None:
        """Run ``work(*args)`` in the writer thread, in order with the writes (work that belongs with the writing,
        a checksum of what is written, say); its error raised as a write's."""
        if self._error is not None:
            raise self._error
        self._blocks.put((work, args))

    def close(self) -> None:
        """Wait until every block is written; the writing's error, if any, raised here."""
        if self._thread.is_alive():
            self._blocks.put(None)
            self._thread.join()
        if self._error is not None:
            raise self._error


@contextlib.contextmanager
def write_behind(file, most_blocks: int = 32):
    """A :class:`WriteBehind` of ``file``, every block written when the block ends (also when it raises: then its
    error, not the writing's, goes on)."""
    behind = WriteBehind(file, most_blocks)
    try:
        yield behind
    except BaseException:
        with contextlib.suppress(BaseException):
            behind.close()
        raise
    behind.close()


__all__ = ["WriteBehind", "write_behind"]
