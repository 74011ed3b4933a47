"""``gyrocomp fleet``: fit many units into a calibration store, look them up, export them."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import click
from rich.table import Table

from ..errors import InputError
from ..fleet.stations import station_status
from ..fleet import model_file_name
from ..fleet import (
    CalibrationStore,
    FleetSettings,
    Limits,
    expand_inputs,
    fit_fleet,
    fleet_table,
    fleet_yield,
    parse_time,
    population_prior,
    units_from_manifest,
    units_from_pattern,
)
from ..io import refuse_to_overwrite_inputs, write_text_atomic
from ..report.fleet import build_fleet_report
from ..report.certificate import build_certificate, print_pdf
from ..fleet.certify import held_out_of
from .entry_point import in_cli_words
from .common import (
    echo,
    FINITE,
    accept_option,
    OUTPUT_FILE,
    make_console,
    parse_channels,
    pop_read_options,
    progress_bar,
    read_options,
    read_settings,
)
from ..export import EXPORTERS
from .export import write_export
from .render import print_station_status

#: failures and outliers listed after a fleet fit (the fleet table has them all)
_LISTED = 10


@click.group()
def fleet():
    """Production calibration of many units: fit them on Dask into a calibration store, judge them against
    limits, look a unit's calibration up and export it."""


@fleet.command("fit")
@click.argument("data", nargs=-1, type=click.Path())
@click.option(
    "-o",
    "--output",
    required=True,
    type=click.Path(file_okay=False),
    help="Fleet folder: calibrations.sqlite, models/SERIAL.json, fleet.parquet.",
)
@click.option(
    "--unit-from",
    "unit_pattern",
    default=None,
    metavar="PATTERN",
    help="Which unit each run belongs to, from its path: e.g. '{serial}/run_{n}.csv' (matched against "
    "the end of the path; {serial} required).",
)
@click.option(
    "--manifest",
    default=None,
    type=click.Path(dir_okay=False),
    help="CSV or Parquet table of the runs: columns path, serial, optional metadata (instead of --unit-from).",
)
@click.option(
    "--limits",
    "limits_file",
    default=None,
    type=click.Path(dir_okay=False),
    help="Pass/fail limits on the figures of merit (TOML).",
)
@click.option(
    "--scheduler",
    default="local",
    show_default=True,
    help="local (a Dask cluster on this machine), serial (no Dask), or a Dask scheduler address "
    "(tcp://host:8786; the runs must be readable at the same paths on its workers).",
)
@click.option(
    "--workers",
    type=click.IntRange(min=1),
    default=None,
    help="Local cluster: worker processes (default: one per core).",
)
@click.option(
    "--memory-limit",
    default="auto",
    show_default=True,
    help="Local cluster: memory per worker (e.g. 2GiB; auto shares the machine's memory out).",
)
@click.option("--store", default=None, help="Store the calibrations here instead (an SQLite file or a SQLAlchemy URL).")
@click.option(
    "--prior",
    "prior",
    default=None,
    help="A calibrated fleet (its folder, SQLite file or database URL): fit each unit with that "
    "population as the prior, for short chamber runs.",
)
@click.option("--channels", default="gyro", show_default=True, help="gyro, accel or gyro,accel (as gyrocomp fit).")
@click.option("--pipeline", default="joint", show_default=True, help="As gyrocomp fit.")
@accept_option
@click.option(
    "--certificates",
    type=click.Choice(["html", "pdf"]),
    default=None,
    help="Write a certificate of each unit fitted now into certificates/ (pdf: its PDF too).",
)
@click.option(
    "--station",
    default=None,
    metavar="NAME",
    help="This station's name, stored with each calibration it writes (default: the machine's name).",
)
@read_options
@click.pass_context
def fit(
    ctx,
    data,
    output,
    unit_pattern,
    manifest,
    limits_file,
    scheduler,
    workers,
    memory_limit,
    store,
    prior,
    channels,
    pipeline,
    accept,
    certificates,
    station,
    **kwargs,
):
    """Fit every unit of DATA (folders, globs or files of runs; none with --manifest) as gyrocomp fit would, in
    parallel; rerun to fit only the units whose runs changed. Several stations may fit into one store at once
    (--store URL): each unit is fitted by one of them, the others skip it."""
    opts = pop_read_options(kwargs)
    units = _units(data, unit_pattern, manifest, output)
    limits = Limits.load(limits_file) if limits_file else None
    population = None
    if prior is not None:
        with CalibrationStore(prior) as db:
            population = population_prior(db.latest_rows())
    settings = FleetSettings(
        channels=parse_channels(channels),
        pipeline=pipeline,
        read=read_settings(opts),
        fmt=opts["fmt"],
        prior=population,
        accept=tuple(accept),
    )
    memory = int(memory_limit) if memory_limit.isdigit() else memory_limit
    with progress_bar(f"{'station ' + station + ': ' if station else ''}fitting {len(units)} units") as bar:
        summary = fit_fleet(
            units,
            output,
            settings,
            limits=limits,
            scheduler=scheduler,
            workers=workers,
            memory_limit=memory,
            store=store,
            station=station,
            progress=None if bar is None else (lambda done, total: bar(done / total)),
        )
    if len(summary.failed) == len(units):
        first = next(iter(summary.failed.items()))
        raise InputError(f"every unit failed (e.g. {first[0]}: {first[1]}); nothing was calibrated")
    if certificates is not None:
        _write_certificates(summary, output, store, limits, certificates, settings)
    if not ctx.obj["quiet"]:
        _print_summary(summary, output, limits is not None)


