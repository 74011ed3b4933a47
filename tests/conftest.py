"""Shared fixtures: simulated runs with known truth, and the shared datasets (skipped when absent)."""

from __future__ import annotations

import base64
import gc
import importlib
import importlib.util
import io
import locale
import math
import os
import pkgutil
import re
import select
import signal
import subprocess
import sys
import tempfile
import traceback
import warnings
import weakref
from html.parser import HTMLParser
from pathlib import Path

#: ``make test`` runs two processes on two cores: each holds the numeric libraries to one thread, as a command of
#: gyrocomp does (``cli.entry_point.one_thread_per_pool``), and so do the commands and interpreters they start
#: (two BLAS threads in each process, spinning while they waited for each other, made two processes' planning tests
#: 3.6 times slower than one's); a setting already in the environment is kept
for _pool in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_pool, "1")

import numpy as np  # noqa: E402 - after the thread pools' setting, which numpy's BLAS reads when it loads
import pytest  # noqa: E402
from threadpoolctl import threadpool_limits  # noqa: E402

from gyrocomp import Compensator, apply  # noqa: E402
from gyrocomp.models.fit import fit_channels  # noqa: E402
from gyrocomp.recording import ACCEL_AXES, GYRO_AXES, Recording  # noqa: E402
from gyrocomp.simulation import GyroErrorModel, simulate  # noqa: E402

if os.environ["OPENBLAS_NUM_THREADS"] == "1":
    threadpool_limits(1, user_api="blas")  # a BLAS a plugin loaded before the setting above

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"
DATASETS = SHARED / "datasets"


#: the test modules that take a minute or more in all (real recordings, many seeds, a fleet): collected first, so
#: that ``make test``'s two processes (which share whole modules out as they come free) never end with one of them
#: running such a module alone while the other waits
HEAVY_FIRST = ("tests/real/", "tests/models/test_few_runs.py", "tests/fleet/", "tests/fitting/test_order_evidence.py")


def pytest_collection_modifyitems(config, items):
    items.sort(key=lambda item: not item.nodeid.startswith(HEAVY_FIRST))  # stable: each group keeps its order


#: test modules that share a session fixture too costly to build twice, sent to one process of ``make test``
#: together (the fleet fitted once: tests/fleet/conftest.py's ``fleet_run``, about 35 s)
SAME_PROCESS = {"tests/fleet/test_prior.py": "tests/fleet/test_fleet_fit.py"}


def pytest_xdist_make_scheduler(config, log):
    """``--dist loadfile`` (each test module in one process), with the modules of :data:`SAME_PROCESS` in one
    process together."""
    from xdist.scheduler import LoadFileScheduling

    class SharedFixtureFiles(LoadFileScheduling):
        def _split_scope(self, nodeid: str) -> str:
            scope = super()._split_scope(nodeid)
            return SAME_PROCESS.get(scope, scope)

    return SharedFixtureFiles(config, log)


def shared_dataset(name: str) -> Path:
    """Path of a folder in ../shared/datasets, or skip the test with a message saying what is missing."""
    path = DATASETS / name
    if not path.is_dir():
        pytest.skip(f"shared dataset {name!r} not found at {path}; these tests need ../shared beside the repository")
    return path


def xsens_session():
    """imu_tk's Xsens multi-position session (../shared/datasets/imu_tk-xsens) as a Recording: raw 16-bit counts
    around 32768, scaled by nominal factors only (about 3700 counts per g, imu_tk's 1/6258 (rad/s)/count); the
    calibrations find the real ones. Skips when the dataset is absent."""
    folder = shared_dataset("imu_tk-xsens")
    acc = np.loadtxt(folder / "xsens_acc.mat")
    gyro = np.loadtxt(folder / "xsens_gyro.mat")
    return Recording(
        acc[:, 0],
        np.degrees((gyro[:, 1:] - 32768) / 6258),
        GYRO_AXES,
        accel_g=(acc[:, 1:] - 32768) / 3700.0,
        accel_axes=ACCEL_AXES,
        source="xsens",
    )


