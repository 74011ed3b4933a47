"""What every command does with bad input, a refused write, a signal: one line, status 2, nothing lost (run through
the real entry point in a subprocess)."""

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from gyrocomp.calibration import SCHEMA_VERSION
from gyrocomp.cli import in_cli_words
from gyrocomp.cli.entry_point import _environment_message
from gyrocomp.cli.apply import apply
from gyrocomp.cli.evaluate import evaluate
from gyrocomp.cli.fit import fit

from ..conftest import SCRIPT, run


ERROR_CASES = {
    "empty": ("", r"empty.csv: the file is empty"),
    "header_only": ("time,gyro_z,temperature\n", r"header_only.csv: a header but no data rows"),
    "no_temperature": ("time,gyro_z\n0,1\n1,2\n2,3\n", r"no_temperature.csv: no temperature column"),
    "text_in_number": (
        "time,gyro_z,temperature\n0,1,20\n1,x1,21\n2,1,22\n",
        r"text_in_number.csv: row 2 \(line 3\), column 'gyro_z': 'x1' is not a number",
    ),
    "nan_rows": (
        "time,gyro_z,temperature\n0,1,20\n1,NaN,21\n2,1,22\n",
        r"nan_rows.csv: row 2, column 'gyro_z': nan is not a finite number; fix the file or drop such rows explicitly \(--drop-nan\)",
    ),
    "time_backwards": (
        "time,gyro_z,temperature\n0,1,20\n1,1,21\n0.5,1,22\n",
        r"time_backwards.csv: row 3: time goes backwards \(0.5 s after 1 s\)",
    ),
}


@pytest.mark.parametrize("name", sorted(ERROR_CASES))
def test_bad_inputs_give_one_line_and_status_2(tmp_path, name):
    text, message = ERROR_CASES[name]
    (tmp_path / f"{name}.csv").write_text(text)
    r = run("fit", tmp_path / f"{name}.csv", "-o", tmp_path / "m.json")
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    assert lines[0].startswith("gyrocomp: error: ")
    assert re.search(message, lines[0]), lines[0]
    assert "Traceback" not in r.stderr
    assert not (tmp_path / "m.json").exists()


def test_debug_shows_traceback(tmp_path):
    (tmp_path / "e.csv").write_text("")
    r = run("--debug", "fit", tmp_path / "e.csv", "-o", tmp_path / "m.json")
    assert r.returncode == 2 and "Traceback" in r.stderr


def test_drop_nan_reports_and_proceeds(tmp_path):
    (tmp_path / "n.csv").write_text("time,gyro_z,temperature\n0,1,20\n1,NaN,21\n2,1,22\n3,2,23\n")
    r = run("fit", tmp_path / "n.csv", "-o", tmp_path / "m.json", "--drop-nan", "--temperature", "poly:1")
    assert r.returncode == 0, r.stderr
    assert "gyrocomp: warning: " in r.stderr and "dropped 1 of 4 rows" in r.stderr


