"""Stations: several fleet fits writing one store at once, each unit fitted by one of them.

A station claims a unit in the store before it fits it (a row of the ``claims`` table, one per serial), and
releases the claim once the unit's outcome is stored. Another station that finds the claim skips the unit
(``busy``). A claim is renewed (its heartbeat) every :data:`CLAIM_RENEW_S` while its station runs; it can be
taken over when its heartbeat is older than :data:`CLAIM_LEASE_S` (a station that died on another machine), or at
once when its process is gone from this machine (a station killed here and run again). A claim is never what keeps
the store consistent (that is the unique chain of :mod:`gyrocomp.fleet.store`): it keeps two stations from
fitting one unit twice.
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import os
import socket
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError
from ..io.atomic import process_alive
from .store import CLAIMS, CalibrationStore, sa, utc_now

#: a claim whose heartbeat is older than this is another machine's dead station's, and may be taken over [s]
CLAIM_LEASE_S = 600.0
#: how often a running station renews the heartbeat of its claims [s]
CLAIM_RENEW_S = 30.0


@dataclass(frozen=True)
class Station:
    """Who fits: the station's name (default: the machine's), its host and process."""

    name: str
    host: str
    pid: int

    @classmethod
    def here(cls, name: str | None = None) -> "Station":
        host = socket.gethostname()
        return cls(name or host, host, os.getpid())


@dataclass(frozen=True)
class Claim:
    """A unit being fitted: by which station, since when and its last heartbeat (naive UTC)."""

    serial: str
    station: str
    host: str
    pid: int
    claimed_utc: _dt.datetime
    heartbeat_utc: _dt.datetime

    def stale(self, now: _dt.datetime, host: str) -> bool:
        """Whether the claim may be taken over: its heartbeat older than the lease, or its process gone from this
        machine."""
        if (now - self.heartbeat_utc).total_seconds() > CLAIM_LEASE_S:
            return True
        return self.host == host and not _running(self.pid)


def _running(pid: int) -> bool:
    """Whether process ``pid`` runs on this machine (a zombie, killed and not yet reaped, does not)."""
    if not process_alive(pid):
        return False
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return True
    return state not in ("Z", "X")


def claim(db: CalibrationStore, serial: str, me: Station) -> Claim | None:
    """Claim ``serial`` for ``me``; returns None when claimed (or already mine), else the claim that holds it."""
    now = utc_now()
    mine = {"station": me.name, "host": me.host, "pid": me.pid, "claimed_utc": now, "heartbeat_utc": now}
    for _ in range(3):
        try:
            with db.transaction() as conn:
                held = conn.execute(sa.select(CLAIMS).where(CLAIMS.c.serial == serial)).mappings().first()
                if held is None:
                    conn.execute(CLAIMS.insert().values(serial=serial, **mine))
                    return None
                holder = Claim(**held)
                if (holder.host, holder.pid) != (me.host, me.pid) and not holder.stale(now, me.host):
                    return holder
                taken = conn.execute(
                    CLAIMS.update()
                    .where(  # take it over, unless another station did since
                        (CLAIMS.c.serial == serial)
                        & (CLAIMS.c.host == holder.host)
                        & (CLAIMS.c.pid == holder.pid)
                        & (CLAIMS.c.heartbeat_utc == holder.heartbeat_utc)
                    )
                    .values(**mine)
                ).rowcount
                if taken == 1:
                    return None
        except sa.exc.IntegrityError:
            pass  # claimed by another station between the look and the insert: look again
    with db.engine.connect() as conn:
        held = conn.execute(sa.select(CLAIMS).where(CLAIMS.c.serial == serial)).mappings().first()
    if held is None:
        raise InputError(f"{db.location}: unit {serial!r}: its claim changed hands three times in a row; try again")
    return Claim(**held)


def release(db: CalibrationStore, serial: str, me: Station) -> None:
    """Release ``me``'s claim of ``serial`` (nothing when it holds none)."""
    with db.transaction() as conn:
        conn.execute(
            CLAIMS.delete().where((CLAIMS.c.serial == serial) & (CLAIMS.c.host == me.host) & (CLAIMS.c.pid == me.pid))
        )


def renew(db: CalibrationStore, me: Station) -> None:
    """Renew the heartbeat of every claim of ``me``."""
    with db.transaction() as conn:
        conn.execute(
            CLAIMS.update().where((CLAIMS.c.host == me.host) & (CLAIMS.c.pid == me.pid)).values(heartbeat_utc=utc_now())
        )


def claims(db: CalibrationStore) -> list[Claim]:
    """Every claim in the store, by serial (none in a store of schema 1, which had no claims)."""
    if db.schema_version < 2:
        return []
    with db.engine.connect() as conn:
        return [Claim(**row) for row in conn.execute(sa.select(CLAIMS).order_by(CLAIMS.c.serial)).mappings()]


@contextlib.contextmanager
def station(db: CalibrationStore, me: Station) -> Iterator[Station]:
    """Run as station ``me`` for the block: its claims renewed in a background thread every
    :data:`CLAIM_RENEW_S`, and all of them released at the end, however the block ends."""
    stop = threading.Event()

    def beat() -> None:
        while not stop.wait(CLAIM_RENEW_S):
            with contextlib.suppress(sa.exc.SQLAlchemyError):  # a missed beat is renewed at the next
                renew(db, me)

    thread = threading.Thread(target=beat, name="gyrocomp-station-heartbeat", daemon=True)
    thread.start()
    try:
        yield me
    finally:
        stop.set()
        thread.join()
        with contextlib.suppress(sa.exc.SQLAlchemyError):
            with db.transaction() as conn:
                conn.execute(CLAIMS.delete().where((CLAIMS.c.host == me.host) & (CLAIMS.c.pid == me.pid)))


@dataclass(frozen=True)
class StationStatus:
    """What one station has done: its calibrations stored (``ok``, ``failed``), its last write (naive UTC), the
    units it is fitting now, and how many of those claims are stale (its process gone, or silent past the
    lease: rerun the station to finish them)."""

    station: str
    ok: int
    failed: int
    last_utc: _dt.datetime | None
    fitting: tuple[str, ...]
    stale: int


def station_status(db: CalibrationStore) -> list[StationStatus]:
    """Each station's work in the store (rows written before stations were recorded count under ``(none)``)."""
    rows = db.station_counts()
    held = claims(db)
    now, host = utc_now(), socket.gethostname()
    names = sorted({name for name, *_ in rows} | {c.station for c in held}, key=lambda n: (n is None, n or ""))
    out = []
    for name in names:
        counts = {status: (n, last) for station_name, status, n, last in rows if station_name == name}
        mine = [c for c in held if c.station == name]
        lasts = [last for _n, last in counts.values() if last is not None]
        out.append(
            StationStatus(
                name if name is not None else "(none)",
                counts.get("ok", (0, None))[0],
                counts.get("failed", (0, None))[0],
                max(lasts) if lasts else None,
                tuple(c.serial for c in mine),
                sum(c.stale(now, host) for c in mine),
            )
        )
    return out


__all__ = [
    "CLAIM_LEASE_S",
    "CLAIM_RENEW_S",
    "Claim",
    "Station",
    "StationStatus",
    "claim",
    "claims",
    "release",
    "renew",
    "station",
    "station_status",
]