@pytest.fixture(scope="session")
def consumer_model():
    """A consumer part's default model (thermal lag included), fitted on two 1-hour chamber runs at 2 Hz (unit 3,
    seeds 0 and 1); the model the chunked paths (apply_file, evaluate_file) are checked with."""
    runs = [
        simulate("consumer", profile="chamber", rate_hz=2, duration_s=3600, seed=s, unit=3).recording for s in range(2)
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit_channels(runs)


#: the test sensor: MTi-10-class temperature drift, moderate bias instability
TEST_MODEL = GyroErrorModel(bias_instability_deg_per_h=5.0)


@pytest.fixture(scope="session")
def chamber_runs():
    """Seven 1-hour chamber runs at 20 Hz of TEST_MODEL (seeds 0..6), each with its own turn-on bias."""
    return [simulate(TEST_MODEL, profile="chamber", duration_s=3600, rate_hz=20, seed=s) for s in range(7)]


def assert_streaming_equals_batch(calibration, recording, cuts: list[int]) -> None:
    """Compensate ``recording`` in chunks of the lengths ``cuts`` (the rest in one) through a Compensator and
    check the output equals ``apply`` on the whole recording to 1e-12 [deg/s]."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        batch = apply(calibration, recording).gyro_dps
        comp = Compensator(calibration, recording.gyro_axes, rate_hz=recording.rate_hz)
        parts, start = [], 0
        for c in list(cuts) + [recording.n_samples]:
            stop = min(start + c, recording.n_samples)
            if stop > start:
                parts.append(
                    comp.update(
                        recording.time_s[start:stop],
                        recording.gyro_dps[start:stop],
                        recording.temperature_degc[start:stop],
                    )
                )
            start = stop
    np.testing.assert_allclose(np.concatenate(parts), batch, rtol=0, atol=1e-12)


#: the console script of this environment, run as a user would
SCRIPT = Path(sys.executable).parent / "gyrocomp"


def run(*args, cwd=None, fresh: bool = False) -> subprocess.CompletedProcess:
    """Run the ``gyrocomp`` command through its real entry point (:func:`gyrocomp.cli.main`, the console script's)
    in a child process: stdout, stderr and the exit status as :func:`subprocess.run` gives them (wide terminal,
    300 s limit).

    The child is forked from this test process, whose numeric libraries are already loaded (the suite runs the
    command some 440 times, and a new interpreter's imports took most of each short run); it starts as a new one
    would: stdin empty, stdout and stderr files, Python's default warning filters, numpy's default error handling,
    ``sys.argv`` as the script sees it, and it ends with ``os._exit``, after the finalizers its command registered
    (a spilled series' folder) have run. ``fresh`` (and ``fleet fit`` on Dask, whose thread pools and event loops
    must not be inherited) runs the console script in a new interpreter instead; tests/cli/test_entry.py checks the two
    give the same output, byte for byte."""
    argv = [os.fspath(a) if isinstance(a, os.PathLike) else str(a) for a in args]
    if fresh or not hasattr(os, "fork") or _on_dask(argv):
        cmd = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "gyrocomp"]
        env = {**os.environ, "COLUMNS": "200"}
        return subprocess.run([*cmd, *argv], capture_output=True, text=True, cwd=cwd, env=env, timeout=300)
    return _run_forked(argv, cwd, timeout_s=300.0)


def _on_dask(argv: list[str]) -> bool:
    """Whether the command is a ``fleet fit`` on Dask (any scheduler but ``serial``), after the group's options
    or not."""
    if ["fleet", "fit"] not in [argv[k : k + 2] for k in range(len(argv) - 1)]:
        return False
    scheduler = [b for a, b in zip(argv, argv[1:]) if a == "--scheduler"]
    scheduler += [a.split("=", 1)[1] for a in argv if a.startswith("--scheduler=")]
    return scheduler[-1:] != ["serial"]


#: the warning filters a new interpreter starts with (``python -c "import warnings; print(warnings.filters)"``,
#: no -W and no PYTHONWARNINGS), applied in the forked command in place of pytest's
_DEFAULT_WARNING_FILTERS = (
    ("default", DeprecationWarning, "__main__"),
    ("ignore", DeprecationWarning, ""),
    ("ignore", PendingDeprecationWarning, ""),
    ("ignore", ImportWarning, ""),
    ("ignore", ResourceWarning, ""),
)
_prewarmed = False


def _prewarm() -> None:
    """Import every module of gyrocomp (and with them the libraries each command loads) once in this process,
    before the first fork, so that no forked command imports them again."""
    global _prewarmed
    if _prewarmed:
        return
    import gyrocomp

    for module in pkgutil.walk_packages(gyrocomp.__path__, "gyrocomp."):
        if module.name != "gyrocomp.__main__":
            try:
                importlib.import_module(module.name)
            except ImportError:  # an optional extra not installed: the command that needs it says so itself
                pass
    _prewarmed = True


def _run_forked(argv: list[str], cwd, timeout_s: float) -> subprocess.CompletedProcess:
    _prewarm()
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        for stream in (sys.stdout, sys.stderr, sys.__stdout__, sys.__stderr__):
            if stream is not None:
                stream.flush()
        pid = os.fork()
        if pid == 0:  # the child: never back into pytest
            status = 1
            try:
                status = _forked_command(argv, cwd, out.fileno(), err.fileno())
            except BaseException:  # noqa: BLE001 - said on the command's stderr, status 1
                traceback.print_exc()
            finally:
                os._exit(status)
        status = _wait(pid, timeout_s, argv)
        out.seek(0)
        err.seek(0)
        return subprocess.CompletedProcess(["gyrocomp", *argv], status, _as_text(out.read()), _as_text(err.read()))


def _forked_command(argv: list[str], cwd, out_fd: int, err_fd: int) -> int:
    """In the forked child: the command run as the console script would run it; its exit status."""
    stdin = os.open(os.devnull, os.O_RDONLY)
    os.dup2(stdin, 0)
    os.dup2(out_fd, 1)
    os.dup2(err_fd, 2)
    sys.stdin = open(0, closefd=False)  # noqa: SIM115 - the process's streams, as a new interpreter opens them
    sys.stdout = open(1, "w", closefd=False)  # noqa: SIM115
    sys.stderr = open(2, "w", buffering=1, errors="backslashreplace", closefd=False)  # noqa: SIM115
    if cwd is not None:
        os.chdir(cwd)
    os.environ["COLUMNS"] = "200"
    sys.argv = [str(SCRIPT), *argv]
    warnings.resetwarnings()
    for action, category, module in reversed(_DEFAULT_WARNING_FILTERS):
        warnings.filterwarnings(action, category=category, module=module)
    np.seterr(all="warn", under="ignore")
    entry_point = importlib.import_module("gyrocomp.cli.entry_point")
    entry_point._LOOKED_UP.clear()  # what earlier in-process commands looked up is not this command's
    inherited = set(weakref.finalize._registry)
    try:
        entry_point.main()
        status = 0
    except SystemExit as exc:
        status = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        if not isinstance(exc.code, (int, type(None))):
            print(exc.code, file=sys.stderr)
    gc.collect()
    for finalizer in [f for f in list(weakref.finalize._registry) if f not in inherited]:
        if finalizer.atexit:
            finalizer()
    sys.stdout.flush()
    sys.stderr.flush()
    return status


def _wait(pid: int, timeout_s: float, argv: list[str]) -> int:
    """The forked command's exit status (as subprocess gives it: -N when killed by signal N), killing it after
    ``timeout_s`` [s] as subprocess.run's timeout does."""
    try:
        handle = os.pidfd_open(pid)
    except (AttributeError, OSError):  # before Linux 5.3: waited for without a limit
        handle = None
    if handle is not None:
        try:
            if not select.select([handle], [], [], timeout_s)[0]:
                os.kill(pid, signal.SIGKILL)
                os.waitpid(pid, 0)
                raise subprocess.TimeoutExpired(["gyrocomp", *argv], timeout_s)
        finally:
            os.close(handle)
    return os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1])


def _as_text(data: bytes) -> str:
    """Bytes decoded as subprocess.run(text=True) decodes them (the locale's encoding, universal newlines)."""
    text = data.decode(locale.getpreferredencoding(False))
    return text.replace("\r\n", "\n").replace("\r", "\n")


class ReportPage(HTMLParser):
    """An HTML report's sections (their ids), images (their sources) and other links, in order."""

    def __init__(self):
        super().__init__()
        self.sections, self.images, self.links, self.heads = [], [], [], 0

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "section":
            self.sections.append(attrs["id"])
        if tag == "img":
            self.images.append(attrs["src"])
        for key in ("href", "src"):
            if key in attrs and tag != "img":
                self.links.append(attrs[key])


def report_sections(text: str) -> list[str]:
    """The ids of an HTML report's sections, in order."""
    page = ReportPage()
    page.feed(text)
    return page.sections


def check_report_page(text: str, expected_sections: list[str]) -> ReportPage:
    """An HTML report holds these sections, drawn figures (PNG data, not blank) and no link off the page."""
    matplotlib_image = pytest.importorskip("matplotlib.image", reason="the report's figures are read with matplotlib")
    page = ReportPage()
    page.feed(text)
    assert page.sections == expected_sections
    assert page.images, "no figure in the report"
    for src in page.images:
        assert src.startswith("data:image/png;base64,")
        image = matplotlib_image.imread(io.BytesIO(base64.b64decode(src.split(",", 1)[1])), format="png")
        assert image.ndim == 3 and image.shape[0] > 100 and image.shape[1] > 100
        assert np.ptp(image[..., :3]) > 0.5  # drawn, not blank
    assert all(link.startswith("#") for link in page.links)  # only links within the page
    assert not re.search(r"(https?:)?//[a-z0-9]", re.sub(r"data:image/png;base64,[A-Za-z0-9+/=]+", "", text))
    return page


def joined_recordings(pieces, gap_s):
    """Recordings one after another, each next one starting gap_s after the previous ended."""
    times, gyro, temps, start = [], [], [], 0.0
    for rec in pieces:
        t = rec.time_s - rec.time_s[0] + start
        times.append(t)
        gyro.append(rec.gyro_dps)
        temps.append(rec.temperature_degc)
        start = t[-1] + gap_s
    return Recording(
        np.concatenate(times),
        np.concatenate(gyro),
        pieces[0].gyro_axes,
        temperature_degc=np.concatenate(temps),
        source="joined",
    )


def static_recording(n=60_000, rate_hz=50.0, gap_after=None, seed=0) -> Recording:
    """A still unit: gyro_x and gyro_z white noise of N = 0.01 deg/s/sqrt(Hz), the accelerometer 1e-3 g noise about
    (0, 0, 1) g; ``gap_after``: a 10 s hole after that sample."""
    rng = np.random.default_rng(seed)
    time_s = np.arange(n) / rate_hz
    if gap_after is not None:
        time_s[gap_after:] += 10.0  # a 10 s hole
    gyro = rng.standard_normal((n, 2)) * 0.01 * math.sqrt(rate_hz)  # N = 0.01 deg/s/sqrt(Hz)
    accel = np.column_stack(
        [rng.standard_normal(n) * 1e-3, rng.standard_normal(n) * 1e-3, 1.0 + rng.standard_normal(n) * 1e-3]
    )
    return Recording(
        time_s=time_s,
        gyro_dps=gyro,
        gyro_axes=("gyro_x", "gyro_z"),
        accel_g=accel,
        accel_axes=("accel_x", "accel_y", "accel_z"),
        source="static.csv",
    )


def burst_stamped_recording(rate_hz: float, n: int, burst: int, arrival_step_s: float) -> Recording:
    """A sensor sampling evenly at ``rate_hz`` [Hz] whose samples reach the logger ``burst`` at a time (when the
    last of them is taken), stamped on arrival ``arrival_step_s`` [s] apart (a serial link's buffer)."""
    arrival = np.repeat(np.arange(burst - 1, n + burst, burst) / rate_hz, burst)[:n]
    within = np.tile(np.arange(burst) * arrival_step_s, n // burst + 1)[:n]
    return Recording(time_s=arrival + within, gyro_dps=np.zeros((n, 1)), gyro_axes=("gyro_z",), source="b.csv")


# -- a throwaway PostgreSQL server ------------------------------------------------------------------------------
def _tool(name: str):
    """The module tools/NAME.py (the project's scripts beside the package), loaded once."""
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, Path(__file__).parents[1] / "tools" / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]


postgres_cluster = _tool("postgres_cluster")
#: headless Chromium driven over its DevTools pipe (tools/browser.py): the browser tests
browser = _tool("browser")
#: every command on every shape of input (tools/shape_matrix.py): its runs written from the physics, none of
#: gyrocomp's model forms (a tanh of a lagged die temperature, a rate-of-change term, a power-on constant)
shape_matrix = _tool("shape_matrix")
chamber_run = shape_matrix.chamber_run


@pytest.fixture(scope="session")
def postgres_server():
    """A PostgreSQL cluster of its own (tools/postgres_cluster.py): yields a function that makes a new empty
    database and returns its URL. Skipped with the reason where no server binaries or no driver exist."""
    if postgres_cluster.binaries() is None:
        pytest.skip("no PostgreSQL server binaries (initdb, pg_ctl) on this machine")
    if importlib.util.find_spec("psycopg") is None:
        pytest.skip("psycopg is not installed (pip install 'gyrocomp[postgresql]')")
    with postgres_cluster.throwaway_cluster() as new_database:
        yield new_database


@pytest.fixture(params=["sqlite", "postgresql"])
def store_location(request, tmp_path):
    """A new, empty calibration store's location on each backend: a fleet folder (SQLite), a PostgreSQL URL."""
    if request.param == "sqlite":
        return str(tmp_path / "FLEET")
    return request.getfixturevalue("postgres_server")()
