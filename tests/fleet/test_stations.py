"""Stations at once, on SQLite and on a real PostgreSQL server: the unique chain keeps concurrent writers from
storing a unit twice (conflicts retried), claims keep them from fitting it twice, a store of schema 1 is read and
upgraded, and a station killed (SIGKILL) at a random moment leaves a consistent store that its rerun completes."""

from __future__ import annotations

import datetime as dt
import json
import os
import random
import signal
import subprocess
import sys
import threading
import time

import pytest
import sqlalchemy as sa

from gyrocomp.errors import InputError
from gyrocomp.fleet import CalibrationRecord, CalibrationStore, InputFile, model_file_name
from gyrocomp.fleet import stations
from gyrocomp.fleet.stations import CLAIM_LEASE_S, Station, claim, claims, release, station_status
from gyrocomp.fleet.store import STORE_SCHEMA_VERSION
from gyrocomp.io.tables import write_recording
from gyrocomp.simulation import simulate

from ..conftest import SCRIPT, run

CMD = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "gyrocomp"]


def _record(serial: str, digest: str = "ab" * 32, when: dt.datetime | None = None) -> CalibrationRecord:
    return CalibrationRecord(
        serial=serial,
        calibrated_utc=when or dt.datetime(2026, 1, 1),
        status="ok",
        input_hash=digest,
        gyrocomp_version="0.1.0",
        inputs=(InputFile("/a.csv", "cd" * 32),),
        model_json='{"not": "read here"}',
        station="T",
    )


def _chain(db: CalibrationStore, serial: str) -> list[tuple[int, int | None]]:
    with db.engine.connect() as conn:
        return [
            tuple(r)
            for r in conn.execute(
                sa.text("select id, supersedes from calibrations where serial = :s and status = 'ok' order by id"),
                {"s": serial},
            )
        ]


