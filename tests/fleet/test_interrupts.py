"""A fleet on Dask stopped by Ctrl-C (to the whole process group, as a terminal sends it), SIGTERM or SIGHUP, or
started without enough file descriptors: one line on stderr, none of Dask's own log lines or tracebacks, the
store as consistent as before (the rerun fits what was not finished)."""

from __future__ import annotations

import contextlib
import os
import resource
import signal
import subprocess
import time

import pytest

from gyrocomp.fleet import CalibrationStore
from gyrocomp.io.tables import write_recording
from gyrocomp.simulation import simulate

from ..conftest import SCRIPT

UNITS = 16


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    folder = tmp_path_factory.mktemp("interrupted")
    for k in range(UNITS):
        (folder / f"SN{k:02d}").mkdir()
        recording = simulate("consumer", profile="chamber", duration_s=3600, rate_hz=5, seed=k).recording
        write_recording(recording, folder / f"SN{k:02d}" / "run_1.csv")
    return folder


def _start(fleet, out, **popen):
    return subprocess.Popen(
        [
            str(SCRIPT),
            "fleet",
            "fit",
            str(fleet),
            "--unit-from",
            "{serial}/run_{n}.csv",
            "-o",
            str(out),
            "--scheduler",
            "local",
            "--workers",
            "2",
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        **popen,
    )


def _only_line(stderr: str, message: str) -> None:
    lines = [line for line in stderr.splitlines() if not line.startswith("gyrocomp: warning")]
    assert lines == [line for line in lines if line.startswith("gyrocomp: ")] and len(lines) == 1, stderr
    assert message in lines[0], stderr
    assert "distributed" not in stderr and "Traceback" not in stderr


@pytest.mark.slow
@pytest.mark.parametrize(
    "stop, message, status",
    [
        ("group SIGINT", "gyrocomp: interrupted (Ctrl-C); outputs not finished were removed", 130),
        ("SIGTERM", "gyrocomp: stopped by SIGTERM; outputs not finished were removed", 143),
    ],
)
def test_a_fleet_stopped_says_so_in_one_line_and_the_rerun_finishes(fleet, tmp_path, stop, message, status):
    out = tmp_path / "out"
    # a terminal's Ctrl-C reaches every process of the command: its own session, SIGINT to the whole group
    process = _start(
        fleet, out, start_new_session=True, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL)
    )
    time.sleep(1.0)
    # as a user would, again every half second until it stops: while the workers start (a second or two), the
    # command ignores the terminal's signals, so that the workers it spawns ignore them too
    while process.poll() is None:
        if stop == "group SIGINT":
            os.killpg(process.pid, signal.SIGINT)
        else:
            process.send_signal(getattr(signal, stop))
        with contextlib.suppress(subprocess.TimeoutExpired):
            process.wait(timeout=0.5)  # a second signal during the way out is ignored: the cleanup finishes
    stderr = process.communicate(timeout=120)[1]
    assert process.returncode == status, stderr
    _only_line(stderr, message)
    assert not [p for p in out.rglob("*") if p.name.startswith(".gyrocomp-")]  # no temporary file left
    if stop != "group SIGINT":
        return  # the rerun after one stop is enough
    rerun = _start(fleet, out)
    assert rerun.wait(timeout=300) == 0, rerun.stderr.read()
    with CalibrationStore(out / "calibrations.sqlite") as store:
        assert sorted(record.serial for record in store.latest_rows()) == [f"SN{k:02d}" for k in range(UNITS)]


@pytest.mark.slow
def test_too_few_file_descriptors_for_the_workers_is_one_line(fleet, tmp_path):
    process = _start(fleet, tmp_path / "out", preexec_fn=lambda: resource.setrlimit(resource.RLIMIT_NOFILE, (40, 40)))
    stderr = process.communicate(timeout=120)[1]
    assert process.returncode == 2, stderr
    _only_line(
        stderr,
        "--scheduler: local: this process may open 40 files at once (ulimit -n), and a local Dask "
        "cluster of 2 worker(s) needs about 192: raise the limit",
    )


def test_a_command_stopped_by_sighup_says_so_in_one_line(tmp_path):
    """A closed terminal (SIGHUP) on a long simulation: one line, no output left behind."""
    process = subprocess.Popen(
        [
            str(SCRIPT),
            "simulate",
            "--profile",
            "chamber",
            "--duration",
            "4e6",
            "--rate",
            "10",
            "-o",
            str(tmp_path / "long.csv"),
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    time.sleep(1.5)
    process.send_signal(signal.SIGHUP)
    stderr = process.communicate(timeout=60)[1]
    assert process.returncode == 129, stderr
    _only_line(stderr, "gyrocomp: stopped by SIGHUP; outputs not finished were removed")
    assert list(tmp_path.iterdir()) == []
