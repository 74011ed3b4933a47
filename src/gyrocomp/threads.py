"""Numeric work without thread oversubscription: the library's hot paths run BLAS on one thread.

gyrocomp's dense algebra is many small solves (least squares on a few thousand rows, a few columns) and
long dot products (Allan sums). OpenBLAS and MKL start one thread per core for each; on a machine another
job shares, or in a Dask worker beside others, those threads wait for each other: a 3600 x 10 ``lstsq``
took 3-7 ms with two threads and a busy neighbour against 0.4 ms on one, and ``allan_deviation`` on 1e7
samples 0.27 s against 0.14 s (issue #21). Parallelism belongs a level up (one run, one unit, one Dask task
per core), so the public entry points of fitting and the Allan engine hold BLAS to one thread while they
run and restore the caller's setting after (``threadpoolctl``, which finds the BLAS libraries numpy and
scipy loaded).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import TypeVar

from threadpoolctl import ThreadpoolController

F = TypeVar("F", bound=Callable)
_CONTROLLER: list[ThreadpoolController] = []


def _controller() -> ThreadpoolController:
    """The process's view of its thread pools, found once (the scan of loaded libraries costs milliseconds).

    scipy brings a BLAS of its own beside numpy's (scipy.linalg's OpenBLAS), and the fits import scipy.linalg
    late, inside the limit: a library loaded after the scan, or while the limit holds, keeps every thread, so the
    same fit's last bits depended on what the process had imported before it (a fit in a process that had not
    imported scipy against the same fit through the command line). scipy.linalg is loaded before the scan, so
    both BLAS libraries are held to one thread."""
    if not _CONTROLLER:
        import scipy.linalg  # noqa: F401 (its BLAS loaded, to be found; 0.1 s, which every fit pays anyway)

        _CONTROLLER.append(ThreadpoolController())
    return _CONTROLLER[0]


def blas_threads() -> int | None:
    """How many threads BLAS may use now (the largest over the loaded BLAS libraries; None without one)."""
    pools = [info["num_threads"] for info in _controller().info() if info.get("user_api") == "blas"]
    return max(pools) if pools else None


def single_threaded_blas(func: F) -> F:
    """Run ``func`` with BLAS on one thread, the caller's setting restored after (also when it raises)."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with _controller().limit(limits=1, user_api="blas"):
            return func(*args, **kwargs)

    return wrapper  # type: ignore[return-value]


__all__ = ["blas_threads", "single_threaded_blas"]
