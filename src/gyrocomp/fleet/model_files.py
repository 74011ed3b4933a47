"""The fleet's output folder: each unit's model file under a name its serial gives, stored with its row (the file
in place before the row is visible), the fleet table, and a model file put back from the store."""

from __future__ import annotations

import hashlib
import re
import warnings
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import DataQualityWarning, GyrocompError, InputError, user_stacklevel
from ..io.atomic import atomic_path, folder_lock, write_text_atomic
from .store import CalibrationRecord, CalibrationStore


if TYPE_CHECKING:
    import pandas as pd

#: the folder of the output that holds each unit's model file
MODELS_FOLDER = "models"
#: the fleet table in the output folder (one row per unit)
FLEET_TABLE = "fleet.parquet"


#: the longest serial kept whole in a model file's name [characters]
MAX_NAME_CHARS = 80


def model_file_name(serial: str) -> str:
    """The model file of a unit, ``SERIAL.json``, one per serial: a serial of letters, digits, ``.``, ``-`` and
    ``_`` (ASCII) up to :data:`MAX_NAME_CHARS` long is its own name; any other (``a/b``, a long or non-ASCII one)
    becomes its safe characters, ``~`` and 16 hex digits of its SHA-256, so that two serials never share a file
    (``a/b`` and ``a_b`` once did) and no name is too long for the file system."""
    if re.fullmatch(r"[A-Za-z0-9_-][A-Za-z0-9._-]*", serial) and len(serial) <= MAX_NAME_CHARS:
        return serial + ".json"
    safe = re.sub(r"[^A-Za-z0-9._-]", "_", serial)[:MAX_NAME_CHARS].lstrip(".")
    return f"{safe}~{hashlib.sha256(serial.encode('utf-8', 'surrogatepass')).hexdigest()[:16]}.json"


def serial_key(serial: str) -> str:
    """A Dask key part for a serial (file names: :func:`model_file_name`)."""
    return model_file_name(serial)[: -len(".json")]


def _write_model(output: Path, serial: str, model_json: str) -> None:
    """Write the unit's model file atomically; a failed write (a full or read-only disk) is one line, and nothing
    is stored for the unit, so the next run fits it again."""
    folder = output / MODELS_FOLDER
    try:
        folder.mkdir(exist_ok=True)
        write_text_atomic(folder / model_file_name(serial), model_json)
    except OSError as exc:
        raise model_write_error(folder / model_file_name(serial), serial, exc) from None


def store_with_model(db: CalibrationStore, record: CalibrationRecord, since, output: Path) -> int | None:
    """Store a successful ``record`` (:meth:`CalibrationStore.add_new` with ``since``, a time) and its unit's model
    file in ``output``'s models folder, under the folder's lock (writers of one folder take turns).

    The file is renamed into place before the row is committed, so that a row is never visible without its
    model file, at any moment of a kill: a kill between the two leaves a file newer than the unit's newest row,
    and the unit, its inputs not stored, is fitted again by the next run. When the row is not stored (another fit
    stored the unit from the same inputs, or the store failed or the write was interrupted) the file the unit had
    is put back. Returns the row's id, or None when another fit had stored the unit."""
    folder = output / MODELS_FOLDER
    path = folder / model_file_name(record.serial)
    try:
        folder.mkdir(exist_ok=True)
        with folder_lock(path):
            previous = _previous_model(path)
            write_text_atomic(path, record.model_json)
            try:
                row = db.add_new(record, since=since, stamp=True)
            except BaseException:
                _put_back(path, previous)
                raise
            if row is None:
                _put_back(path, previous)
            return row
    except OSError as exc:
        raise model_write_error(path, record.serial, exc) from None


def _previous_model(path: Path) -> bytes | None:
    """The unit's model file as it is (None: none yet)."""
    try:
        return path.read_bytes()
    except FileNotFoundError:
        return None


def _put_back(path: Path, previous: bytes | None) -> None:
    """The unit's model file as it was before a row that was not stored (removed when there was none)."""
    if previous is None:
        path.unlink(missing_ok=True)
    else:
        with atomic_path(path) as tmp:
            tmp.write_bytes(previous)


def model_write_error(path: Path, serial: str, exc: OSError) -> InputError:
    """The one line for a unit's model file that could not be written (nothing is stored for the unit)."""
    return InputError(
        f"{path}: cannot write unit {serial!r}'s model ({exc.strerror or exc}); nothing was stored "
        "for it, the next run fits it again"
    )


def repair_model(output: Path, db: CalibrationStore, serial: str) -> None:
    """An unchanged unit's model file is checked against its newest successful row: a missing file (deleted, a
    run stopped between the two writes) is put back; one that differs (another unit's copied over it, cut short,
    edited) is written again from the row, and said."""
    path = output / MODELS_FOLDER / model_file_name(serial)
    ok = [r for r in db.history(serial) if r.status == "ok"]
    if not ok:
        return
    try:
        present = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        present = None
    except (OSError, UnicodeDecodeError):
        present = ""
    if present != ok[-1].model_json:
        try:  # a row another program damaged is no model to write back: said, the file left as it is
            ok[-1].calibration()
        except GyrocompError as exc:
            raise InputError(
                f"{db.location}: {exc}; {path} is left as it is (refit the unit into a new store, or "
                "restore the store from a copy)"
            ) from None
        _write_model(output, serial, ok[-1].model_json)
        if present is not None:
            warnings.warn(
                f"{path}: differed from unit {serial!r}'s newest calibration in the store (row "
                f"{ok[-1].id}); written again from the store",
                DataQualityWarning,
                stacklevel=user_stacklevel(),
            )


def write_fleet_table(table: pd.DataFrame, path: Path) -> Path:
    """Write the fleet table (one row per unit, its newest calibration; see :func:`fleet_table`) atomically."""
    with atomic_path(path) as tmp:
        table.to_parquet(tmp, index=False)
    return path


__all__ = [
    "FLEET_TABLE",
    "MAX_NAME_CHARS",
    "MODELS_FOLDER",
    "model_file_name",
    "model_write_error",
    "repair_model",
    "serial_key",
    "store_with_model",
    "write_fleet_table",
]
