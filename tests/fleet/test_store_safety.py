"""The calibration store cannot be left inconsistent: one model file per serial, the file written before its row,
a rerun that repairs what a crash left, concurrent fits that store each unit once, and no output over the store."""

from __future__ import annotations

import hashlib
import re
import shutil
import sqlite3
import subprocess
import sys
from types import SimpleNamespace

import pytest
import sqlalchemy as sa

from gyrocomp.calibration import Calibration
from gyrocomp.fleet import CalibrationStore, model_file_name
from gyrocomp.fleet.model_files import store_with_model
from gyrocomp.io.tables import write_recording
from gyrocomp.simulation import simulate

from ..conftest import SCRIPT, run

SERIALS = ("a/b", "a_b", "SN-1", "x" * 300)


def test_model_file_names_are_one_per_serial_and_short():
    names = [model_file_name(s) for s in SERIALS + ("a b", "a\\b", ".hidden", "caf\u00e9", "\udcff")]
    assert len(set(names)) == len(names)
    assert model_file_name("SN-1") == "SN-1.json"  # a plain serial keeps its name
    assert all(len(n) <= 120 and "/" not in n and not n.startswith(".") for n in names)
    assert model_file_name("a/b") == f"a_b~{hashlib.sha256(b'a/b').hexdigest()[:16]}.json"


class _Store:
    """A store whose insert sees what a reader of the folder would at the instant the row becomes visible, then
    stores the row (its id), finds the unit already stored (None) or is interrupted."""

    def __init__(self, model_file, outcome):
        self.model_file, self.outcome, self.seen = model_file, outcome, None

    def add_new(self, record, since, stamp):
        self.seen = self.model_file.read_text() if self.model_file.exists() else None
        if isinstance(self.outcome, BaseException):
            raise self.outcome
        return self.outcome


@pytest.mark.parametrize("had_file", [False, True])
@pytest.mark.parametrize("outcome", [7, None, KeyboardInterrupt()])
def test_the_model_file_is_in_place_before_its_row_and_put_back_when_no_row_is_stored(tmp_path, had_file, outcome):
    """A kill at any moment can leave a file newer than the rows, never a row without its file: the new model is
    the file when the row is committed; a row not stored (another fit stored the unit, Ctrl-C) puts back what
    was there."""
    path = tmp_path / "models" / model_file_name("SN-1")
    if had_file:
        path.parent.mkdir()
        path.write_text("the previous model")
    db = _Store(path, outcome)
    record = SimpleNamespace(serial="SN-1", model_json="the new model")
    if isinstance(outcome, BaseException):
        with pytest.raises(KeyboardInterrupt):
            store_with_model(db, record, None, tmp_path)
    else:
        assert store_with_model(db, record, None, tmp_path) == outcome
    assert db.seen == "the new model"
    if outcome == 7:
        assert path.read_text() == "the new model"
    elif had_file:
        assert path.read_text() == "the previous model"
    else:
        assert not path.exists()
    assert sorted(p.name for p in path.parent.iterdir()) == ([path.name] if outcome == 7 or had_file else [])


def _units(folder, serials):
    """One short chamber run per unit, written as folder/u<k>/run.csv, and a manifest naming the serials."""
    rows = ["path,serial"]
    for k, s in enumerate(serials):
        (folder / f"u{k}").mkdir(parents=True)
        path = folder / f"u{k}" / "run.csv"
        write_recording(simulate("consumer", profile="chamber", duration_s=600, rate_hz=2, seed=k).recording, path)
        rows.append(f'{path},"{s}"')
    manifest = folder / "manifest.csv"
    manifest.write_text("\n".join(rows) + "\n")
    return manifest


@pytest.fixture(scope="module")
def manifest(tmp_path_factory):
    return _units(tmp_path_factory.mktemp("units"), SERIALS)


def _fit(manifest, out, *more):
    return run("fleet", "fit", "--manifest", manifest, "-o", out, "--scheduler", "serial", *more)


@pytest.fixture(scope="module")
def fitted(manifest, tmp_path_factory):
    """The fleet of ``manifest`` fitted once into a store; tests that change it work on a copy."""
    out = tmp_path_factory.mktemp("fitted") / "FLEET"
    result = _fit(manifest, out)
    assert result.returncode == 0, result.stderr
    return out


@pytest.mark.slow
def test_serials_that_once_shared_a_file_each_keep_their_model(fitted):
    out = fitted
    with CalibrationStore(out) as db:
        for s in SERIALS:
            stored = db.valid_at(s).calibration()
            on_disk = Calibration.load(out / "models" / model_file_name(s))
            assert on_disk.axes == stored.axes
    assert len(list((out / "models").glob("*.json"))) == len(SERIALS)


