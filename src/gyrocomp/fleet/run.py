"""Fit a fleet: one model per unit, on a Dask cluster, into a calibration store; resumable and failure-tolerant.

Each unit is one task. The task gets the unit's file paths and the settings (a few hundred bytes), reads and
hashes its own files, fits them as ``gyrocomp fit`` would with its defaults (:func:`gyrocomp.fit`),
computes the figures of merit, and returns the model JSON and the figures (a few kB): nothing large passes
through the client, whatever the size of the runs. The client appends one row per unit to the store as the
tasks finish, so an interrupted fleet keeps what it finished. A rerun passes each unit the input hash of its
newest successful calibration; a unit whose files (by content) and settings hash the same returns at once
without fitting. A unit that fails (an unreadable file, too little data, any error) is recorded with its error
and the others go on.

Several fleet fits (stations, on one machine or several) may write one store at once, with overlapping units:
each claims a unit before fitting it (:mod:`gyrocomp.fleet.stations`) and skips those another station is fitting,
so each unit is fitted and stored once; a station killed at any moment leaves the store consistent, and its rerun
finishes the rest. A unit's model file is written beside its row: staged before the row is committed, renamed
into place after (under a lock of the models folder, so that the file is always that of the unit's newest row);
a station killed between the two leaves a row whose file its rerun puts back.

Schedulers: ``"local"`` starts a local Dask cluster (one single-threaded worker process per core, memory bounded
per worker), an address (``tcp://host:8786``) uses a running cluster (the run files must be readable at the same
paths on the workers: a shared file system), ``"serial"`` fits in this process one unit after another (no Dask;
the baseline of ``benchmarks/bench_fleet.py``).
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Literal

from .._version import __version__
from ..errors import GyrocompError, InputError
from ..files.check import ask_for, read_checked, refuse, rewarn, warn_findings
from ..io import ReadOptions
from ..measures.data_check import check_runs
from ..io.foreign_libraries import require
from ..models.fit import fit
from ..models.pipelines import Pipeline
from ..models.fit import check_channels
from ..runs.prepared import Channel
from ..threads import single_threaded_blas
from .unit_figures import REFERENCE_TEMPERATURE_DEGC, UnitFigures, unit_figures
from .limits import Limits
from .population import fleet_table
from .prior import PopulationPrior, fit_with_prior
from .store import CalibrationRecord, CalibrationStore, InputFile, utc_now
from .stations import Station, claim, release, station as running_as
from .devices import UnitRuns, content_hash, input_hash
from .cluster import check_reachable, dask_client
from .model_files import FLEET_TABLE, repair_model, serial_key, store_with_model, write_fleet_table

if TYPE_CHECKING:
    import pandas as pd

#: most warnings kept per unit (a run can warn once per axis and check)
_MAX_WARNINGS = 20


@dataclass(frozen=True)
class FleetSettings:
    """How each unit is read and fitted (the defaults are ``gyrocomp fit``'s).

    Parameters
    ----------
    channels : tuple of str
        ``("gyro",)``, ``("accel",)`` or both (see :func:`gyrocomp.fit`).
    pipeline : str
        The fit's pipeline (``"joint"``).
    read : ReadOptions
        Column layout and units of tables, sensor instance of logs.
    fmt : str, optional
        The runs' format (default: told from each file).
    reference_temperature_degc : float
        Reference of the temperature figures [degC].
    prior : PopulationPrior, optional
        Fit each unit with this population prior (:func:`gyrocomp.fleet.fit_with_prior`: short runs) instead of
        the default fit; ``channels`` and ``pipeline`` then do not apply.
    accept : tuple of str
        Data checks accepted knowingly (:mod:`gyrocomp.measures.data_check`): a unit whose runs the check refuses
        is recorded as failed with the reason, unless its check is accepted here.
    """

    channels: tuple[Channel, ...] = ("gyro",)
    pipeline: Pipeline = "joint"
    read: ReadOptions = field(default_factory=ReadOptions)
    fmt: str | None = None
    reference_temperature_degc: float = REFERENCE_TEMPERATURE_DEGC
    prior: PopulationPrior | None = None
    accept: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "channels", check_channels(self.channels))

    def fingerprint(self) -> dict:
        """What of the settings changes a unit's model (part of its input hash)."""
        return {
            "channels": list(self.channels),
            "pipeline": self.pipeline,
            "read": repr(self.read),
            "fmt": self.fmt,
            "reference_temperature_degc": self.reference_temperature_degc,
            "prior": None if self.prior is None else self.prior.digest(),
            **({"accept": sorted(self.accept)} if self.accept else {}),
        }


@dataclass(frozen=True)
class UnitOutcome:
    """What one unit's task returns: ``unchanged`` when its inputs hash as its newest calibration's did; ``busy``
    (``error`` says by whom) when another station is fitting it."""

    serial: str
    status: Literal["ok", "failed", "unchanged", "busy"]
    input_hash: str
    inputs: tuple[InputFile, ...] = ()
    model_json: str | None = None
    figures: UnitFigures | None = None
    error: str | None = None
    warnings: tuple[str, ...] = ()


@dataclass(frozen=True)
class FleetSummary:
    """What a fleet fit did: units fitted now, skipped as unchanged, failed, the verdicts of those fitted, and
    the warnings of the fit of each unit fitted now that had any (kept in the store with its calibration), and
    the units left to the other stations fitting them (by whom)."""

    fitted: tuple[str, ...]
    unchanged: tuple[str, ...]
    failed: dict[str, str]
    passed: tuple[str, ...]
    rejected: tuple[str, ...]
    store: str
    table: Path | None
    warned: dict[str, tuple[str, ...]] = field(default_factory=dict)
    busy: dict[str, str] = field(default_factory=dict)
    #: the fleet table as written (one row per unit): what a caller shows, without reading back a file another
    #: fit of the same folder may be replacing at that moment
    units: pd.DataFrame | None = None


@single_threaded_blas
def fit_unit(unit: UnitRuns, settings: FleetSettings, known_hash: str | None = None) -> UnitOutcome:
    """Fit one unit (the task of a fleet fit): hash its files, stop if the hash is ``known_hash``, else read,
    fit and measure. Never raises for a problem of the unit: the outcome is then ``failed`` with the error."""
    try:
        inputs = tuple(InputFile(p, content_hash(p)) for p in unit.paths)
    except OSError as exc:
        return UnitOutcome(unit.serial, "failed", "", error=_error_text(exc))
    digest = input_hash(unit.paths, settings.fingerprint(), contents=[i.sha256 for i in inputs])
    if digest == known_hash:
        return UnitOutcome(unit.serial, "unchanged", digest, inputs)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            runs = [read_checked(p, settings.read, settings.fmt) for p in unit.paths]
            unread = next((r for r in runs if r.recording is None), None)
            if unread is not None:
                raise InputError(unread.refusal or f"{unread.source}: unreadable")
            rewarn(runs)
            checks = check_runs(runs, ask_for(), settings.accept)
            refuse(checks)
            recordings = [r.recording for r in runs]
            if settings.prior is not None:
                calibration = fit_with_prior(recordings, settings.prior)
            else:
                calibration = fit(recordings, channels=settings.channels, pipeline=settings.pipeline)
            figures = unit_figures(
                calibration, recordings, reference_temperature_degc=settings.reference_temperature_degc
            )
            warn_findings(checks)  # after the fit's own warnings, which say more of this unit's model
        except Exception as exc:  # noqa: BLE001 - one unit's failure, whatever it is, must not stop the fleet
            return UnitOutcome(unit.serial, "failed", digest, inputs, error=_error_text(exc))
    messages = tuple(dict.fromkeys(str(w.message) for w in caught))[:_MAX_WARNINGS]
    return UnitOutcome(unit.serial, "ok", digest, inputs, calibration.to_json(), figures, warnings=messages)


def _error_text(exc: BaseException) -> str:
    if isinstance(exc, GyrocompError):
        return str(exc)
    return f"{type(exc).__name__}: {exc}"


def fit_fleet(
    units: Iterable[UnitRuns],
    output: str | os.PathLike,
    settings: FleetSettings | None = None,
    *,
    limits: Limits | None = None,
    scheduler: str = "local",
    workers: int | None = None,
    memory_limit: str | int = "auto",
    store: str | os.PathLike | None = None,
    progress: Callable[[int, int], None] | None = None,
    station: str | None = None,
) -> FleetSummary:
    """Fit every unit (see the module) and write the fleet's outputs into the folder ``output``.

    Parameters
    ----------
    units : iterable of UnitRuns
        The units and their run files (:func:`units_from_pattern`, :func:`units_from_manifest`).
    output : path
        Folder for the store (``calibrations.sqlite``, unless ``store`` names another), the newest model of each
        unit (``models/SERIAL.json``) and the fleet table (``fleet.parquet``).
    settings : FleetSettings, optional
        How each unit is read and fitted.
    limits : Limits, optional
        Pass/fail limits; each unit's verdict is stored with its calibration, and the table judges every unit
        by these limits.
    scheduler : str
        ``"local"`` (a local Dask cluster), ``"serial"`` (this process, no Dask), or a Dask scheduler address.
    workers : int, optional
        Worker processes of the local cluster (default: one per core).
    memory_limit : str or int
        Memory per worker of the local cluster (Dask's ``"auto"``: the machine's memory shared out; or bytes,
        or ``"2GiB"``); a worker past it is restarted by Dask and its unit recorded as failed.
    store : str or path, optional
        Another store location (an SQLite file or a database URL; see :mod:`gyrocomp.fleet.store`).
    progress : callable, optional
        Called with (units done, units in all) as each unit finishes.
    station : str, optional
        This station's name, stored with each row it writes (default: the machine's name).
    """
    units, output = _checked(units, output, scheduler)
    settings = settings or FleetSettings()
    tally = _Tally()
    started = utc_now()
    with (
        CalibrationStore(store if store is not None else output, create=True) as db,
        running_as(db, Station.here(station)) as me,
    ):
        by_serial = {u.serial: u for u in units}
        for done, outcome in enumerate(
            _outcomes(_claimed(units, db, me), settings, scheduler, workers, memory_limit), 1
        ):
            _keep(outcome, by_serial[outcome.serial], limits, output, db, started, tally, me)
            release(db, outcome.serial, me)
            if progress is not None:
                progress(done, len(units))
        table = fleet_table(db.latest_rows(), limits)
        write_fleet_table(table, output / FLEET_TABLE)
    return tally.summary(os.fspath(store if store is not None else output), output / FLEET_TABLE, table)


def _checked(units: Iterable[UnitRuns], output, scheduler: str) -> tuple[list[UnitRuns], Path]:
    """The units (their paths made absolute) and the output folder (made), after checking them and that a
    scheduler's address is reachable."""
    units = list(units)
    _check_units(units)
    if scheduler not in ("local", "serial"):
        check_reachable(scheduler)
    output = Path(output)
    if output.exists() and not output.is_dir():
        raise InputError(f"output: {output} is a file; a fleet is written into a folder")
    output.mkdir(parents=True, exist_ok=True)
    return [replace(u, paths=tuple(os.path.abspath(p) for p in u.paths)) for u in units], output


@dataclass(frozen=True)
class _Claimed:
    """A unit claimed by this station (with its newest successful calibration's input hash), or, as ``busy``, the
    outcome of a unit another station is fitting."""

    unit: UnitRuns
    known_hash: str | None = None
    busy: UnitOutcome | None = None


def _claimed(units: list[UnitRuns], db: CalibrationStore, me: Station) -> Iterator[_Claimed]:
    """Each unit as this station claims it, just before it is fitted: its input hash read then (another station
    may have stored it since this one began)."""
    for unit in units:
        holder = claim(db, unit.serial, me)
        if holder is None:
            yield _Claimed(unit, db.ok_hash(unit.serial))
        else:
            yield _Claimed(
                unit,
                busy=UnitOutcome(
                    unit.serial,
                    "busy",
                    "",
                    error=(
                        f"station {holder.station} ({holder.host}, process {holder.pid}) has been fitting it since "
                        f"{holder.claimed_utc:%Y-%m-%d %H:%M:%S} UTC"
                    ),
                ),
            )


def _keep(
    outcome: UnitOutcome,
    unit: UnitRuns,
    limits: Limits | None,
    output: Path,
    db: CalibrationStore,
    started,
    tally: "_Tally",
    me: Station,
) -> None:
    """Store one unit's outcome with its model file (:func:`gyrocomp.fleet.model_files.store_with_model`); a unit another fit stored from
    the same inputs since ``started`` counts as unchanged; an unchanged unit's missing model file is put back."""
    if outcome.status == "busy":
        tally.busy[outcome.serial] = outcome.error or "busy"
        return
    if outcome.status == "unchanged":
        tally.unchanged.append(outcome.serial)
        repair_model(output, db, outcome.serial)
        return
    record = _record(outcome, unit, limits, me.name)
    stored = (
        store_with_model(db, record, started, output)
        if record.status == "ok"
        else db.add_new(record, since=started, stamp=True)
    )
    if stored is None:
        tally.unchanged.append(outcome.serial)
    else:
        tally.count(record)


@dataclass
class _Tally:
    """What a fleet fit did so far, unit by unit."""

    fitted: list[str] = field(default_factory=list)
    unchanged: list[str] = field(default_factory=list)
    failed: dict[str, str] = field(default_factory=dict)
    passed: list[str] = field(default_factory=list)
    rejected: list[str] = field(default_factory=list)
    warned: dict[str, tuple[str, ...]] = field(default_factory=dict)
    busy: dict[str, str] = field(default_factory=dict)

    def summary(self, store: str, table, units=None) -> FleetSummary:
        """The fleet fit's summary: what this tally counted, the store's location and the fleet table (its path
        and its rows)."""
        return FleetSummary(
            tuple(self.fitted),
            tuple(self.unchanged),
            self.failed,
            tuple(self.passed),
            tuple(self.rejected),
            store=store,
            table=table,
            warned=self.warned,
            busy=self.busy,
            units=units,
        )

    def count(self, record: CalibrationRecord) -> None:
        if record.status == "ok":
            self.fitted.append(record.serial)
            if record.warnings:
                self.warned[record.serial] = tuple(record.warnings)
            (self.passed if record.verdict != "fail" else self.rejected).append(record.serial)
        else:
            self.failed[record.serial] = record.error or "failed"


def _check_units(units: list[UnitRuns]) -> None:
    if not units:
        raise InputError("units: no unit to fit")
    serials = [u.serial for u in units]
    repeated = sorted({s for s in serials if serials.count(s) > 1})
    if repeated:
        raise InputError(f"units: serial {repeated[0]!r} is given twice; give each unit once with all its runs")


#: units in flight per worker thread of a Dask cluster (each claimed just before it is submitted): enough to hide
#: the round trip to the workers; the local cluster's scheduler hands a worker one at a time (its
#: ``worker-saturation`` 1.0), the rest wait in its queue, so that a unit never waits on a worker beside another
#: that outgrows the worker's memory (Dask counts every task of a killed worker against its retries)
IN_FLIGHT_PER_THREAD = 4


def _outcomes(
    claimed: Iterator[_Claimed], settings: FleetSettings, scheduler: str, workers: int | None, memory_limit: str | int
) -> Iterator[UnitOutcome]:
    """Each unit's outcome as it finishes (a busy unit's at once)."""
    if scheduler == "serial":
        for item in claimed:
            yield item.busy or fit_unit(item.unit, settings, item.known_hash)
        return
    distributed = require("dask.distributed", "fleet", "fitting a fleet on Dask (scheduler local or an address)")
    with dask_client(distributed, scheduler, workers, memory_limit) as client:
        window = IN_FLIGHT_PER_THREAD * max(1, sum(client.nthreads().values()))
        futures: dict = {}
        running = distributed.as_completed()

        def top_up() -> list[UnitOutcome]:
            busy = []
            while len(futures) < window:
                item = next(claimed, None)
                if item is None:
                    break
                if item.busy is not None:
                    busy.append(item.busy)
                    continue
                future = client.submit(
                    fit_unit,
                    item.unit,
                    settings,
                    item.known_hash,
                    pure=False,
                    key=f"gyrocomp-fit-{serial_key(item.unit.serial)}-{os.getpid()}-{id(item)}",
                )
                futures[future] = item.unit
                running.add(future)
            return busy

        yield from top_up()
        for future in running:
            unit = futures.pop(future)
            if future.status == "finished":
                yield future.result()
            else:  # the worker died (memory limit, a crash): the unit fails, the fleet goes on
                exc = future.exception()
                why = (
                    "its worker was killed on every try (past its memory limit, or a crash): "
                    if type(exc).__name__ == "KilledWorker"
                    else ""
                )
                yield UnitOutcome(unit.serial, "failed", "", error=why + _error_text(exc))
            future.release()
            yield from top_up()


def _record(outcome: UnitOutcome, unit: UnitRuns, limits: Limits | None, station: str) -> CalibrationRecord:
    verdict = None
    if outcome.status == "ok" and limits is not None:
        verdict = limits.check(outcome.figures)
    return CalibrationRecord(
        serial=outcome.serial,
        calibrated_utc=utc_now(),
        status="ok" if outcome.status == "ok" else "failed",
        input_hash=outcome.input_hash,
        gyrocomp_version=__version__,
        inputs=outcome.inputs,
        metadata=dict(unit.metadata),
        verdict=None if verdict is None else verdict.label,
        failures=() if verdict is None else verdict.failures,
        model_json=outcome.model_json,
        figures=outcome.figures,
        error=outcome.error,
        warnings=outcome.warnings,
        station=station,
    )


__all__ = ["FleetSettings", "FleetSummary", "UnitOutcome", "fit_fleet", "fit_unit"]