def _units(data, unit_pattern, manifest, output) -> list:
    """The units to fit, from DATA and --unit-from or from --manifest (none of their runs the output)."""
    if (unit_pattern is None) == (manifest is None):
        raise click.UsageError(
            "say which unit each run belongs to: give --unit-from PATTERN or --manifest FILE (one of them)"
        )
    if manifest is not None:
        if data:
            raise click.UsageError("--manifest names the runs: give no DATA with it")
        units = units_from_manifest(manifest)
    else:
        if not data:
            raise click.UsageError("give DATA: the folders, globs or files of the runs (or --manifest FILE)")
        units = units_from_pattern(expand_inputs(data), unit_pattern)
    for unit in units:
        refuse_to_overwrite_inputs(output, unit.paths)
    return units


def _write_certificates(summary, output, store, limits, kind: str, settings) -> None:
    """A certificate of each unit fitted now: certificates/SERIAL.html (and .pdf)."""
    folder = Path(output) / "certificates"
    folder.mkdir(exist_ok=True)
    with (
        CalibrationStore(store if store is not None else output) as db,
        progress_bar(f"certificates of {len(summary.fitted)} units") as bar,
    ):
        for k, serial in enumerate(summary.fitted, 1):
            name = model_file_name(serial)[: -len(".json")]
            write_certificate(
                db.latest(serial),
                folder / f"{name}.html",
                folder / f"{name}.pdf" if kind == "pdf" else None,
                limits,
                settings.read,
                settings.fmt,
            )
            if bar is not None:
                bar(k / len(summary.fitted))


