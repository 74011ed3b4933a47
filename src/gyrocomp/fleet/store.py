"""The calibration store: every calibration of every unit, in SQLite by default or any database SQLAlchemy reaches.

One row per calibration attempt, never overwritten: a unit calibrated again gets a new row, so the calibration
valid at any past time can be found (:meth:`CalibrationStore.valid_at`). A row holds the serial, the time (UTC),
the status (``ok`` or ``failed`` with its error), the inputs and their content hash, gyrocomp's version, the model
JSON (validated when read back, as a model file is), the figures of merit and the verdict against the limits.

``location`` names the store: a folder (the fleet's output; the store is ``calibrations.sqlite`` in it), an
SQLite file (``.sqlite``, ``.sqlite3``, ``.db``), or a SQLAlchemy URL (``postgresql://user@host/db``: the
``postgresql`` extra installs psycopg, which a plain ``postgresql://`` URL then uses).

Several writers at once (stations on other machines, each with only the URL): a successful row names the row it
supersedes (the unit's newest successful row when it was written, 0 for the first), and the pair (serial,
supersedes) is unique on both backends, so two writers that read the same history cannot both append to it: the
second's insert fails, and it retries (:data:`WRITE_TRIES`) on the history as it now is, where the check finds
the first's row. PostgreSQL's serialization failures and deadlocks are retried the same way.
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import json
import math
import os
import random
import time
from importlib.util import find_spec
from collections.abc import Callable
from dataclasses import dataclass, field, replace as _replace
from pathlib import Path
from typing import Literal

from ..calibration import Calibration
from ..errors import InputError, ModelError, foreign_message
from ..io.atomic import refuse_link
from ..io.foreign_libraries import require
from ..jsontext import loads
from .unit_figures import UnitFigures
from .limits import Failure

sa = require("sqlalchemy", "fleet", "the calibration store")

STORE_FILE = "calibrations.sqlite"
#: 2: the station that wrote a row, the row a successful row supersedes (unique per serial), station claims, serials
#: of any length
STORE_SCHEMA_VERSION = 2
_SQLITE_SUFFIXES = (".sqlite", ".sqlite3", ".db")

_META = sa.MetaData()
_INFO = sa.Table(
    "gyrocomp_store",
    _META,
    sa.Column("key", sa.String(64), primary_key=True),
    sa.Column("value", sa.String(256), nullable=False),
)
_ROWS = sa.Table(
    "calibrations",
    _META,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("serial", sa.Text, nullable=False, index=True),  # any length: PostgreSQL enforces a VARCHAR's
    sa.Column("calibrated_utc", sa.DateTime, nullable=False, index=True),
    sa.Column("status", sa.String(16), nullable=False),
    sa.Column("verdict", sa.String(8)),
    sa.Column("failures", sa.Text, nullable=False),
    sa.Column("input_hash", sa.String(64), nullable=False),
    sa.Column("inputs", sa.Text, nullable=False),
    sa.Column("unit_metadata", sa.Text, nullable=False),
    sa.Column("gyrocomp_version", sa.String(32), nullable=False),
    sa.Column("model", sa.Text),
    sa.Column("figures", sa.Text),
    sa.Column("error", sa.Text),
    sa.Column("warnings", sa.Text, nullable=False),
    sa.Column("station", sa.Text),
    sa.Column("supersedes", sa.Integer),
)
#: one successor per successful row of a unit: two writers that read the same history cannot both append
_CHAIN = sa.Index("uq_calibrations_chain", _ROWS.c.serial, _ROWS.c.supersedes, unique=True)
#: the store's schema version, as its info table holds it
_VERSION = sa.select(_INFO.c.value).where(_INFO.c.key == "schema_version")
#: the columns a row is read back from (a schema 1 store has neither the station nor the chain)
_READ = [c for c in _ROWS.c if c.name not in ("station", "supersedes")]
#: which station fits which unit now (:mod:`gyrocomp.fleet.stations`)
CLAIMS = sa.Table(
    "claims",
    _META,
    sa.Column("serial", sa.Text, primary_key=True),
    sa.Column("station", sa.Text, nullable=False),
    sa.Column("host", sa.Text, nullable=False),
    sa.Column("pid", sa.Integer, nullable=False),
    sa.Column("claimed_utc", sa.DateTime, nullable=False),
    sa.Column("heartbeat_utc", sa.DateTime, nullable=False),
)

Status = Literal["ok", "failed"]


@dataclass(frozen=True)
class InputFile:
    """One run file of a calibration: its path as given and the SHA-256 of its content."""

    path: str
    sha256: str


@dataclass(frozen=True)
class CalibrationRecord:
    """One row of the store. ``calibrated_utc`` is naive UTC; ``model_json`` is None for a failed unit."""

    serial: str
    calibrated_utc: _dt.datetime
    status: Status
    input_hash: str
    gyrocomp_version: str
    inputs: tuple[InputFile, ...] = ()
    metadata: dict[str, str] = field(default_factory=dict)
    verdict: Literal["pass", "fail"] | None = None
    failures: tuple[Failure, ...] = ()
    model_json: str | None = None
    figures: UnitFigures | None = None
    error: str | None = None
    warnings: tuple[str, ...] = ()
    station: str | None = None
    id: int | None = None

    def calibration(self) -> Calibration:
        """The model, validated (and upgraded) as a model file is on load."""
        if self.model_json is None:
            raise ModelError(
                f"unit {self.serial}: the calibration of {self.calibrated_utc:%Y-%m-%d %H:%M:%S} "
                f"failed ({self.error}); it has no model"
            )
        source = f"store row {self.id} ({self.serial})"
        return Calibration.from_dict(loads(self.model_json, source, "model", non_finite=True), source=source)


def utc_now() -> _dt.datetime:
    """Now, naive UTC (what the store keeps), to the microsecond."""
    return _dt.datetime.now(_dt.timezone.utc).replace(tzinfo=None)


def parse_time(text: str, name: str = "at") -> _dt.datetime:
    """An ISO 8601 date or time (``2026-11-24``, ``2026-11-24T10:30``, with or without a zone) as naive UTC; a date
    alone means the end of that day (a calibration made that day is valid at it)."""
    try:
        value = _dt.datetime.fromisoformat(text.strip())
    except ValueError:
        raise InputError(
            f"{name}: {text!r} is not an ISO 8601 date or time (e.g. 2026-11-24 or 2026-11-24T10:30:00Z)"
        ) from None
    if len(text.strip()) <= 10:  # the end of that day (the last day there is: its last microsecond)
        value = _dt.datetime.combine(value.date(), _dt.time.max, value.tzinfo)
    if value.tzinfo is not None:
        try:
            value = value.astimezone(_dt.timezone.utc).replace(tzinfo=None)
        except OverflowError:  # beyond the years UTC has (9999-12-31T23:59-12:00): before or after every row
            value = _dt.datetime.min if value.utcoffset() > _dt.timedelta(0) else _dt.datetime.max
    return value


def store_url(location: str | os.PathLike) -> str:
    """The SQLAlchemy URL of a store location (see the module)."""
    text = os.fspath(location)
    if "://" in text:
        if text.startswith("postgresql://") and find_spec("psycopg2") is None and find_spec("psycopg") is not None:
            return "postgresql+psycopg://" + text[len("postgresql://") :]  # SQLAlchemy's default driver is psycopg2
        return text
    path = sqlite_file(text)
    return f"sqlite:///{path.resolve()}"


def shown_location(location: str | os.PathLike) -> str:
    """A store location as gyrocomp prints and writes it: a URL with its password masked (``***``, as SQLAlchemy
    renders one), a path as given."""
    text = os.fspath(location)
    if "://" not in text:
        return text
    try:
        return sa.engine.make_url(text).render_as_string(hide_password=True)
    except (sa.exc.ArgumentError, ValueError):  # not a URL SQLAlchemy parses: nothing after the scheme is shown
        return text.split("://", 1)[0] + "://***"


def sqlite_file(location: str | os.PathLike) -> Path:
    """The SQLite file a store location that is not a URL names (the file, or ``calibrations.sqlite`` in the
    folder), as given: not resolved."""
    path = Path(location)
    return path if path.suffix.lower() in _SQLITE_SUFFIXES else path / STORE_FILE


#: how long a writer waits for another process's write to the same SQLite store [s]
SQLITE_BUSY_TIMEOUT_S = 60.0
#: how many times a write that conflicted with another writer's is tried in all
WRITE_TRIES = 12
#: PostgreSQL's serialization failure and deadlock: the transaction is tried again
_RETRIED_SQLSTATES = ("40001", "40P01")
#: the advisory lock that creating or upgrading a PostgreSQL store holds (any fixed 64-bit number)
_SCHEMA_LOCK_KEY = 0x6779726F636F6D70


#: how long a statement waits for a lock another client of a server holds [s] (SQLite: SQLITE_BUSY_TIMEOUT_S)
LOCK_TIMEOUT_S = 60.0


def _connect_args(url: str, sqlite: bool) -> dict:
    """The driver's connection options: SQLite's busy timeout; PostgreSQL's lock timeout (a table another client
    holds locked is one line after LOCK_TIMEOUT_S, not a wait for ever)."""
    if sqlite:
        return {"timeout": SQLITE_BUSY_TIMEOUT_S}
    if url.startswith("postgresql"):
        return {"options": f"-c lock_timeout={int(LOCK_TIMEOUT_S * 1000)}"}
    return {}


#: PostgreSQL's error classes and codes, in words: what happened and what to do
_TROUBLE = (
    ("55P03", "a table of the store is locked by another client for more than {lock:g} s; run the command again "
     "when that client is done"),
    ("42501", "the database user may not read or write the store's tables (permission denied); give a user that "
     "may, or grant this one SELECT, INSERT and UPDATE on them"),
    ("57P", "the database server shut down while the command ran; the store is as it was before the statement "
     "that failed: run the command again once the server is back"),
    ("08", "the connection to the database server failed or dropped; the store is as it was before the statement "
     "that failed: run the command again once the server can be reached"),
)  # fmt: skip


def database_trouble(exc) -> str:
    """A database error (SQLAlchemy's, wrapping the driver's) in words: a lock held too long, a permission, a
    server that stopped or cannot be reached (PostgreSQL's SQLSTATE classes), else the driver's own message cut to
    one line (:func:`gyrocomp.errors.foreign_message`)."""
    orig = getattr(exc, "orig", exc)
    state = getattr(orig, "sqlstate", None) or ""
    for prefix, words in _TROUBLE:
        if state.startswith(prefix):
            return words.format(lock=LOCK_TIMEOUT_S)
    if "database is locked" in str(orig):
        return (
            f"the SQLite store is locked by another process for more than {SQLITE_BUSY_TIMEOUT_S:g} s; run the "
            "command again when it is done"
        )
    text = str(orig).lower()
    if not state and ("could not connect" in text or "connection" in text):
        return (
            "the database server cannot be reached (is it running, and is the URL's host and port right?): "
            + foreign_message(orig)
        )
    return f"the database refused: {foreign_message(orig)}"


class _Retry(Exception):
    """A write that conflicted with another writer's (a unique key taken, a serialization failure)."""


def _serialize_sqlite_writes(engine) -> None:
    """A write transaction of ``engine`` (SQLite; marked ``immediate`` in its connection's ``info``) takes the
    write lock when it begins (``BEGIN IMMEDIATE``), waiting up to :data:`SQLITE_BUSY_TIMEOUT_S` for another
    process's: a check and the write it decides are then one step, whatever runs beside. Reads begin as usual.
    (SQLAlchemy's recipe for SQLite transactions: pysqlite's own begin is disabled.)"""

    @sa.event.listens_for(engine, "connect")
    def _connect(dbapi_connection, _record):
        dbapi_connection.isolation_level = None

    @sa.event.listens_for(engine, "begin")
    def _begin(connection):
        connection.exec_driver_sql("BEGIN IMMEDIATE" if connection.info.pop("immediate", False) else "BEGIN")


class CalibrationStore:
    """A calibration store (see the module). ``create``: make the database (and its tables) when absent; two
    processes creating one store at once both end with it made once."""

    def __init__(self, location: str | os.PathLike, *, create: bool = False) -> None:
        #: the store as messages name it (a URL's password masked: :func:`shown_location`)
        self.location = shown_location(location)
        url = store_url(location)
        #: the SQLite file of the store (None for a server database)
        self.file: Path | None = None
        if url.startswith("sqlite:///"):
            refuse_link(sqlite_file(location), "calibration stores are")
            self.file = file = Path(url[len("sqlite:///") :])
            if not file.exists():
                if not create:
                    raise InputError(
                        f"{self.location}: no calibration store there (no {file.name}); give the folder "
                        f"a fleet fit wrote, an SQLite file or a database URL"
                    )
                file.parent.mkdir(parents=True, exist_ok=True)
        try:
            self.engine = sa.create_engine(url, connect_args=_connect_args(url, self.file is not None))
        except (sa.exc.ArgumentError, sa.exc.NoSuchModuleError, ModuleNotFoundError, ValueError) as exc:
            # a URL's parse errors quote the URL, password and all: named by their kind alone
            why = exc if isinstance(exc, (sa.exc.NoSuchModuleError, ModuleNotFoundError)) else type(exc).__name__
            raise InputError(f"{self.location}: not a database URL SQLAlchemy can open ({why})") from None
        if self.file is not None:
            _serialize_sqlite_writes(self.engine)
        self._prepare(create)

    def _prepare(self, create: bool) -> None:
        try:
            inspector = sa.inspect(self.engine)
            present = inspector.has_table(_ROWS.name)
        except sa.exc.DatabaseError as exc:
            if isinstance(exc, sa.exc.OperationalError) and self.file is None:  # a server: down, refused, locked
                raise InputError(f"{self.location}: {database_trouble(exc)}") from None
            raise InputError(f"{self.location}: not a database ({exc.orig})") from None
        if not present and not create:
            raise InputError(f"{self.location}: the database has no calibrations table; not a gyrocomp store")
        if present and not inspector.has_table(_INFO.name):
            raise InputError(
                f"{self.location}: its calibrations table was not written by gyrocomp (the database has no "
                f"{_INFO.name} table); gyrocomp neither reads nor writes it: give a store of its own (a new "
                "database, SQLite file or folder)"
            )
        version = self._version() if present else None
        if present and (version is None or not version.isdigit() or int(version) > STORE_SCHEMA_VERSION):
            raise InputError(
                f"{self.location}: store schema version {version}; this gyrocomp reads up to "
                f"{STORE_SCHEMA_VERSION} (upgrade gyrocomp)"
            )
        if create and version != str(STORE_SCHEMA_VERSION):
            with self._writing(schema=True) as conn:  # one transaction: a second creator waits, then finds it done
                self._create_or_upgrade(conn)
            version = str(STORE_SCHEMA_VERSION)
        #: the store's schema version (a store of version 1 is read as it is, and upgraded by its next writer)
        self.schema_version = int(version)
        self._columns = _READ + ([_ROWS.c.station] if self.schema_version >= 2 else [])

    def _version(self) -> str | None:
        with self.engine.connect() as conn:
            return conn.execute(_VERSION).scalar()

    @staticmethod
    def _create_or_upgrade(conn) -> None:
        """Create the tables, or bring a store of schema 1 to :data:`STORE_SCHEMA_VERSION` (its rows kept as they
        are: they name no station and supersede nothing)."""
        if not sa.inspect(conn).has_table(_ROWS.name):
            _META.create_all(conn, checkfirst=True)
            conn.execute(_INFO.insert().values(key="schema_version", value=str(STORE_SCHEMA_VERSION)))
            return
        if conn.execute(_VERSION).scalar() == "1":
            for column in (_ROWS.c.station, _ROWS.c.supersedes):
                conn.execute(
                    sa.text(f"ALTER TABLE {_ROWS.name} ADD COLUMN {column.name} {column.type.compile(conn.dialect)}")
                )
            if conn.dialect.name == "postgresql":  # schema 1 made the serial a VARCHAR(200), which PostgreSQL enforces
                conn.execute(sa.text(f"ALTER TABLE {_ROWS.name} ALTER COLUMN serial TYPE TEXT"))
            _CHAIN.create(conn)
            CLAIMS.create(conn, checkfirst=True)
            conn.execute(_INFO.update().where(_INFO.c.key == "schema_version").values(value=str(STORE_SCHEMA_VERSION)))

    def close(self) -> None:
        self.engine.dispose()

    def __enter__(self) -> "CalibrationStore":
        return self

    def __exit__(self, kind, exc, trace) -> None:
        self.close()
        if isinstance(exc, sa.exc.DBAPIError):  # the database's own refusal, reaching the command: one line
            raise InputError(f"{self.location}: {database_trouble(exc)}") from None

    # -- writing -------------------------------------------------------------------------------------------
    @contextlib.contextmanager
    def _writing(self, schema: bool = False):
        """A write transaction (SQLite: ``BEGIN IMMEDIATE``, writers take turns; PostgreSQL: concurrent, at
        repeatable read, kept apart by the unique chain, and, for ``schema`` changes, a transaction-wide advisory
        lock); a full disk or a read-only store is one line naming the store. Conflicts that a retry resolves
        propagate as :class:`_Retry`."""
        try:
            with self.transaction(snapshot=not schema) as conn:
                if schema and conn.dialect.name == "postgresql":
                    conn.execute(sa.text("SELECT pg_advisory_xact_lock(:key)"), {"key": _SCHEMA_LOCK_KEY})
                yield conn
        except sa.exc.IntegrityError as exc:
            raise _Retry(str(exc.orig)) from None
        except sa.exc.OperationalError as exc:
            if getattr(exc.orig, "sqlstate", None) in _RETRIED_SQLSTATES:
                raise _Retry(str(exc.orig)) from None
            if self.file is None or "locked" in str(exc.orig):  # a server, or a lock held too long: in words
                trouble = database_trouble(exc)
                raise InputError(f"{self.location}: cannot write to the calibration store: {trouble}") from None
            raise InputError(
                f"{self.location}: cannot write to the calibration store ({exc.orig}); is the disk "
                "full or the store read-only?"
            ) from None
        except sa.exc.ProgrammingError as exc:  # a user without the right to write the tables
            raise InputError(
                f"{self.location}: cannot write to the calibration store: {database_trouble(exc)}"
            ) from None

    @contextlib.contextmanager
    def transaction(self, snapshot: bool = False):
        """A connection in a write transaction (on SQLite holding the write lock from its start); ``snapshot``: on
        PostgreSQL at repeatable read, every statement of it seeing one snapshot. Errors as the database raises
        them."""
        with self.engine.connect() as conn:
            conn.info["immediate"] = True
            if snapshot and conn.dialect.name == "postgresql":
                conn.execution_options(isolation_level="REPEATABLE READ")
            with conn.begin():
                yield conn

    def _retrying(self, write: Callable[[], object]):
        """``write()`` (one transaction), tried again on a conflict with another writer, up to
        :data:`WRITE_TRIES` times with a random pause."""
        for attempt in range(WRITE_TRIES):
            try:
                return write()
            except _Retry as conflict:
                if attempt == WRITE_TRIES - 1:
                    raise InputError(
                        f"{self.location}: another writer conflicted with this one {WRITE_TRIES} times "
                        f"in a row ({str(conflict)[:160]}); try again"
                    ) from None
                time.sleep(random.uniform(0.0, 0.05 * 2 ** min(attempt, 6)))
        raise AssertionError("unreachable")

    def add(self, record: CalibrationRecord) -> int:
        """Append ``record`` (a new row, whatever the serial's history); returns its id."""
        return self._retrying(lambda: self._append(record, None, False))

    def add_new(self, record: CalibrationRecord, since: _dt.datetime, *, stamp: bool = False) -> int | None:
        """Append a successful ``record`` unless another writer stored a successful calibration of the same unit
        from the same inputs (its ``input_hash``) after ``since`` (naive UTC): the check and the write are one
        transaction, retried on a conflict with another writer. ``stamp``: the row's time is the time of the
        write (the newest row of a unit is then also the latest). Returns the new row's id, or None when it was
        not stored."""
        return self._retrying(lambda: self._append(record, since, stamp))

    def _append(self, record: CalibrationRecord, since: _dt.datetime | None, stamp: bool) -> int | None:
        with self._writing() as conn:
            previous = None
            if record.status == "ok":
                if (
                    since is not None
                    and conn.execute(
                        sa.select(_ROWS.c.id)
                        .where(
                            (_ROWS.c.serial == record.serial)
                            & (_ROWS.c.status == "ok")
                            & (_ROWS.c.input_hash == record.input_hash)
                            & (_ROWS.c.calibrated_utc >= since)
                        )
                        .limit(1)
                    ).scalar()
                    is not None
                ):
                    return None
                previous = conn.execute(_newest_ok(record.serial)).scalar() or 0
            row = _to_row(record if not stamp else _replace(record, calibrated_utc=utc_now()))
            result = conn.execute(_ROWS.insert().values(**row, supersedes=previous))
            return int(result.inserted_primary_key[0])

    def newest_ok_id(self, serial: str) -> int | None:
        """The id of the newest successful row of ``serial`` (None when it has none)."""
        with self.engine.connect() as conn:
            return conn.execute(_newest_ok(serial)).scalar()

    # -- reading -------------------------------------------------------------------------------------------
    def _records(self, query) -> list[CalibrationRecord]:
        """The records of the rows ``query`` selects; a damaged row (a time that is none, a field that is not the
        JSON gyrocomp wrote: another program's edit, a damaged file) is one line naming the store and the row."""
        with self.engine.connect() as conn:
            try:
                rows = list(conn.execute(query).mappings())
            except (ValueError, TypeError, OverflowError) as exc:  # the time column, parsed as rows are fetched
                raise InputError(
                    f"{self.location}: {self._bad_time(conn) or 'a row'} holds no time gyrocomp wrote "
                    f"({exc}); the store was changed by another program"
                ) from None
        out = []
        for row in rows:
            try:
                out.append(_from_row(row))
            except (ValueError, TypeError, KeyError, AttributeError) as exc:
                raise InputError(
                    f"{self.location}: row {row['id']} (unit {str(row['serial'])[:80]!r}) is damaged "
                    f"({type(exc).__name__}: {str(exc)[:120]}); the store was changed by another "
                    "program"
                ) from None
        return out

    @staticmethod
    def _bad_time(conn) -> str | None:
        """``row N (unit S)``: the first row whose time is no ISO time, read as text."""
        query = sa.select(_ROWS.c.id, _ROWS.c.serial, sa.cast(_ROWS.c.calibrated_utc, sa.Text)).order_by(_ROWS.c.id)
        for row_id, serial, text in conn.execute(query):
            try:
                _dt.datetime.fromisoformat(str(text))
            except ValueError:
                return f"row {row_id} (unit {str(serial)[:80]!r})"
        return None

    def history(self, serial: str) -> list[CalibrationRecord]:
        """Every row of ``serial``, oldest first."""
        return self._records(
            sa.select(*self._columns).where(_ROWS.c.serial == serial).order_by(_ROWS.c.calibrated_utc, _ROWS.c.id)
        )

    def latest(self, serial: str) -> CalibrationRecord | None:
        """The newest row of ``serial`` (ok or failed), or None."""
        rows = self.history(serial)
        return rows[-1] if rows else None

    def valid_at(self, serial: str, at: _dt.datetime | None = None) -> CalibrationRecord:
        """The calibration of ``serial`` valid at ``at`` (naive UTC; default now): its newest successful row made
        at or before then."""
        rows = self.history(serial)
        if not rows:
            raise InputError(f"serial: no unit {serial!r} in {self.location}")
        ok = [r for r in rows if r.status == "ok" and (at is None or r.calibrated_utc <= at)]
        if not ok:
            first = next((r for r in rows if r.status == "ok"), None)
            when = f" at {at:%Y-%m-%d %H:%M:%S}" if at is not None else ""
            hint = (
                f"; its first calibration is of {first.calibrated_utc:%Y-%m-%d %H:%M:%S} UTC"
                if first is not None
                else f"; every calibration of it failed (last: {rows[-1].error})"
            )
            raise InputError(f"serial: unit {serial!r} had no valid calibration{when}{hint}")
        return ok[-1]

    def latest_rows(self) -> list[CalibrationRecord]:
        """The newest row of every unit, by serial."""
        newest = sa.select(_ROWS.c.serial, sa.func.max(_ROWS.c.id).label("id")).group_by(_ROWS.c.serial).subquery()
        return self._records(sa.select(*self._columns).join(newest, _ROWS.c.id == newest.c.id).order_by(_ROWS.c.serial))

    def ok_hash(self, serial: str) -> str | None:
        """The input hash of ``serial``'s newest successful calibration (None when it has none)."""
        with self.engine.connect() as conn:
            return conn.execute(
                sa.select(_ROWS.c.input_hash).where(_ROWS.c.id == _newest_ok(serial).scalar_subquery())
            ).scalar()

    def station_counts(self) -> list[tuple[str | None, str, int, _dt.datetime | None]]:
        """(station, status, rows, newest time) for each station and status (station None: rows that name none)."""
        keys = [_ROWS.c.station, _ROWS.c.status] if self.schema_version >= 2 else [_ROWS.c.status]
        query = sa.select(*keys, sa.func.count(), sa.func.max(_ROWS.c.calibrated_utc)).group_by(*keys)
        with self.engine.connect() as conn:
            return [tuple(row) if len(keys) == 2 else (None, *row) for row in conn.execute(query)]

    def serials(self) -> list[str]:
        with self.engine.connect() as conn:
            return list(conn.execute(sa.select(_ROWS.c.serial).distinct().order_by(_ROWS.c.serial)).scalars())


def _newest_ok(serial: str):
    """The query of the id of ``serial``'s newest successful row (NULL when it has none)."""
    return sa.select(sa.func.max(_ROWS.c.id)).where((_ROWS.c.serial == serial) & (_ROWS.c.status == "ok"))


def _to_row(record: CalibrationRecord) -> dict:
    return {
        "serial": record.serial,
        "calibrated_utc": record.calibrated_utc,
        "status": record.status,
        "verdict": record.verdict,
        "failures": json.dumps([[f.figure, _json_float(f.value), f.reason] for f in record.failures]),
        "input_hash": record.input_hash,
        "inputs": json.dumps([[i.path, i.sha256] for i in record.inputs]),
        "unit_metadata": json.dumps(dict(record.metadata)),
        "gyrocomp_version": record.gyrocomp_version,
        "model": record.model_json,
        "figures": None if record.figures is None else json.dumps(record.figures.to_dict()),
        "error": record.error,
        "warnings": json.dumps(list(record.warnings)),
        "station": record.station,
    }


def _json_float(value):
    return None if isinstance(value, float) and math.isnan(value) else value


def _from_row(row) -> CalibrationRecord:
    """A row as a record; a field that is not what gyrocomp writes raises ValueError or TypeError (see
    :meth:`CalibrationStore._records`)."""
    figures = None
    if row["figures"] is not None:
        figures = UnitFigures.from_dict(json.loads(row["figures"]))
    if row["status"] not in ("ok", "failed") or not isinstance(row["calibrated_utc"], _dt.datetime):
        raise ValueError(f"status {str(row['status'])[:20]!r}, time {str(row['calibrated_utc'])[:30]!r}")
    metadata = json.loads(row["unit_metadata"])
    if not isinstance(metadata, dict):
        raise TypeError("unit_metadata is no JSON object")
    return CalibrationRecord(
        serial=row["serial"],
        calibrated_utc=row["calibrated_utc"],
        status=row["status"],
        input_hash=row["input_hash"],
        gyrocomp_version=row["gyrocomp_version"],
        inputs=tuple(InputFile(str(p), str(h)) for p, h in json.loads(row["inputs"])),
        metadata={str(k): str(v) for k, v in metadata.items()},
        verdict=row["verdict"],
        failures=tuple(
            Failure(str(f), math.nan if v is None else float(v), str(r)) for f, v, r in json.loads(row["failures"])
        ),
        model_json=row["model"],
        figures=figures,
        error=row["error"],
        warnings=tuple(str(w) for w in json.loads(row["warnings"])),
        station=row.get("station"),
        id=row["id"],
    )


__all__ = [
    "STORE_FILE",
    "STORE_SCHEMA_VERSION",
    "CalibrationRecord",
    "CalibrationStore",
    "InputFile",
    "parse_time",
    "shown_location",
    "store_url",
    "utc_now",
]