@pytest.mark.parametrize(
    "edit,message",
    [
        (
            lambda t: t.replace(f'"schema_version": {SCHEMA_VERSION}', '"schema_version": 99'),
            r"written with model schema 99, .*upgrade gyrocomp",
        ),
        (lambda t: t[: len(t) // 2], r"not valid JSON \(line \d+, column \d+: .*\); the file may be truncated"),
    ],
)
def test_bad_model_files(workdir, tmp_path, edit, message):
    (tmp_path / "bad.json").write_text(edit((workdir / "model.json").read_text()))
    r = run("apply", tmp_path / "bad.json", workdir / "run3.csv", "-o", tmp_path / "o.csv")
    assert r.returncode == 2
    assert re.search(message, r.stderr.strip()) and len(r.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "o.csv").exists()


def test_refuses_to_overwrite_input(workdir, tmp_path):
    src = tmp_path / "in.csv"
    shutil.copy(workdir / "run3.csv", src)
    before = src.read_bytes()
    r = run("apply", workdir / "model.json", src, "-o", src)
    assert r.returncode == 2
    assert "this is an input file; choose another output path" in r.stderr
    assert src.read_bytes() == before


@pytest.mark.parametrize(
    "args,message",
    [
        (["simulate", "--duration", "abc", "-o", "x.csv"], r"Invalid value for '--duration': 'abc' is not a number"),
        (["fit", "x.csv"], r"Missing option '-o'"),
        (
            ["fit", "{run}", "-o", "m.json", "--temperature", "poly:7"],
            r"--temperature: 'poly:7': the size of poly must be a whole number from 0 to 5",
        ),
        (["fit", "{run}", "-o", "m.json", "--columns", "gyro_z=Nope"], r"--columns gyro_z=Nope: no column 'Nope'"),
        (["apply", "{model}", "{run}", "-o", "o.csv", "--gyro-unit", "rpm"], r"--gyro-unit: unknown unit 'rpm'"),
        (
            ["apply", "{model}", "{run}", "-o", "o.csv", "--turn-on-window", "-3"],
            r"--turn-on-window: must be a positive",
        ),
        (["evaluate", "{model}", "{run}", "--window", "1e9"], r"--window: 1e\+09 s is longer than the run"),
        (["simulate", "--profile", "oven", "-o", "x.csv"], r"--profile: unknown profile 'oven'"),
        (["simulate", "--axes", "q", "-o", "x.csv"], r"--axes: gyro_q; this part has gyro_x, gyro_y, gyro_z"),
        (["simulate", "--preset", "adxrs450", "--axes", "x", "-o", "x.csv"], r"--axes: gyro_x; this part has gyro_z"),
        (
            ["simulate", "--preset", "mems", "-o", "x.csv"],
            r"--preset: unknown preset 'mems'; use one of adxrs450, mti10",
        ),
        (["simulate", "--runs", "0", "-o", "x.csv"], r"Invalid value for --runs: must be at least 1"),
        (["simulate", "--set-points", "cold", "-o", "x.csv"], r"Invalid value for --set-points: give comma-separated"),
        (["simulate", "--ramp-rate", "0", "-o", "x.csv"], r"--ramp-rate: must be positive, got 0"),
        (["simulate", "--cycles", "0", "-o", "x.csv"], r"--cycles: must be at least 1, got 0"),
        (["simulate", "--unit", "-1", "-o", "x.csv"], r"--unit: must be a whole number >= 0, got -1"),
        (["simulate", "-o", "x.csv", "--truth", "x.csv"], r"--truth x.csv: the same file as a data output"),
        (
            ["fit", "{run}", "-o", "m.json", "--hysteresis", "sometimes"],
            r"Invalid value for '--hysteresis': 'sometimes'",
        ),
        (
            ["fit", "{run}", "-o", "m.json", "--hysteresis-order", "9"],
            r"Invalid value for --hysteresis-order: use auto, 1, 2 or 3",
        ),
        (
            ["fit", "{run}", "-o", "m.json", "--hysteresis-band", "80,55"],
            r"Invalid value for --hysteresis-band: give LO,HI",
        ),
        (["nosuchcommand"], r"No such command 'nosuchcommand'"),
    ],
)
def test_usage_errors(workdir, tmp_path, args, message):
    args = [a.format(run=workdir / "run3.csv", model=workdir / "model.json") for a in args]
    r = run(*args, cwd=tmp_path)
    assert r.returncode == 2, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert re.search(message, r.stderr), r.stderr


def test_version_and_help():
    r = run("--version")
    assert r.returncode == 0 and "gyrocomp" in r.stdout
    r = run("--help")
    assert r.returncode == 0 and "demo" in r.stdout and "evaluate" in r.stdout


def test_a_model_with_nan_coefficients_is_refused_before_anything_is_written(workdir, tmp_path):
    d = json.loads((workdir / "model.json").read_text())
    d["axes"]["gyro_x"]["temperature"]["coefficients_dps"][1] = float("nan")
    (tmp_path / "nan.json").write_text(json.dumps(d))  # Python writes the NaN token JSON readers accept
    r = run("export", tmp_path / "nan.json", "--format", "px4", "-o", tmp_path / "tc.params")
    assert r.returncode == 2 and not (tmp_path / "tc.params").exists()
    assert r.stderr.strip() == (
        f"gyrocomp: error: {tmp_path / 'nan.json'}: "
        "axes.gyro_x.temperature.coefficients_dps[1]: nan is not a finite number"
    )


@pytest.mark.parametrize(
    "message, shown",
    [
        ("window_s: must be positive, got -1", "--window: must be positive, got -1"),
        (
            "a.csv: the model has no curve for gyro_x; give axes= with the axes",
            "a.csv: the model has no curve for gyro_x; give --axes with the axes",
        ),
        (
            "no temperature column (map it with columns={'temperature': 'NAME'}, or fit with temperature=none)",
            "no temperature column (map it with --columns temperature=NAME, or fit with --temperature none)",
        ),
        (
            "row 2: nan (drop such rows explicitly (drop_nonfinite=True))",
            "row 2: nan (drop such rows explicitly (--drop-nan))",
        ),
        ("a.ulg: instance=3: no sensor_gyro instance 3", "a.ulg: --instance 3: no sensor_gyro instance 3"),
        # what is not a parameter stays: axis names, words in file paths, parameters the command line lacks
        (
            "/data/axes: gyro_z: the temperature does not vary; fit_report: x",
            "/data/axes: gyro_z: the temperature does not vary; fit_report: x",
        ),
    ],
)
def test_library_messages_are_shown_with_the_flags_that_set_their_parameters(message, shown):
    assert in_cli_words(message, [evaluate, fit, apply]) == shown


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this platform")
def test_special_outputs_are_refused(workdir, tmp_path):
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    r = run("apply", workdir / "model.json", workdir / "run3.csv", "-o", fifo)
    assert (
        r.returncode == 2
        and r.stderr.strip()
        == f"gyrocomp: error: {fifo}: is a FIFO; outputs are written to regular files (name a new path)"
    )
    assert fifo.is_fifo()
    r = run("apply", workdir / "model.json", workdir / "run3.csv", "-o", "-")
    assert r.returncode == 2 and "-: gyrocomp writes its outputs to files, not to the standard streams" in r.stderr
    assert not Path("-").exists()


@pytest.mark.parametrize(
    "args",
    [
        ["apply", "{model}", "{run}", "-o", "{d}/out.csv/"],
        ["fit", "{run}", "-o", "{d}/m.json/"],
        ["convert", "{run}", "{d}/out.parquet/"],
        ["simulate", "--duration", "60", "-o", "{d}/s.csv/"],
        ["allan", "{run}", "--plot", "{d}/a.png/"],
        ["learn", "{run}", "-o", "{d}/l.json", "--save-state", "{d}/st/"],
    ],
)
def test_an_output_named_as_a_folder_is_refused_before_any_work(workdir, tmp_path, args):
    """``-o out.csv/`` once wrote ``out.csv``: a name ending in / is a folder's, refused naming it as given."""
    r = run(*[a.format(model=workdir / "model.json", run=workdir / "run3.csv", d=tmp_path) for a in args])
    named = next(a for a in args if a.endswith("/")).format(d=tmp_path)
    assert r.returncode == 2 and r.stderr.strip() == (
        f"gyrocomp: error: {named}: names a folder (it ends in /); name the output file itself"
    ), r.stderr
    assert not any(tmp_path.iterdir())


def test_the_standard_streams_are_no_output_and_a_pipe_is_no_input(workdir, tmp_path):
    r = run("apply", workdir / "model.json", workdir / "run3.csv", "-o", "/dev/stdout")
    assert r.returncode == 2 and r.stderr.strip() == (
        "gyrocomp: error: /dev/stdout: gyrocomp writes its outputs to files, not to the standard streams; name a file"
    )
    cmd = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "gyrocomp"]
    data = (workdir / "run3.csv").read_text()
    for given in (["/dev/stdin"], ["/dev/stdin", "--format", "csv"]):  # a pipe, as `cat run.csv | gyrocomp fit`
        r = subprocess.run(
            [*cmd, "fit", *given, "-o", str(tmp_path / "m.json")],
            input=data,
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert r.returncode == 2 and r.stderr.strip() == (
            "gyrocomp: error: /dev/stdin: is a pipe, not a file; gyrocomp reads an input more than once (its first "
            "bytes tell the format, then its rows): save it to a file first"
        ), r.stderr
        assert not (tmp_path / "m.json").exists()


def test_click_lists_its_choices_on_one_line(tmp_path):
    r = run("split", tmp_path / "x.csv", "-o", tmp_path / "parts")
    assert r.returncode == 2 and r.stderr.strip() == (
        "gyrocomp: error: Missing option '--by'. Choose from: power-on, gap, still, temperature-turn"
    )


def _planted(folder: Path, name: str, victim: Path) -> Path:
    """A link named ``name`` in ``folder`` (world-writable and sticky, as /tmp) to ``victim``, as another user
    could plant it where a command's output will go."""
    folder.mkdir(exist_ok=True)
    folder.chmod(0o1777)
    link = folder / name
    link.symlink_to(victim)
    return link


@pytest.mark.slow
def test_no_output_is_written_through_a_planted_link(workdir, tmp_path):
    """Security: an output path that is a symbolic link is refused in one line (exit 2), for every kind of output
    (a table, a model file, a learner state, firmware files, a fleet store); the file the link points at is left
    byte for byte, and so is the link (before: the atomic writer resolved the link and replaced its target, so
    root writing into a sticky folder replaced whatever file another user's link named)."""
    victim = tmp_path / "victim.txt"
    victim.write_text("not yours\n")
    shared = tmp_path / "shared"
    commands = {
        "out.csv": ("apply", workdir / "model.json", workdir / "run3.csv", "-o"),
        "model.json": ("fit", workdir / "run1.csv", workdir / "run2.csv", "-o"),
        "state.json": ("learn", workdir / "run1.csv", "-o", tmp_path / "learned.json", "--save-state"),
        "thermal.params": ("export", workdir / "model.json", "--format", "px4", "-o"),
    }
    for name, command in commands.items():
        link = _planted(shared, name, victim)
        r = run(*command, link)
        assert r.returncode == 2, (name, r.stderr)
        assert r.stderr.strip() == (
            f"gyrocomp: error: {link}: is a symbolic link (to {victim}); outputs are never "
            "written through a link, which could replace a file elsewhere: name the file "
            "itself, or remove the link"
        ), name
        assert victim.read_text() == "not yours\n" and link.is_symlink()
    store = _planted(shared, "store.sqlite", tmp_path / "elsewhere.sqlite")
    units = tmp_path / "units" / "SN1"
    units.mkdir(parents=True)
    shutil.copy(workdir / "run1.csv", units / "run_0.csv")
    r = run(
        "fleet",
        "fit",
        tmp_path / "units",
        "--unit-from",
        "{serial}/run_{n}.csv",
        "-o",
        tmp_path / "fleet",
        "--store",
        store,
        "--scheduler",
        "serial",
    )
    assert r.returncode == 2, r.stderr
    assert r.stderr.strip().splitlines()[-1] == (
        f"gyrocomp: error: {store}: is a symbolic link (to {tmp_path}/"
        "elsewhere.sqlite); calibration stores are never written through a "
        "link, which could replace a file elsewhere: name the file itself, "
        "or remove the link"
    )
    assert not (tmp_path / "elsewhere.sqlite").exists()


def test_sigterm_leaves_no_temporary_file(tmp_path):
    # the console script's signal handling around an atomic write interrupted half-way
    code = (
        "import os, signal, sys; from gyrocomp.cli import entry_point as cli; from gyrocomp.io.atomic import atomic_path\n"
        "cli._exit_on_termination()\n"
        "with atomic_path(sys.argv[1]) as tmp:\n"
        "    tmp.write_text('half')\n"
        "    os.kill(os.getpid(), signal.SIGTERM)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code, str(tmp_path / "out.csv")], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 128 + 15, done.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads files whatever their permissions")
def test_permission_denied_is_a_bad_input_in_one_line(workdir, tmp_path):
    locked = tmp_path / "locked.csv"
    shutil.copy(workdir / "run3.csv", locked)
    locked.chmod(0)
    r = run("apply", workdir / "model.json", locked, "-o", tmp_path / "o.csv")
    assert (
        r.returncode == 2 and r.stderr.strip() == f"gyrocomp: error: {locked}: permission denied; check its permissions"
    )


def test_a_model_that_is_a_symbolic_link_loop(workdir, tmp_path):
    loop = tmp_path / "loop.json"
    loop.symlink_to(loop)
    r = run("apply", loop, workdir / "run3.csv", "-o", tmp_path / "o.csv")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1
    assert (
        r.stderr.strip() == f"gyrocomp: error: {loop}: cannot read the model file (too many levels of symbolic links)"
    )


def test_a_write_the_file_system_refuses_is_a_bad_input_and_leaves_nothing(workdir, tmp_path):
    resource = pytest.importorskip("resource")
    limit = lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (64 * 1024, 64 * 1024))  # noqa: E731 - ulimit -f 64
    done = subprocess.run(
        [
            shutil.which("gyrocomp") or str(Path(sys.executable).with_name("gyrocomp")),
            "apply",
            str(workdir / "model.json"),
            str(workdir / "run3.csv"),
            "-o",
            str(tmp_path / "o.csv"),
        ],
        capture_output=True,
        text=True,
        preexec_fn=limit,
        timeout=300,
    )
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith("gyrocomp: error: ") and "file too large" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "exc, line",
    [
        (PermissionError(13, "Permission denied", "x.csv"), "x.csv: permission denied; check its permissions"),
        (
            OSError(28, "No space left on device", "o.csv"),
            "o.csv: no space left on device; the disk is full; free space and run again",
        ),
        (
            MemoryError(),
            "not enough memory (or threads) for this size of data under this machine's limits; read less at "
            "once (--columns for the channels needed, --time A:B for a stretch, apply streams tables) or "
            "run it where more memory is allowed (ulimit -v)",
        ),
        (RuntimeError("can't start new thread"), "not enough memory (or threads) for this size"),
        (OSError(24, "Too many open files"), "too many files open at once for this machine's limit (ulimit -n)"),
        (OSError("lseek failed"), "lseek failed"),  # a library's OSError without errno: its words, not "oserror"
    ],
)
def test_environment_errors_read_as_one_line(exc, line):
    assert _environment_message(exc).startswith(line)