def _print_summary(summary, output, judged: bool) -> None:
    console = make_console()
    table = summary.units
    counts = fleet_yield(table)
    console.print(
        f"gyrocomp fleet fit -> {output}: {len(summary.fitted)} unit(s) fitted, {len(summary.unchanged)} "
        f"unchanged (skipped), {len(summary.failed)} failed"
        + (f", {len(summary.busy)} left to the other stations fitting them" if summary.busy else "")
    )
    if judged:
        console.print(f"yield: {counts.passed}/{counts.units} units pass ({100 * counts.yield_fraction:.1f} %)")
    _print_rows(
        console,
        "units other stations are fitting (gyrocomp fleet status shows them; rerun to pick up any they leave)",
        list(summary.busy.items()),
        ("serial", "fitted by"),
    )
    if summary.failed:
        _print_rows(console, "failed units", [(s, e) for s, e in summary.failed.items()], ("serial", "error"))
    if judged:
        rejected = table[table["verdict"] == "fail"]
        _print_rows(
            console,
            "units outside the limits",
            list(zip(rejected["serial"], rejected["failing"])),
            ("serial", "failing figures"),
        )
    _print_rows(
        console,
        "units fitted with warnings (gyrocomp fleet show SERIAL lists them all)",
        [
            (serial, in_cli_words(messages[0]) + (f" (and {len(messages) - 1} more)" if len(messages) > 1 else ""))
            for serial, messages in summary.warned.items()
        ],
        ("serial", "warning"),
    )
    outliers = table[table["outlier"]].sort_values("outlier_score", ascending=False)
    _print_rows(
        console,
        "outliers of the population (robust z > 3.5)",
        [
            (s, f"{z:.1f}", f)
            for s, z, f in zip(outliers["serial"], outliers["outlier_score"], outliers["outlier_figures"])
        ],
        ("serial", "score", "figures"),
    )


def _print_rows(console, title: str, rows: list[tuple], columns: tuple[str, ...]) -> None:
    if not rows:
        return
    table = Table(
        title=f"{title}: {len(rows)}" + (f" (first {_LISTED}; all in fleet.parquet)" if len(rows) > _LISTED else "")
    )
    for column in columns:
        table.add_column(column, overflow="fold")
    for row in rows[:_LISTED]:
        table.add_row(*map(str, row))
    console.print(table)


@fleet.command("status")
@click.option("--store", required=True, help="The fleet folder, an SQLite file or a SQLAlchemy URL.")
@click.option("--json", "as_json", is_flag=True, help="Print the status as JSON.")
def status(store, as_json):
    """What each station has stored in the store, and the units each is fitting now (a stale claim: its station
    died; rerun it to finish them)."""
    with CalibrationStore(store) as db:
        stations = station_status(db)
    if as_json:
        echo(
            json.dumps(
                [
                    {
                        **dataclasses.asdict(s),
                        "last_utc": None if s.last_utc is None else s.last_utc.isoformat() + "Z",
                        "fitting": list(s.fitting),
                    }
                    for s in stations
                ],
                indent=2,
            ),
            lines=True,
        )
        return
    print_station_status(stations, db.location)


@fleet.command("show")
@click.argument("serial")
@click.option("--store", required=True, help="The fleet folder, an SQLite file or a SQLAlchemy URL.")
@click.option(
    "--at",
    "at",
    default=None,
    metavar="DATE",
    help="The calibration valid at this date or time (ISO 8601, UTC unless a zone is given; a date means "
    "its end); default: the newest.",
)
@click.option("--history", is_flag=True, help="List every calibration of the unit instead.")
@click.option("--json", "as_json", is_flag=True, help="Print the calibration (record and model) as JSON.")
@click.option("-o", "--output", default=None, type=OUTPUT_FILE, help="Also write its model file here.")
@click.pass_context
def show(ctx, serial, store, at, history, as_json, output):
    """The calibration of unit SERIAL valid now (or --at a past time): when, from what, verdict, figures."""
    when = parse_time(at) if at is not None else None
    with CalibrationStore(store) as db:
        if output is not None:
            _refuse_output_over_store(output, db)
        if history:
            rows = db.history(serial)
            if not rows:
                raise InputError(f"serial: no unit {serial!r} in {db.location}")
            _print_history(rows)
            return
        record = db.valid_at(serial, when)
    calibration = record.calibration()
    if output is not None:
        calibration.save(output)
    if as_json:
        echo(json.dumps(_record_document(record), indent=2), lines=True)
    elif not ctx.obj["quiet"]:
        _print_record(record, calibration)


