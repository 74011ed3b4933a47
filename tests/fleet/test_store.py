"""The calibration store: rows round-trip through SQLite, history is kept, the calibration valid at a time is the
right historical row (through the API and ``gyrocomp fleet show/export``), and bad stores are refused in one line."""

from __future__ import annotations

import datetime as dt
import math
import sqlite3

import pytest
import sqlalchemy as sa

from gyrocomp.calibration import Calibration
from gyrocomp.errors import InputError, ModelError
from gyrocomp.fleet.store import STORE_SCHEMA_VERSION
from gyrocomp.fleet import (
    AxisFigures,
    CalibrationRecord,
    CalibrationStore,
    Failure,
    InputFile,
    UnitFigures,
    parse_time,
    store_url,
)
from gyrocomp.models.fit import fit_channels
from gyrocomp.simulation import simulate

from ..conftest import run


@pytest.fixture(scope="module")
def models() -> list[Calibration]:
    """Two different models of one part (two sessions of 20-minute chamber runs)."""
    return [
        fit_channels(
            [
                simulate("consumer", profile="chamber", duration_s=1200, rate_hz=5, seed=10 * s + k, unit=1).recording
                for k in range(2)
            ]
        )
        for s in range(2)
    ]


def _figures(value: float) -> UnitFigures:
    axis = AxisFigures(value, 0.5, -0.02, -0.02, 1e-4, math.nan, 1.7, 0.01, 0.002, math.nan, 0.005, 14.0)
    return UnitFigures({"gyro_x": axis, "gyro_y": axis}, -20.0, 70.0, 3)


def _record(serial: str, when: dt.datetime, model: Calibration | None, drift: float = 0.004) -> CalibrationRecord:
    return CalibrationRecord(
        serial=serial,
        calibrated_utc=when,
        status="ok" if model else "failed",
        input_hash="ab" * 32,
        gyrocomp_version="0.1.0",
        inputs=(InputFile("/data/a.csv", "cd" * 32),),
        metadata={"lot": "L7"},
        verdict="fail" if model else None,
        failures=(Failure("gyro_x_held_out_drift_dps", drift, "> max"),),
        model_json=model.to_json() if model else None,
        figures=_figures(drift) if model else None,
        error=None if model else "run.csv: row 3: not a number",
        warnings=("one warning",),
    )


JAN, MAR, JUN = dt.datetime(2026, 1, 5, 12), dt.datetime(2026, 3, 1, 8, 30), dt.datetime(2026, 6, 1)


@pytest.fixture
def store(store_location, models) -> CalibrationStore:
    """A store with a history, on SQLite and on a PostgreSQL server."""
    db = CalibrationStore(store_location, create=True)
    db.add(_record("U1", JAN, models[0], 0.004))
    db.add(_record("U1", MAR, None))
    db.add(_record("U1", JUN, models[1], 0.006))
    db.add(_record("U2", MAR, models[1]))
    yield db
    db.close()


def test_a_row_round_trips_field_by_field(store, models):
    back = store.history("U1")[0]
    original = _record("U1", JAN, models[0], 0.004)
    assert back.id is not None
    for name in (
        "serial",
        "calibrated_utc",
        "status",
        "input_hash",
        "gyrocomp_version",
        "inputs",
        "metadata",
        "verdict",
        "failures",
        "model_json",
        "error",
        "warnings",
    ):
        assert getattr(back, name) == getattr(original, name), name
    assert back.figures.axes["gyro_x"].held_out_drift_dps == 0.004
    assert math.isnan(back.figures.axes["gyro_x"].tempco_3_dps_per_degc3)  # NaN survives (stored as null)
    assert back.calibration().to_dict() == models[0].to_dict()


def test_history_is_kept_and_the_valid_calibration_is_the_one_before(store, models):
    assert [r.calibrated_utc for r in store.history("U1")] == [JAN, MAR, JUN]
    assert store.valid_at("U1", dt.datetime(2026, 2, 1)).calibrated_utc == JAN
    # the failed calibration of March does not replace January's
    assert store.valid_at("U1", dt.datetime(2026, 4, 1)).calibrated_utc == JAN
    assert store.valid_at("U1", JUN).calibrated_utc == JUN
    assert store.valid_at("U1").calibration().to_dict() == models[1].to_dict()
    assert [r.serial for r in store.latest_rows()] == ["U1", "U2"]
    assert store.latest("U1").calibrated_utc == JUN and store.serials() == ["U1", "U2"]
    store.add(_record("U3", JUN, None))  # a unit that never succeeded has no hash to skip by
    assert [store.ok_hash(s) for s in ("U1", "U2", "U3")] == ["ab" * 32, "ab" * 32, None]


def test_valid_at_refuses_a_time_before_the_first_and_an_unknown_serial(store):
    with pytest.raises(InputError, match=r"unit 'U1' had no valid calibration at 2025-12-31.*first .* 2026-01-05"):
        store.valid_at("U1", dt.datetime(2025, 12, 31))
    with pytest.raises(InputError, match=r"serial: no unit 'U9' in"):
        store.valid_at("U9")
    with pytest.raises(ModelError, match=r"unit U1: the calibration of 2026-03-01 08:30:00 failed \(run.csv: row 3"):
        store.history("U1")[1].calibration()


