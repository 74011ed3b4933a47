"""What surrounds gyrocomp: outputs that must not replace inputs or carry a planted file's mode, temporary outputs a
killed writer left, a store's password, text from data on a terminal, in a certificate and in the project file,
another program's table in a store, and a PDF printer that hangs or writes garbage."""

from __future__ import annotations

import os
import re
import sqlite3
import stat
import sys
import tomllib
from pathlib import Path

import pytest

from gyrocomp.errors import InputError
from gyrocomp.fleet import CalibrationStore
from gyrocomp.io.atomic import TEMP_PREFIX, atomic_folder, write_text_atomic
from gyrocomp.io.tables import write_recording
from gyrocomp.report import certificate

from ..conftest import chamber_run, run

#: the control and bidirectional characters a hostile name holds: an escape sequence, a title change, a reversal
HOSTILE = "SN\x1b[31m\u202e1234\x1b]0;owned\x07"


@pytest.fixture(scope="module")
def unit(tmp_path_factory):
    """One unit of a hostile serial and station, fitted into a fleet folder: two runs written from the physics
    (a heat-cool cycle and one heating leg, 10 Hz)."""
    folder = tmp_path_factory.mktemp("environment")
    runs = [folder / "run_0.csv", folder / "run_1.csv"]
    write_recording(chamber_run([20, 60, 20], ramp_degc_per_min=2, seed=1), runs[0])
    write_recording(chamber_run([20, 60], hold_s=300, seed=2), runs[1])
    serial = HOSTILE.replace('"', '""')
    (folder / "m.csv").write_text(f'path,serial\n{runs[0]},"{serial}"\n{runs[1]},"{serial}"\n', encoding="utf-8")
    fitted = run(
        "fleet", "fit", "--manifest", folder / "m.csv", "-o", folder / "FLEET", "--scheduler", "serial",
        "--station", "bay\x1b[2J",
    )  # fmt: skip
    assert fitted.returncode == 0, fitted.stderr
    assert "\x1b" not in fitted.stdout + fitted.stderr and "\\x1b" in fitted.stdout
    return folder, runs


def _mode(path) -> int:
    return stat.S_IMODE(os.stat(path).st_mode)


def test_a_new_file_takes_no_mode_bits_from_a_file_another_user_planted(tmp_path):
    planted = tmp_path / "out.txt"
    planted.write_text("planted")
    os.chmod(planted, 0o6777)
    if os.geteuid() == 0:
        os.chown(planted, 12345, 12345)  # another user's file in a shared folder
    write_text_atomic(planted, "mine")
    assert planted.read_text() == "mine"
    umask = os.umask(0)
    os.umask(umask)
    if os.geteuid() == 0:
        assert _mode(planted) == 0o666 & ~umask and os.stat(planted).st_uid == 0
    else:  # a file of the same user: its read and write bits, never setuid, setgid or execute
        assert _mode(planted) == 0o666
    own = tmp_path / "own.txt"
    own.write_text("x")
    os.chmod(own, 0o640)
    write_text_atomic(own, "y")
    assert _mode(own) == 0o640


@pytest.mark.skipif(os.geteuid() != 0, reason="planting another user's file needs root")
def test_an_export_over_a_planted_setuid_file_writes_a_plain_file(tmp_path, consumer_model):
    model = tmp_path / "m.json"
    consumer_model.save(model)
    out = tmp_path / "px4.params"
    out.write_text("planted")
    os.chmod(out, 0o6777)
    os.chown(out, 12345, 12345)
    result = run("export", model, "--format", "px4", "--device-id", "2490378", "-o", out)
    assert result.returncode == 0, result.stderr
    assert not _mode(out) & (stat.S_ISUID | stat.S_ISGID | stat.S_IWOTH | stat.S_IXUSR)
    assert os.stat(out).st_uid == 0


def test_a_staging_folder_a_killed_writer_left_is_removed_by_the_next_write(tmp_path):
    dead = 2**22 + 12345  # above any pid this machine hands out (pid_max is at most 2**22)
    stale = tmp_path / f"{TEMP_PREFIX}{dead}-out.bag.abc123.tmp"
    (stale / "bag").mkdir(parents=True)
    (stale / "bag" / "bag.db3").write_bytes(b"half a bag")
    alive = tmp_path / f"{TEMP_PREFIX}{os.getpid()}-out.bag.def456.tmp"  # a writer still running keeps its own
    alive.mkdir()
    other = tmp_path / f"{TEMP_PREFIX}{dead}-other.bag.abc123.tmp"  # another output's
    other.mkdir()
    with atomic_folder(tmp_path / "out.bag") as staging:
        assert staging.is_dir() and staging.parent == tmp_path and staging.name.startswith(TEMP_PREFIX)
        assert not stale.exists()
    assert not staging.exists() and alive.exists() and other.exists()


