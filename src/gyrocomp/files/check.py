"""The data check of run files (:mod:`gyrocomp.measures.data_check`): read each run, keep what the reader said
(its time-order notes) and what it refused, and judge the runs against what the fit asks."""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable, Iterable, Sequence

from ..errors import DataQualityWarning, InputError, user_stacklevel
from ..io import ReadOptions
from ..io.tables import release_table_memory
from .chunks import read_whole
from ..measures.data_check import Ask, CheckedRun, RunCheck, check_runs
from ..models.options import FitOptions, Network, Polynomial


def ask_for(options: FitOptions | None = None) -> Ask:
    """What a fit with ``options`` asks of its runs (default: ``gyrocomp fit``'s defaults): whether a temperature
    curve, turning-point hysteresis explicitly, and the curve's parameters (an automatic choice: a line at least,
    the choice going no further than the data allow; a curve of size N: N + 1, as a polynomial of order N or a table
    of N intervals has)."""
    options = options or FitOptions()
    spec = options.temperature
    if spec is None:
        return Ask(temperature="none")
    if isinstance(spec, Network):
        widths = (1, *spec.hidden, 1)
        parameters = sum(a * b + b for a, b in zip(widths[:-1], widths[1:]))
    else:
        size = spec.order if isinstance(spec, Polynomial) else spec.size
        parameters = 2 if size == "auto" else int(size) + 1
    automatic = isinstance(spec, Polynomial) and spec.order == "auto"
    return Ask(
        temperature="auto" if automatic else "asked",
        hysteresis=options.hysteresis.startswith("turning-"),
        parameters=parameters,
    )


def read_checked(path: str | os.PathLike, options: ReadOptions | None = None, fmt: str | None = None) -> CheckedRun:
    """Read one run for the check: its recording and the reader's warnings, or the reader's refusal (a large file
    gathered from its chunks, as a fit reads it: :func:`gyrocomp.files.chunks.read_whole`)."""
    try:
        return _noted(lambda p: read_whole(p, options or ReadOptions(), fmt=fmt), path)
    except InputError as exc:
        return CheckedRun(os.fspath(path), None, refusal=str(exc))


def _noted(read, path: str | os.PathLike) -> CheckedRun:
    """``read(path)``'s recording with the warnings the reader gave, kept (not shown)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        recording = read(path).recording
    release_table_memory()
    return CheckedRun(os.fspath(path), recording, tuple(w.message for w in caught))


def check_files(
    paths: Sequence[str | os.PathLike],
    options: ReadOptions | Callable[[str | os.PathLike], ReadOptions] | None = None,
    fmt: str | None = None,
    ask: Ask | None = None,
    accept: Iterable[str] = (),
) -> tuple[list[CheckedRun], list[RunCheck]]:
    """Read and check ``paths`` as one set of runs (one unit's): the runs as read and their checks (``ask``:
    default, ``gyrocomp fit``'s defaults). ``options``: the reading options, or a function giving each path's."""
    runs = [read_checked(p, options(p) if callable(options) else options, fmt) for p in paths]
    return runs, check_runs(runs, ask or ask_for(), accept)


#: the checks whose warnings another part already gives (the reader: gaps and time order; the plausibility checks
#: of a fit: too little span): :func:`warn_findings` does not say them twice
SAID_ELSEWHERE = frozenset({"gaps", "time", "temperature-span"})


def enforce(checks: Sequence[RunCheck]) -> None:
    """Refuse the first refused run in one line (naming the check to accept), then warn of the findings of the
    others (:func:`refuse`, :func:`warn_findings`)."""
    refuse(checks)
    warn_findings(checks)


def refuse(checks: Sequence[RunCheck]) -> None:
    """Raise :class:`InputError` for the first refused run: its first refusal, and the check to accept."""
    for c in checks:
        if c.verdict == "refused":
            first = next(f for f in c.findings if f.severity == "refuse")
            raise InputError(f"{first.message}: refused by the data check (accept={first.check} fits it anyway)")


def warn_findings(checks: Sequence[RunCheck]) -> None:
    """Warn once for each finding (:class:`DataQualityWarning`, with its expected cost) not said elsewhere."""
    for c in checks:
        for f in c.findings:
            if f.check not in SAID_ELSEWHERE:
                warnings.warn(f"{f.text()} (data check '{f.check}')", DataQualityWarning, stacklevel=user_stacklevel())


def read_noting(read, path: str | os.PathLike) -> CheckedRun:
    """``read(path)`` (a :class:`gyrocomp.io.InputData`'s maker) kept for the check with what the reader said,
    which is said again as it was."""
    run = _noted(read, path)
    rewarn([run])
    return run


def rewarn(runs: Iterable[CheckedRun]) -> None:
    """Say again what the reader said of each run (it was kept while the runs were checked)."""
    for run in runs:
        for note in run.notes:
            warnings.warn(note, stacklevel=user_stacklevel())


__all__ = [
    "SAID_ELSEWHERE",
    "ask_for",
    "check_files",
    "enforce",
    "read_checked",
    "read_noting",
    "refuse",
    "rewarn",
    "warn_findings",
]