def _in_threads(work, n: int) -> list:
    """``work(k)`` in ``n`` threads started together; their results (an exception re-raised)."""
    start, results = threading.Barrier(n), [None] * n

    def go(k):
        start.wait()
        try:
            results[k] = work(k)
        except Exception as exc:  # noqa: BLE001 - re-raised below, in the test's thread
            results[k] = exc

    threads = [threading.Thread(target=go, args=(k,)) for k in range(n)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        if isinstance(r, Exception):
            raise r
    return results


def test_concurrent_writers_keep_one_chain_per_unit(store_location):
    """Six writers, each its own connection, append to one unit at once: every row lands (conflicts retried), and
    each successful row supersedes the one before it, never two the same."""
    CalibrationStore(store_location, create=True).close()

    def append(k):
        with CalibrationStore(store_location) as db:
            return [db.add(_record("U1", digest=f"{k:02d}" * 32)) for _ in range(3)]

    ids = sorted(i for got in _in_threads(append, 6) for i in got)
    with CalibrationStore(store_location) as db:
        chain = _chain(db, "U1")
    assert [i for i, _ in chain] == ids and len(ids) == 18
    assert [s for _, s in chain] == [0] + ids[:-1]


def test_the_same_inputs_stored_at_once_are_stored_once(store_location):
    CalibrationStore(store_location, create=True).close()
    since = dt.datetime(2025, 1, 1)

    def store_it(_k):
        with CalibrationStore(store_location) as db:
            return db.add_new(_record("U2"), since=since, stamp=True)

    stored = [r for r in _in_threads(store_it, 6) if r is not None]
    assert len(stored) == 1
    with CalibrationStore(store_location) as db:
        (row,) = db.history("U2")
        assert row.station == "T" and row.calibrated_utc > since  # stamped at the write


def test_claims_are_exclusive_and_taken_over_from_a_dead_or_silent_station(store_location):
    with CalibrationStore(store_location, create=True) as db:
        me, other = Station("A", "host-a", os.getpid()), Station("B", "host-b", 1)
        assert claim(db, "U1", me) is None and claim(db, "U1", me) is None  # mine, claimed again
        holder = claim(db, "U1", other)
        assert holder is not None and holder.station == "A"
        release(db, "U1", me)
        assert claim(db, "U1", other) is None
        # B on another machine, silent past the lease: taken over
        with db.engine.begin() as conn:
            conn.execute(
                sa.text("update claims set heartbeat_utc = :t"),
                {"t": dt.datetime.now(dt.timezone.utc).replace(tzinfo=None) - dt.timedelta(seconds=CLAIM_LEASE_S + 5)},
            )
        assert claim(db, "U1", me) is None and claims(db)[0].station == "A"
        # a station of this machine whose process is gone: taken over at once
        dead = subprocess.Popen([sys.executable, "-c", "pass"])
        dead.wait()
        here = Station("C", me.host, dead.pid)
        with db.engine.begin() as conn:
            conn.execute(
                sa.text("update claims set host = :h, pid = :p, station = 'C'"), {"h": here.host, "p": dead.pid}
            )
        live = Station("D", me.host, os.getpid() + 0)
        assert claim(db, "U1", live) is None
        assert [(s.station, s.fitting) for s in station_status(db)] == [("D", ("U1",))]


def test_a_schema_1_store_is_read_as_it_is_and_upgraded_by_its_next_writer(store_location):
    with CalibrationStore(store_location, create=True) as db:
        db.add(_record("U1"))
        with db.engine.begin() as conn:  # back to schema 1, as gyrocomp 0.1 wrote it
            conn.execute(sa.text("drop index uq_calibrations_chain"))
            conn.execute(sa.text("drop table claims"))
            for column in ("station", "supersedes"):
                conn.execute(sa.text(f"alter table calibrations drop column {column}"))
            conn.execute(sa.text("update gyrocomp_store set value = '1' where key = 'schema_version'"))
    with CalibrationStore(store_location) as old:
        assert old.schema_version == 1 and old.history("U1")[0].station is None
        assert [s.station for s in station_status(old)] == ["(none)"]
    with CalibrationStore(store_location, create=True) as db:
        assert db.schema_version == STORE_SCHEMA_VERSION
        db.add(_record("U1", digest="cd" * 32))
        assert [r.station for r in db.history("U1")] == [None, "T"]
        assert _chain(db, "U1")[1][1] == _chain(db, "U1")[0][0]


# -- stations as processes ----------------------------------------------------------------------------------------
UNITS = 12


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """UNITS units of one short chamber run each: {serial: path}."""
    folder = tmp_path_factory.mktemp("station-runs")
    out = {}
    for k in range(UNITS):
        path = folder / f"u{k}.csv"
        write_recording(simulate("consumer", profile="chamber", duration_s=600, rate_hz=2, seed=k).recording, path)
        out[f"SN{k:02d}"] = path
    return out


def _manifest(folder, runs, serials) -> str:
    path = folder / f"manifest-{abs(hash(tuple(serials)))}.csv"
    path.write_text("path,serial\n" + "".join(f"{runs[s]},{s}\n" for s in serials))
    return str(path)


def _station(manifest, out, store, name) -> subprocess.Popen:
    return subprocess.Popen(
        [
            *CMD,
            "fleet",
            "fit",
            "--manifest",
            manifest,
            "-o",
            str(out),
            "--store",
            str(store),
            "--scheduler",
            "serial",
            "--station",
            name,
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def _consistent(store, outputs, serials) -> None:
    """Every successful row holds a valid model, no unit is stored twice from the same inputs, and every model
    file a station wrote is its unit's newest successful row's (a station killed before it made the store wrote
    nothing)."""
    try:
        db = CalibrationStore(store)
    except InputError:  # killed before it made the store (no file, or a database without the tables)
        assert not any(any(out.glob("models/*.json")) for out in outputs)
        return
    with db:
        for serial in serials:
            ok = [r for r in db.history(serial) if r.status == "ok"]
            assert len({r.input_hash for r in ok}) == len(ok), serial
            for r in ok:
                r.calibration()
        for out in outputs:
            for file in (out / "models").glob("*.json") if (out / "models").exists() else ():
                serial = next(s for s in serials if model_file_name(s) == file.name)
                assert file.read_text() == [r for r in db.history(serial) if r.status == "ok"][-1].model_json


@pytest.mark.slow
def test_four_stations_with_overlapping_units_store_each_once(store_location, runs, tmp_path):
    serials = sorted(runs)
    lists = [sorted(set(serials[k * 3 : k * 3 + 6] + serials[:2])) for k in range(4)]  # each overlaps the others
    outputs = [tmp_path / f"station{k}" for k in range(4)]
    procs = [
        _station(_manifest(tmp_path, runs, lst), out, store_location, f"S{k}")
        for k, (lst, out) in enumerate(zip(lists, outputs))
    ]
    for p in procs:
        _, stderr = p.communicate(timeout=300)
        assert p.returncode == 0, stderr
    wanted = sorted(set().union(*lists))
    with CalibrationStore(store_location) as db:
        assert db.serials() == wanted
        assert {
            s: [(r.station, r.status, r.input_hash[:8]) for r in db.history(s)]
            for s in wanted
            if len(db.history(s)) != 1
        } == {}
        assert claims(db) == []
    _consistent(store_location, outputs, wanted)
    status = json.loads(run("fleet", "status", "--store", store_location, "--json").stdout)
    assert {s["station"] for s in status} <= {f"S{k}" for k in range(4)}
    assert sum(s["ok"] for s in status) == len(wanted) and all(not s["fitting"] for s in status)


@pytest.mark.slow
def test_a_station_killed_at_random_moments_leaves_a_consistent_store_its_rerun_completes(
    store_location, runs, tmp_path
):
    serials = sorted(runs)
    manifest = _manifest(tmp_path, runs, serials)
    rng = random.Random(7)
    for trial in range(1):  # 20 trials per backend: benchmarks/bench_stations.py
        out = tmp_path / f"trial{trial}"
        store = (
            store_location
            if trial == 0
            else (str(out / "calibrations.sqlite") if "://" not in store_location else store_location)
        )
        station = _station(manifest, out, store, "K")
        time.sleep(rng.uniform(0.5, 3.0))
        station.send_signal(signal.SIGKILL)
        station.wait()
        _consistent(store, [out], serials)
        rerun = _station(manifest, out, store, "K")
        _, stderr = rerun.communicate(timeout=300)
        assert rerun.returncode == 0, stderr
        _consistent(store, [out], serials)
        with CalibrationStore(store) as db:
            assert claims(db) == []
            assert all(sum(r.status == "ok" for r in db.history(s)) >= 1 for s in serials)
            assert all((out / "models" / model_file_name(s)).exists() for s in serials)


def test_a_running_station_renews_its_claims_and_releases_them_at_the_end(store_location, monkeypatch):
    monkeypatch.setattr(stations, "CLAIM_RENEW_S", 0.2)
    with CalibrationStore(store_location, create=True) as db:
        me = Station.here("beat")
        with stations.station(db, me):
            claim(db, "U1", me)
            first = claims(db)[0].heartbeat_utc
            deadline = time.monotonic() + 10
            while claims(db)[0].heartbeat_utc == first and time.monotonic() < deadline:
                time.sleep(0.05)
            assert claims(db)[0].heartbeat_utc > first
        assert claims(db) == []
