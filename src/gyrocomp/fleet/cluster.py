"""The fleet's Dask cluster: a client of a running scheduler, or a local cluster of worker processes with the file
descriptors they need, deaf to the terminal's signals (the command stops them in order), their logs quiet."""

from __future__ import annotations

import contextlib
import logging
import os
import re
import resource
import signal
import socket
import threading
import warnings
from collections.abc import Iterator

from ..errors import InputError
from ..io.foreign_libraries import require


#: the signals a terminal sends to every process of the command (Ctrl-C, a closed terminal): the local workers
#: ignore them, and the command, which gets them too, stops them in order
_TERMINAL_SIGNALS = tuple(getattr(signal, name) for name in ("SIGINT", "SIGHUP") if hasattr(signal, name))


@contextlib.contextmanager
def _quiet_dask() -> Iterator[None]:
    """Dask's own log lines (a worker killed on shutdown, a lost connection when the command is stopped) kept
    from the user for the block: what matters reaches the command as an outcome or an exception."""
    loggers = [logging.getLogger(name) for name in ("distributed", "asyncio", "tornado")]
    levels = [logger.level for logger in loggers]
    for logger in loggers:
        logger.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        for logger, level in zip(loggers, levels):
            logger.setLevel(level)


#: file descriptors a local Dask cluster takes: the scheduler's and the client's, and each worker's connections
DESCRIPTORS_BASE = 128


DESCRIPTORS_PER_WORKER = 32


def _require_descriptors(workers: int) -> None:
    """Refuse in one line, before Dask starts, a process that may not open enough files at once for a local
    cluster of ``workers`` (Dask then fails in its event loop, each failure a log line, and the store cannot be
    opened)."""
    soft, _ = resource.getrlimit(resource.RLIMIT_NOFILE)
    needed = DESCRIPTORS_BASE + DESCRIPTORS_PER_WORKER * workers
    if soft != resource.RLIM_INFINITY and soft < needed:
        raise InputError(
            f"scheduler: local: this process may open {soft} files at once (ulimit -n), and a local "
            f"Dask cluster of {workers} worker(s) needs about {needed}: raise the limit, use fewer "
            "workers, or the serial scheduler, which fits without Dask"
        )


def _cluster_error(exc: BaseException) -> InputError:
    """One line for a local Dask cluster that did not start, naming the machine's limit behind it where the
    cause says (too many open files, no memory or threads)."""
    causes, seen = [], exc
    while seen is not None and len(causes) < 10:
        causes.append(f"{type(seen).__name__}: {seen}")
        seen = seen.__cause__ or seen.__context__
    text = " / ".join(causes)
    if re.search(r"too many open files|EMFILE", text, re.IGNORECASE):
        why = "too many files open at once for this machine's limit (ulimit -n); raise it, or run with fewer workers"
    elif re.search(r"memory|can't start new thread|resource temporarily unavailable", text, re.IGNORECASE):
        why = "not enough memory or threads for the workers; run with fewer workers or a lower memory limit"
    else:
        why = f"{causes[0][:160]}"
    return InputError(
        f"scheduler: local: the Dask workers did not start ({why}); the serial scheduler fits without Dask"
    )


def _quiet_worker() -> None:
    """Run in each local worker: Dask's log lines there kept from the user's terminal, as in the command."""
    logging.getLogger("distributed").setLevel(logging.CRITICAL + 1)


@contextlib.contextmanager
def _workers_deaf_to_the_terminal() -> Iterator[None]:
    """Start processes that ignore Ctrl-C and a closed terminal (an ignored signal stays ignored in a spawned
    process): the command gets those signals and stops its workers in order, instead of each worker printing its
    own traceback. While the workers start (a second or two), the command ignores them too: a Ctrl-C then is
    lost, the next one stops it."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {sig: signal.signal(sig, signal.SIG_IGN) for sig in _TERMINAL_SIGNALS}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


@contextlib.contextmanager
def dask_client(distributed, scheduler: str, workers: int | None, memory_limit: str | int):
    if scheduler == "local":
        _require_descriptors(workers or os.cpu_count() or 1)
        config = require("dask.config", "fleet", "fitting a fleet on Dask")
        # Dask's statistical profiler samples every task's stack every 10 ms: 10 % of a fleet's time on 2 cores
        with _quiet_dask():
            with (
                warnings.catch_warnings(),
                config.set(
                    {"distributed.worker.profile.enabled": False, "distributed.scheduler.worker-saturation": 1.0}
                ),
                _workers_deaf_to_the_terminal(),
            ):
                warnings.simplefilter("ignore")  # Dask's notes on ports and the dashboard are not the user's concern
                try:
                    cluster = distributed.LocalCluster(
                        n_workers=workers or os.cpu_count() or 1,
                        threads_per_worker=1,
                        processes=True,
                        memory_limit=memory_limit,
                        dashboard_address=None,
                    )
                except Exception as exc:  # noqa: BLE001 - Dask wraps the cause (files, memory) in its own errors
                    raise _cluster_error(exc) from None
            with cluster, distributed.Client(cluster) as client:
                client.run(_quiet_worker)  # and the workers' own log lines (tasks cancelled when the command stops)
                yield client
        return
    try:
        client = distributed.Client(scheduler, timeout="10s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError(f"scheduler: cannot reach a Dask scheduler at {scheduler!r} ({exc})") from None
    with client:
        yield client


def check_reachable(address: str) -> None:
    """Refuse at once a TCP scheduler address nothing listens on (Dask would retry until its timeout)."""
    m = re.fullmatch(r"(?:tcp://)?\[?([^\]\s]+?)\]?:(\d+)", address.strip())
    if m is None:
        if "://" not in address:
            raise InputError(f"scheduler: {address!r}; use local, serial or a Dask scheduler address (tcp://host:8786)")
        return  # another protocol (tls://, ucx://, inproc://): Dask connects and reports
    try:
        socket.create_connection((m.group(1), int(m.group(2))), timeout=10).close()
    except OSError as exc:
        raise InputError(f"scheduler: cannot reach a Dask scheduler at {address!r} ({exc.strerror or exc})") from None


__all__ = ["check_reachable", "dask_client", "DESCRIPTORS_BASE", "DESCRIPTORS_PER_WORKER"]