def test_control_characters_in_a_message_are_escaped_to_keep_one_line(tmp_path):
    """A file name (or a foreign library's message) with a newline or a raw byte stays one escaped line."""
    odd = tmp_path / "two\nlines\x1b.csv"
    odd.write_text("time,gyro_z\n0,1\n")
    result = run("allan", odd)
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and "two\\nlines\\x1b.csv" in result.stderr, result.stderr


@pytest.mark.parametrize(
    "args, message",
    [
        (("simulate", "--rate", "inf", "-o", "x.csv"), "Invalid value for '--rate': inf is not a finite number"),
        (("simulate", "--rate", "nan", "-o", "x.csv"), "Invalid value for '--rate': nan is not a finite number"),
        (
            ("simulate", "--set-points", "10,inf", "-o", "x.csv"),
            "Invalid value for --set-points: '10,inf': give finite",
        ),
        (
            ("simulate", "--duration", "1e999", "-o", "x.csv"),
            "Invalid value for '--duration': inf is not a finite number",
        ),
    ],
)
def test_number_options_are_finite_or_refused_in_one_line(tmp_path, args, message):
    r = run(*args, cwd=tmp_path)
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and message in r.stderr
    assert not (tmp_path / "x.csv").exists()


def test_window_inf_and_learn_rate_0_are_refused(workdir, tmp_path):
    r = run("evaluate", workdir / "model.json", workdir / "run3.csv", "--window", "inf")
    assert r.returncode == 2 and "Invalid value for '--window': inf is not a finite number" in r.stderr
    r = run("learn", workdir / "run1.csv", "--rate", "0", "-o", tmp_path / "m.json")
    assert (
        r.returncode == 2
        and r.stderr.count("\n") == 1
        and "--rate: must be a positive number of Hz up to 1e6, got 0.0" in r.stderr
    )


