"""A throwaway PostgreSQL cluster for the tests and benchmarks: initdb into a temporary folder, pg_ctl start on a
Unix socket only (no TCP port), a new empty database per call, everything stopped and removed at the end.

The server refuses to run as root: as root, initdb and pg_ctl run as the user ``postgres`` (which Debian's
postgresql package creates). ``binaries()`` finds initdb and pg_ctl on PATH or in /usr/lib/postgresql/N/bin.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path


def binaries() -> Path | None:
    """The folder of initdb and pg_ctl, or None where the server is not installed."""
    for folder in os.environ.get("PATH", "").split(os.pathsep) + sorted(
        (str(p) for p in Path("/usr/lib/postgresql").glob("*/bin")), reverse=True
    ):
        if folder and (Path(folder) / "initdb").exists() and (Path(folder) / "pg_ctl").exists():
            return Path(folder)
    return None


def _as_server_user(command: list[str]) -> list[str]:
    if os.geteuid() != 0:
        return command
    return ["su", "postgres", "-s", "/bin/sh", "-c", " ".join(f"'{c}'" for c in command)]


@contextlib.contextmanager
def throwaway_cluster() -> Iterator[Callable[[], str]]:
    """Start a cluster; yield a function that creates a new empty database and returns its URL
    (``postgresql://postgres@/NAME?host=SOCKET_FOLDER&port=N``)."""
    import sqlalchemy as sa

    folder_of_binaries = binaries()
    if folder_of_binaries is None:
        raise RuntimeError("no PostgreSQL server binaries (initdb, pg_ctl)")
    folder = Path(tempfile.mkdtemp(prefix="gyrocomp-pg-"))
    if os.geteuid() == 0:
        shutil.chown(folder, "postgres")
    data, port = folder / "data", 5432
    pg_ctl = str(folder_of_binaries / "pg_ctl")
    try:
        subprocess.run(
            _as_server_user(
                [
                    str(folder_of_binaries / "initdb"),
                    "-D",
                    str(data),
                    "-A",
                    "trust",
                    "-U",
                    "postgres",
                    "--no-sync",
                    "-E",
                    "UTF8",
                ]
            ),
            check=True,
            capture_output=True,
        )
        subprocess.run(
            _as_server_user(
                [
                    pg_ctl,
                    "-D",
                    str(data),
                    "-w",
                    "-l",
                    str(folder / "log"),
                    "-o",
                    f"-k {folder} -p {port} -c listen_addresses= -c fsync=off -c max_connections=200",
                    "start",
                ]
            ),
            check=True,
            capture_output=True,
        )
        admin = sa.create_engine(
            f"postgresql+psycopg://postgres@/postgres?host={folder}&port={port}", isolation_level="AUTOCOMMIT"
        )
        made = []

        def new_database() -> str:
            name = f"store_{len(made)}"
            with admin.connect() as conn:
                conn.execute(sa.text(f"CREATE DATABASE {name}"))
            made.append(name)
            return f"postgresql://postgres@/{name}?host={folder}&port={port}"

        try:
            yield new_database
        finally:
            admin.dispose()
    finally:
        subprocess.run(_as_server_user([pg_ctl, "-D", str(data), "-m", "immediate", "stop"]), capture_output=True)
        shutil.rmtree(folder, ignore_errors=True)