def test_a_certificate_is_written_for_a_unit_whose_second_run_is_one_leg(unit, tmp_path):
    folder, runs = unit
    out = tmp_path / "cert.html"
    result = run("fleet", "certificate", HOSTILE, "--store", folder / "FLEET", "-o", out)
    assert result.returncode == 0, result.stderr
    page = out.read_text(encoding="utf-8")
    assert "not judged (no limits given)" in page  # the unit's verdict, stated
    # the serial shown as it is, its reversal neutralised (a browser would show SN4321 for the raw character)
    assert "\u202e" not in page and "\x1b" not in page and "SN\\x1b[31m\\u202e1234" in page
    assert "\x1b" not in result.stdout and "\\u202e" in result.stdout


@pytest.mark.parametrize(
    "args, message",
    [
        (["-o", "{run1}"], r"-o .*run_1\.csv: this is one of unit .*'s runs; choose another output path"),
        (["-o", "{link}"], r"-o .*hard\.csv: this is one of unit .*'s runs"),
        (["-o", "{tmp}/c.html", "--pdf", "{run0}"], r"--pdf .*run_0\.csv: this is one of unit .*'s runs"),
        (["-o", "{tmp}/c.html", "--pdf", "{tmp}/c.html"], r"--pdf .*c\.html: this is the HTML page \(-o\)"),
    ],
)
def test_a_certificate_never_replaces_a_run_or_its_own_page(unit, tmp_path, args, message):
    folder, runs = unit
    os.link(runs[0], tmp_path / "hard.csv")  # a hard link to a run is the run
    before = [p.read_bytes() for p in runs]
    names = {"run0": runs[0], "run1": runs[1], "link": tmp_path / "hard.csv", "tmp": tmp_path}
    result = run(
        "fleet", "certificate", HOSTILE, "--store", folder / "FLEET", *[a.format(**names) for a in args]
    )  # fmt: skip
    assert result.returncode == 2 and len(result.stderr.splitlines()) == 1, result.stderr
    assert re.search(message, result.stderr), result.stderr
    assert [p.read_bytes() for p in runs] == before and not (tmp_path / "c.html").exists()


def test_names_from_the_store_reach_the_terminal_escaped(unit):
    folder, _ = unit
    outputs = [
        run("fleet", "status", "--store", folder / "FLEET"),
        run("fleet", "show", HOSTILE, "--store", folder / "FLEET"),
        run("fleet", "show", HOSTILE, "--store", folder / "FLEET", "--history"),
    ]
    for result in outputs:
        assert result.returncode == 0, result.stderr
        assert "\x1b" not in result.stdout and "\u202e" not in result.stdout and "\x07" not in result.stdout
    assert "bay\\x1b[2J" in outputs[0].stdout and "SN\\x1b[31m\\u202e1234" in outputs[2].stdout


def test_an_output_name_reaches_the_terminal_escaped(tmp_path, consumer_model):
    model = tmp_path / "m.json"
    consumer_model.save(model)
    data = tmp_path / "in.csv"
    write_recording(chamber_run([20, 30], hold_s=60, rate_hz=2, seed=3), data)
    out = tmp_path / "out\x1b[2J.csv"
    result = run("apply", model, data, "-o", out)
    assert result.returncode == 0, result.stderr
    assert out.exists() and "\x1b" not in result.stdout and "out\\x1b[2J.csv" in result.stdout


def test_a_store_password_is_never_printed(tmp_path):
    url = "postgresql://station:S3cretPw@127.0.0.1:9/calibrations"  # no server listens on port 9
    for args in (["fleet", "status", "--store", url], ["fleet", "report", url, "-o", tmp_path / "r.html"]):
        result = run(*args)
        assert result.returncode == 2 and len(result.stderr.splitlines()) == 1, result.stderr
        assert "S3cretPw" not in result.stdout + result.stderr and "station:***@127.0.0.1" in result.stderr
        assert "the database server cannot be reached" in result.stderr
    bad = "postgresql://station:S3cretPw@127.0.0.1:notaport/db"
    with pytest.raises(InputError, match=r"^postgresql://\*\*\*: not a database URL") as caught:
        CalibrationStore(bad)
    assert "S3cretPw" not in str(caught.value)


def test_a_store_password_stays_out_of_the_fleet_report(postgres_server, unit, tmp_path):
    folder, runs = unit
    url = postgres_server().replace("postgresql://postgres@", "postgresql://postgres:S3cretPw@")  # trust: any
    fitted = run(
        "fleet", "fit", "--manifest", folder / "m.csv", "-o", tmp_path / "F", "--store", url, "--scheduler", "serial"
    )  # fmt: skip
    assert fitted.returncode == 0, fitted.stderr
    assert "S3cretPw" not in fitted.stdout + fitted.stderr
    page = tmp_path / "r.html"
    assert run("fleet", "report", url, "-o", page).returncode == 0
    text = page.read_text(encoding="utf-8")
    assert "S3cretPw" not in text and "postgres:***@" in text
    status = run("fleet", "status", "--store", url)
    assert status.returncode == 0 and "S3cretPw" not in status.stdout and "postgres:***@" in status.stdout