def test_a_closed_or_full_standard_output_is_no_internal_error(workdir, tmp_path):
    """stdout closed (>&-): the command runs, what it would print goes nowhere (before: an internal error on
    sys.stdout None); stdout on a full disk (> /dev/full): fit fails in one line before it writes the model file
    (before: exit 2 with the model file left); stdout read by head -1: a quiet end, no traceback."""
    exe = shutil.which("gyrocomp") or str(Path(sys.executable).with_name("gyrocomp"))
    closed = subprocess.run(
        [exe, "show", str(workdir / "model.json")],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        timeout=120,
        preexec_fn=lambda: os.close(1),
    )
    assert closed.returncode == 0 and "internal error" not in closed.stderr, closed.stderr
    if Path("/dev/full").exists():
        with open("/dev/full", "w") as full:
            done = subprocess.run(
                [exe, "fit", str(workdir / "run1.csv"), str(workdir / "run2.csv"), "-o", str(tmp_path / "m.json")],
                stdout=full,
                stderr=subprocess.PIPE,
                text=True,
                timeout=300,
            )
        assert done.returncode == 2 and done.stderr.strip().splitlines()[-1] == (
            "gyrocomp: error: no space left on device; the disk is full; free space and run again"
        )
        assert not (tmp_path / "m.json").exists()
    piped = subprocess.run(
        f"'{exe}' show '{workdir / 'model.json'}' | head -1", shell=True, capture_output=True, text=True, timeout=120
    )
    assert piped.stdout.count("\n") == 1 and "Traceback" not in piped.stderr and "error" not in piped.stderr