@pytest.mark.slow
def test_a_failed_model_write_stores_nothing_and_the_rerun_fits_the_unit(manifest, tmp_path, store_location):
    """On each backend (the store a fleet folder's SQLite file, or a PostgreSQL database beside the folder)."""
    out = tmp_path / "OUT"
    out.mkdir()
    (out / "models").write_text("not a folder")  # every model write fails
    store = _store_args(store_location, out)
    result = _fit(manifest, out, *store)
    assert result.returncode == 2 and result.stderr.count("\n") == 1
    assert "cannot write unit" in result.stderr and "the next run fits it again" in result.stderr
    with CalibrationStore(_store(store_location, out)) as db:
        assert db.serials() == []  # no row without its model file
    (out / "models").unlink()
    result = _fit(manifest, out, *store)
    assert result.returncode == 0, result.stderr
    assert f"{len(SERIALS)} unit(s) fitted, 0 unchanged" in result.stdout


@pytest.mark.slow
def test_the_rerun_puts_back_a_missing_model_file(manifest, fitted, tmp_path, store_location):
    out = tmp_path / "OUT"
    store = _store_args(store_location, out)
    _fitted_once(manifest, fitted, out, store_location)
    lost = out / "models" / model_file_name("a/b")
    text = lost.read_text()
    lost.unlink()
    result = _fit(manifest, out, *store)
    assert result.returncode == 0 and f"0 unit(s) fitted, {len(SERIALS)} unchanged" in result.stdout
    assert lost.read_text() == text


@pytest.mark.slow
def test_outputs_onto_the_store_are_refused_and_the_store_is_intact(fitted, tmp_path):
    out = tmp_path / "FLEET"
    shutil.copytree(fitted, out)
    store = out / "calibrations.sqlite"
    before = store.read_bytes()
    for args in (
        ("report", out, "-o", store),
        ("export", "SN-1", "--store", out, "--format", "json", "-o", store),
        ("show", "SN-1", "--store", out, "-o", store),
    ):
        result = run("fleet", *args)
        assert result.returncode == 2 and result.stderr.count("\n") == 1, result.stderr
        assert "this is an input file; choose another output path" in result.stderr
    assert store.read_bytes() == before


