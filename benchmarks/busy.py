"""A busy neighbour for the benchmarks: another process spinning on one core while a figure is measured, as on a
shared machine or beside other Dask workers (#21)."""

from __future__ import annotations

import contextlib
import subprocess
import sys
import time


@contextlib.contextmanager
def busy_neighbour():
    """Run the block while a second Python process keeps one core busy; it is stopped after."""
    spinner = subprocess.Popen([sys.executable, "-c", "while True:\n    pass"])
    try:
        time.sleep(0.3)  # let it start spinning
        yield
    finally:
        spinner.kill()
        spinner.wait()