def _record_document(record) -> dict:
    return {
        "serial": record.serial,
        "calibrated_utc": record.calibrated_utc.isoformat() + "Z",
        "id": record.id,
        "verdict": record.verdict,
        "failures": [f.figure + " " + f.reason for f in record.failures],
        "input_hash": record.input_hash,
        "inputs": [{"path": i.path, "sha256": i.sha256} for i in record.inputs],
        "metadata": record.metadata,
        "gyrocomp_version": record.gyrocomp_version,
        "figures": record.figures.to_dict(),
        "warnings": list(record.warnings),
        "model": json.loads(record.model_json),
    }


def _print_record(record, calibration) -> None:
    console = make_console()
    console.print(
        f"unit {record.serial}: calibration {record.id} of {record.calibrated_utc:%Y-%m-%d %H:%M:%S} UTC "
        f"(gyrocomp {record.gyrocomp_version}), {len(record.inputs)} run(s); model {calibration.model}"
    )
    if record.verdict is not None:
        console.print(
            f"verdict: {record.verdict}"
            + (f" ({'; '.join(f.figure + ' ' + f.reason for f in record.failures)})" if record.failures else "")
        )
    figures = record.figures
    table = Table(
        title=f"figures of merit (runs {figures.temperature_min_degc:.1f}..{figures.temperature_max_degc:.1f} degC)"
    )
    table.add_column("figure")
    names = list(next(iter(figures.axes.values())).__dataclass_fields__) if figures.axes else []
    for axis in figures.axes:
        table.add_column(axis, justify="right")
    for name in names:
        table.add_row(name, *(_number(getattr(f, name)) for f in figures.axes.values()))
    console.print(table)
    for message in record.warnings:
        console.print(f"warning at fit: {message}")


def _number(value: float) -> str:
    return "-" if math.isnan(value) else f"{value:.4g}"


def _print_history(rows) -> None:
    table = Table(title=f"unit {rows[0].serial}: {len(rows)} calibration(s)")
    for column in ("id", "calibrated (UTC)", "status", "verdict", "runs", "input hash", "error"):
        table.add_column(column, overflow="fold")
    for r in rows:
        table.add_row(
            str(r.id),
            f"{r.calibrated_utc:%Y-%m-%d %H:%M:%S}",
            r.status,
            r.verdict or "-",
            str(len(r.inputs)),
            r.input_hash[:12],
            r.error or "",
        )
    make_console().print(table)


@fleet.command("report")
@click.argument("store")
@click.option("-o", "--output", required=True, type=OUTPUT_FILE, help="HTML file to write.")
@click.option(
    "--limits",
    "limits_file",
    default=None,
    type=click.Path(dir_okay=False),
    help="Judge the units by these limits (TOML; default: the verdicts stored with each calibration).",
)
@click.pass_context
def report(ctx, store, output, limits_file):
    """One HTML page of the fleet in STORE (folder, SQLite file or URL): yield, distributions of every figure,
    outliers, the worst units, rejected and failed units."""
    limits = Limits.load(limits_file) if limits_file else None
    with CalibrationStore(store) as db:
        _refuse_output_over_store(output, db)
        table = fleet_table(db.latest_rows(), limits)
        title = db.location
    page = build_fleet_report(table, limits=limits, title=title)
    write_text_atomic(output, page.html)
    if not ctx.obj["quiet"]:
        echo(f"wrote {output} ({len(table)} units; sections: {', '.join(page.sections)})")