@pytest.mark.slow
def test_two_fits_of_one_new_store_at_once_store_each_unit_once(manifest, tmp_path, store_location):
    """Two fits creating one new store at once (a fleet folder's SQLite file, or an empty PostgreSQL database)."""
    out = tmp_path / "FLEET"
    cmd = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "gyrocomp"]
    args = [
        "fleet",
        "fit",
        "--manifest",
        str(manifest),
        "-o",
        str(out),
        "--scheduler",
        "serial",
        "--store",
        str(_store(store_location, out)),
    ]
    procs = [
        subprocess.Popen([*cmd, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for _ in range(2)
    ]
    results = [p.communicate(timeout=300) + (p.returncode,) for p in procs]
    for _stdout, stderr, code in results:
        assert code == 0, stderr
    with CalibrationStore(_store(store_location, out)) as db:
        assert sorted(db.serials()) == sorted(SERIALS)
        assert all(len(db.history(s)) == 1 for s in SERIALS)


def _other_inputs(folder, serials):
    """The same serials as :func:`_units`, each with another run (other seeds): a recalibration."""
    rows = ["path,serial"]
    for k, s in enumerate(serials):
        (folder / f"v{k}").mkdir(parents=True)
        path = folder / f"v{k}" / "run.csv"
        write_recording(simulate("consumer", profile="chamber", duration_s=600, rate_hz=2, seed=50 + k).recording, path)
        rows.append(f'{path},"{s}"')
    other = folder / "other.csv"
    other.write_text("\n".join(rows) + "\n")
    return other


def _store(store_location: str, out):
    """The store of a test on either backend: a PostgreSQL URL, else the fleet folder ``out``."""
    return store_location if "://" in store_location else out


def _store_args(store_location: str, out) -> list:
    """``--store URL`` for a PostgreSQL store (a SQLite store is the fleet folder's own)."""
    return ["--store", store_location] if "://" in store_location else []


def _fitted_once(manifest, fitted, out, store_location):
    """``out`` as after one fit of ``manifest`` on the test's backend: a copy of the module's fitted fleet for a
    SQLite store, a new fit for a PostgreSQL one."""
    if "://" in store_location:
        assert _fit(manifest, out, *_store_args(store_location, out)).returncode == 0
    else:
        shutil.copytree(fitted, out)


def _files_agree_with_newest_rows(out, serials, store=None):
    with CalibrationStore(store or out) as db:
        for s in serials:
            newest = [r for r in db.history(s) if r.status == "ok"][-1]
            assert (out / "models" / model_file_name(s)).read_text() == newest.model_json, s


@pytest.mark.slow
def test_two_fits_of_one_unit_from_other_inputs_at_once_leave_the_newest_rows_model(
    manifest, tmp_path, store_location, request
):
    """Two stations recalibrating the same units from different runs at once: whatever the interleaving, each
    unit's model file is its newest row's (the file is written holding the store's write lock); on each backend
    (each repeat a new PostgreSQL database)."""
    other = _other_inputs(tmp_path, SERIALS)
    cmd = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "gyrocomp"]
    for repeat in range(3):
        out = tmp_path / f"FLEET{repeat}"
        location = (
            store_location
            if repeat == 0 or "://" not in store_location
            else request.getfixturevalue("postgres_server")()
        )
        procs = [
            subprocess.Popen(
                [
                    *cmd,
                    "fleet",
                    "fit",
                    "--manifest",
                    str(m),
                    "-o",
                    str(out),
                    "--scheduler",
                    "serial",
                    *_store_args(location, out),
                ],
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                text=True,
            )
            for m in (manifest, other)
        ]
        for p in procs:
            _, stderr = p.communicate(timeout=300)
            assert p.returncode == 0, stderr
        _files_agree_with_newest_rows(out, SERIALS, _store(location, out))


@pytest.mark.slow
def test_the_rerun_puts_back_a_model_file_copied_over_or_cut_short(manifest, fitted, tmp_path, store_location):
    out = tmp_path / "OUT"
    store = _store_args(store_location, out)
    _fitted_once(manifest, fitted, out, store_location)
    first, second = (out / "models" / model_file_name(s) for s in ("SN-1", "a_b"))
    first.write_text(second.read_text())  # another unit's model copied over it
    second.write_text(second.read_text()[:100])  # cut short
    result = _fit(manifest, out, *store)
    assert result.returncode == 0 and f"0 unit(s) fitted, {len(SERIALS)} unchanged" in result.stdout
    said = [line for line in result.stderr.splitlines() if "written again from the store" in line]
    assert len(said) == 2 and any(str(first) in line for line in said) and any(str(second) in line for line in said)
    _files_agree_with_newest_rows(out, SERIALS, _store(store_location, out))


@pytest.mark.parametrize(
    "column, value, said",
    [
        ("model", '{"schema_version": 6, "axes"', r"store row \d+ \(SN-1\): .*"),
        ("inputs", "not json", r"row \d+ \(unit 'SN-1'\) is damaged \(JSONDecodeError"),
        ("calibrated_utc", "garbage", r"row \d+ \(unit 'SN-1'\) holds no time gyrocomp wrote"),
    ],
)
@pytest.mark.slow
def test_a_store_row_changed_by_another_program_is_one_line_naming_it(manifest, fitted, tmp_path, column, value, said):
    out = tmp_path / "FLEET"
    shutil.copytree(fitted, out)
    with sqlite3.connect(out / "calibrations.sqlite") as conn:
        conn.execute(f"UPDATE calibrations SET {column} = ? WHERE serial = 'SN-1'", (value,))
    model_file = out / "models" / "SN-1.json"
    kept = model_file.read_bytes()
    for args in (
        ["show", "SN-1", "--store", out],
        ["export", "SN-1", "--store", out, "--format", "json", "-o", tmp_path / "m.json"],
        ["report", out, "-o", tmp_path / "r.html"],
        ["fit", "--manifest", manifest, "-o", out, "--scheduler", "serial"],
    ):
        result = run("fleet", *args)
        if column == "model" and args[0] == "report":
            continue  # the report reads figures, not models
        assert result.returncode == 2 and result.stderr.count("\n") == 1, (args, result.stderr)
        assert re.search(said, result.stderr), (args, result.stderr)
    assert not (tmp_path / "m.json").exists() and (tmp_path / "r.html").exists() == (column == "model")
    # the rerun never writes a damaged row's model over the unit's good file (it did, with a warning)
    assert model_file.read_bytes() == kept


@pytest.mark.slow
def test_a_damaged_model_row_on_postgresql_is_one_line_naming_it(manifest, tmp_path, postgres_server):
    """The same on a PostgreSQL store, changed by another program through SQL: every command that reads the row
    says it in one line, and the rerun leaves the unit's good model file alone."""
    url, out = postgres_server(), tmp_path / "OUT"
    assert _fit(manifest, out, "--store", url).returncode == 0
    engine = sa.create_engine(url.replace("postgresql://", "postgresql+psycopg://", 1))
    with engine.begin() as conn:
        conn.execute(
            sa.text("UPDATE calibrations SET model = :value WHERE serial = 'SN-1'"),
            {"value": '{"schema_version": 6, "axes"'},
        )
    engine.dispose()
    kept = (out / "models" / "SN-1.json").read_bytes()
    for args in (
        ["show", "SN-1", "--store", url],
        ["export", "SN-1", "--store", url, "--format", "json", "-o", tmp_path / "m.json"],
        ["fit", "--manifest", manifest, "-o", out, "--scheduler", "serial", "--store", url],
    ):
        result = run("fleet", *args)
        assert result.returncode == 2 and result.stderr.count("\n") == 1, (args, result.stderr)
        assert re.search(r"store row \d+ \(SN-1\): ", result.stderr), (args, result.stderr)
    assert not (tmp_path / "m.json").exists() and (out / "models" / "SN-1.json").read_bytes() == kept


@pytest.mark.slow
def test_show_at_the_last_day_there_is(fitted):
    result = run("fleet", "show", "SN-1", "--store", fitted, "--at", "9999-12-31")
    assert result.returncode == 0, result.stderr