def test_a_database_holding_another_programs_calibrations_table_is_refused_untouched(tmp_path):
    db = tmp_path / "other.sqlite"
    with sqlite3.connect(db) as conn:
        conn.execute("CREATE TABLE calibrations (id INTEGER PRIMARY KEY, sensor TEXT, offset REAL)")
        conn.execute("INSERT INTO calibrations (sensor, offset) VALUES ('imu', 0.5)")
    before = db.read_bytes()
    for args in (["fleet", "status", "--store", db], ["fleet", "show", "SN1", "--store", db]):
        result = run(*args)
        assert result.returncode == 2 and len(result.stderr.splitlines()) == 1, result.stderr
        assert "its calibrations table was not written by gyrocomp" in result.stderr
    assert db.read_bytes() == before


def test_init_writes_a_hostile_file_name_and_column_as_data(tmp_path):
    name = 'log\n[learn]\nsave-state = "owned.json"\n#.csv'
    log = tmp_path / name
    log.write_text('time,"g=z,,",temperature\n' + "".join(f"{k / 10},{0.01 * k},25.0\n" for k in range(50)))
    (tmp_path / "plain.csv").write_bytes(log.read_bytes())
    result = run("init", log, "--rate", "10", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    project = tomllib.loads((tmp_path / "gyrocomp.toml").read_text(encoding="utf-8"))
    assert set(project) == {"read"}  # the name added no section
    assert project["read"]["columns"]["gyro_z"] == "g=z,,"
    assert "\n[learn]" not in result.stdout
    shown = run("config", "show", cwd=tmp_path)
    assert shown.returncode == 0 and "[learn]" not in shown.stdout, shown.stdout
    # the column init read is the column every later command reads
    checked = run("check", "plain.csv", cwd=tmp_path)
    assert checked.returncode == 0, checked.stderr


def _fake_chromium(folder: Path, body: str) -> None:
    script = folder / "chromium"
    script.write_text(f"#!{sys.executable}\nimport sys, time\nargs = sys.argv[1:]\n{body}\n")
    script.chmod(0o755)


@pytest.mark.parametrize(
    "body, message",
    [
        ("time.sleep(30)", r"did not print .* within 1 s and was stopped"),
        (
            "out = next(a for a in args if a.startswith('--print-to-pdf='))[15:]\nopen(out, 'wb').write(b'garbage')",
            r"what it wrote is not a PDF",
        ),
        ("sys.stderr.write('x' * 10_000_000)\nsys.exit(3)", r"exit 3: x{160}\); the HTML"),
    ],
)
def test_a_pdf_printer_that_hangs_or_writes_garbage_is_one_line(tmp_path, monkeypatch, body, message):
    _fake_chromium(tmp_path, body)
    monkeypatch.setenv("PATH", f"{tmp_path}{os.pathsep}{os.environ['PATH']}")
    page = tmp_path / "c.html"
    page.write_text("<p>page</p>")
    with pytest.raises(InputError, match=message) as caught:
        certificate.print_pdf(page, tmp_path / "c.pdf", timeout_s=1)
    assert len(str(caught.value)) < 600 and not (tmp_path / "c.pdf").exists()


def test_a_locked_table_a_read_only_user_and_a_stopped_server_are_one_line_each(
    postgres_server, unit, tmp_path, monkeypatch
):
    import psycopg

    from gyrocomp.fleet import store as store_module
    from gyrocomp.fleet.stations import station_status

    folder, runs = unit
    url = postgres_server()
    fitted = run(
        "fleet", "fit", "--manifest", folder / "m.csv", "-o", tmp_path / "F", "--store", url, "--scheduler", "serial"
    )  # fmt: skip
    assert fitted.returncode == 0, fitted.stderr
    monkeypatch.setattr(store_module, "LOCK_TIMEOUT_S", 1.0)
    with psycopg.connect(url) as other:  # another client holds the table locked in an open transaction
        other.execute("LOCK TABLE calibrations IN ACCESS EXCLUSIVE MODE")
        with pytest.raises(InputError, match=r": a table of the store is locked by another client for more than 1 s"):
            with CalibrationStore(url) as db:
                station_status(db)
    with psycopg.connect(url, autocommit=True) as admin:
        admin.execute("CREATE ROLE reader LOGIN")
        admin.execute("GRANT SELECT ON ALL TABLES IN SCHEMA public TO reader")
    reader = url.replace("postgresql://postgres@", "postgresql://reader@")
    assert run("fleet", "status", "--store", reader).returncode == 0  # reading is allowed
    (tmp_path / "other.csv").write_text(f"path,serial\n{runs[0]},SN2\n{runs[1]},SN2\n")
    refused = run(
        "fleet", "fit", "--manifest", tmp_path / "other.csv", "-o", tmp_path / "G", "--store", reader,
        "--scheduler", "serial",
    )  # fmt: skip
    assert refused.returncode == 2 and len(refused.stderr.splitlines()) == 1, refused.stdout + refused.stderr
    assert "the database user may not read or write the store's tables" in refused.stderr
    with CalibrationStore(url) as db:  # as consistent as before: the one unit, no row of SN2
        assert [r.serial for r in db.latest_rows()] == [HOSTILE]