@fleet.command("certificate")
@click.argument("serial")
@click.option("--store", required=True, help="The fleet folder, an SQLite file or a SQLAlchemy URL.")
@click.option("-o", "--output", required=True, type=OUTPUT_FILE, help="HTML file to write.")
@click.option(
    "--pdf",
    "pdf",
    default=None,
    type=OUTPUT_FILE,
    help="Also print it to this PDF (headless Chromium: apt-get install chromium).",
)
@click.option(
    "--limits",
    "limits_file",
    default=None,
    type=click.Path(dir_okay=False),
    help="Judge the unit by these limits (TOML; default: the verdict stored with its calibration).",
)
@click.option(
    "--at",
    "at",
    default=None,
    metavar="DATE",
    help="The certificate of the calibration valid at this date or time (default: the newest).",
)
@read_options
@click.pass_context
def certificate(ctx, serial, store, output, pdf, limits_file, at, **kwargs):
    """The calibration certificate of unit SERIAL: one self-contained HTML page (and its PDF) with the station,
    time, inputs' hashes, version, model, valid range, held-out residual with its 95 % band, figures of merit
    against the limits and the verdict. The unit's runs are read again (and checked against their hashes)."""
    opts = pop_read_options(kwargs)
    limits = Limits.load(limits_file) if limits_file else None
    with CalibrationStore(store) as db:
        for path in (output, pdf):
            if path is not None:
                _refuse_output_over_store(path, db)
        record = db.valid_at(serial, parse_time(at) if at else None)
    write_certificate(record, output, pdf, limits, read_settings(opts), opts["fmt"])
    if not ctx.obj["quiet"]:
        echo(f"wrote {output}" + (f" and {pdf}" if pdf else "") + f" (unit {serial}, row {record.id})")


def write_certificate(record, output, pdf, limits, read=None, fmt=None) -> None:
    """Build the certificate of ``record`` and write it (and its PDF) atomically; neither output may be one of the
    unit's runs (read again for the residual), nor the PDF the HTML page it prints."""
    runs = [i.path for i in record.inputs]
    refuse_to_overwrite_inputs(output, runs, "-o", f"one of unit {record.serial}'s runs")
    if pdf is not None:
        refuse_to_overwrite_inputs(pdf, runs, "--pdf", f"one of unit {record.serial}'s runs")
        refuse_to_overwrite_inputs(pdf, [output], "--pdf", "the HTML page (-o) it is printed from")
    page = build_certificate(record, held_out=held_out_of(record, read, fmt), limits=limits)
    write_text_atomic(output, page.html)
    if pdf is not None:
        print_pdf(output, pdf)


@fleet.command("export")
@click.argument("serial")
@click.option("--store", required=True, help="The fleet folder, an SQLite file or a SQLAlchemy URL.")
@click.option(
    "--format",
    "fmt",
    type=click.Choice(tuple(EXPORTERS)),
    required=True,
    help="; ".join(exporter.help() for exporter in EXPORTERS.values()) + ".",
)
@click.option("-o", "--output", required=True, type=click.Path(), help="File (c: folder) to write.")
@click.option("--at", "at", default=None, metavar="DATE", help="Export the calibration valid at this date or time.")
@click.option("--rate", "rate_hz", type=FINITE, default=None, help="c: the sample rate the code will run at [Hz].")
@click.option("--instance", type=int, default=None, help="As gyrocomp export.")
@click.option("--device-id", type=int, default=None, help="PX4: the gyro's device id (default: the model's).")
@click.option("--accel-device-id", type=int, default=None, help="PX4: the accelerometer's device id.")
@click.pass_context
def export(ctx, serial, store, fmt, output, at, rate_hz, instance, device_id, accel_device_id):
    """Write the calibration of unit SERIAL from the store as autopilot parameters, C code or a model file."""
    when = parse_time(at) if at is not None else None
    with CalibrationStore(store) as db:
        _refuse_output_over_store(output, db)
        calibration = db.valid_at(serial, when).calibration()
    write_export(
        calibration,
        fmt,
        output,
        rate_hz=rate_hz,
        instance=instance,
        device_id=device_id,
        accel_device_id=accel_device_id,
        quiet=ctx.obj["quiet"],
    )


def _refuse_output_over_store(output, db: CalibrationStore) -> None:
    """An output is never written over the store it reads (the store is an input too)."""
    if db.file is not None:
        refuse_to_overwrite_inputs(output, [db.file], "-o")


__all__ = ["fleet"]