def test_parse_time_reads_dates_times_and_zones():
    assert parse_time("2026-03-01") == dt.datetime(2026, 3, 1, 23, 59, 59, 999999)
    assert parse_time("2026-03-01T08:30") == dt.datetime(2026, 3, 1, 8, 30)
    assert parse_time("2026-03-01T10:30:00+02:00") == dt.datetime(2026, 3, 1, 8, 30)
    assert parse_time("2026-03-01T08:30:00Z") == dt.datetime(2026, 3, 1, 8, 30)
    with pytest.raises(InputError, match=r"at: 'March 1st' is not an ISO 8601 date"):
        parse_time("March 1st")
    # instants beyond the years UTC holds are after (or before) every row, not an overflow
    assert parse_time("9999-12-31T23:59:59-12:00") == dt.datetime.max
    assert parse_time("0001-01-01T00:00:00+14:00") == dt.datetime.min


def test_store_locations(tmp_path):
    assert store_url(tmp_path / "FLEET") == f"sqlite:///{tmp_path / 'FLEET' / 'calibrations.sqlite'}"
    assert store_url(tmp_path / "cal.db") == f"sqlite:///{tmp_path / 'cal.db'}"
    assert store_url("postgresql+psycopg2://factory@db/c") == "postgresql+psycopg2://factory@db/c"
    assert store_url("postgresql://factory@db/c") in ("postgresql://factory@db/c", "postgresql+psycopg://factory@db/c")
    with pytest.raises(InputError, match=r"no calibration store there \(no calibrations.sqlite\)"):
        CalibrationStore(tmp_path / "nowhere")
    (tmp_path / "junk.sqlite").write_bytes(b"this is not a database" * 100)
    with pytest.raises(InputError, match=r"junk.sqlite: not a database"):
        CalibrationStore(tmp_path / "junk.sqlite")
    sqlite3.connect(tmp_path / "other.sqlite").execute("create table t (x int)").connection.close()
    with pytest.raises(InputError, match=r"other.sqlite: the database has no calibrations table"):
        CalibrationStore(tmp_path / "other.sqlite")
    with pytest.raises(InputError, match=r"nodb://x: not a database URL SQLAlchemy can open"):
        CalibrationStore("nodb://x")


def test_a_store_of_a_newer_schema_is_refused(store):
    with store.engine.begin() as conn:
        conn.execute(sa.text("update gyrocomp_store set value = '99' where key = 'schema_version'"))
    with pytest.raises(InputError, match=rf"store schema version 99; this gyrocomp reads up to {STORE_SCHEMA_VERSION}"):
        CalibrationStore(store.location)


@pytest.mark.slow
def test_fleet_show_and_export_through_the_command_line(store, models, tmp_path):
    folder = store.location
    shown = run("fleet", "show", "U1", "--store", folder, "--at", "2026-05-01", "--json")
    assert shown.returncode == 0, shown.stderr
    assert '"calibrated_utc": "2026-01-05T12:00:00Z"' in shown.stdout
    table = run("fleet", "show", "U1", "--store", folder)
    assert "calibration 3 of 2026-06-01 00:00:00 UTC" in table.stdout and "held_out_drift_dps" in table.stdout
    history = run("fleet", "show", "U1", "--store", folder, "--history")
    assert history.stdout.count("2026-") == 3 and "failed" in history.stdout
    out = tmp_path / "u1.json"
    exported = run("fleet", "export", "U1", "--store", folder, "--format", "json", "--at", "2026-02-01", "-o", out)
    assert exported.returncode == 0, exported.stderr
    assert Calibration.load(out).to_dict() == models[0].to_dict()
    px4 = run(
        "fleet",
        "export",
        "U2",
        "--store",
        store.file or folder,
        "--format",
        "px4",
        "-o",
        tmp_path / "u2.params",
        "--device-id",
        7,
    )
    models[1].save(tmp_path / "u2.json")
    direct = run("export", tmp_path / "u2.json", "--format", "px4", "-o", tmp_path / "direct.params", "--device-id", 7)
    assert px4.returncode == 0 and direct.returncode == 0
    assert "TC_G0_X0_0" in (tmp_path / "u2.params").read_text()
    assert (tmp_path / "u2.params").read_text() == (tmp_path / "direct.params").read_text()
    early = run("fleet", "show", "U1", "--store", folder, "--at", "2025-12-01")
    assert early.returncode == 2 and early.stderr.count("\n") == 1
    assert "unit 'U1' had no valid calibration at 2025-12-01" in early.stderr
    unknown = run("fleet", "export", "U7", "--store", folder, "--format", "c", "-o", tmp_path / "c")
    assert unknown.returncode == 2 and "no unit 'U7'" in unknown.stderr and not (tmp_path / "c").exists()
