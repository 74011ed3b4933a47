"""``gyrocomp split``: parse its options, call the library, print the result."""

from __future__ import annotations

from pathlib import Path

import click

from ..errors import InputError
from ..io import refuse_to_overwrite_inputs, write_rows
from ..io.tables import PARQUET_SUFFIXES
from ..runs.runsplit import SPLITS, split_runs
from .common import FINITE, pop_read_options, read_options, read_run, echo


@click.command()
@click.argument("log", type=click.Path())
@click.option(
    "-o",
    "--output",
    "folder",
    required=True,
    type=click.Path(file_okay=False),
    help="Folder to write the runs to (made when missing): LOG_run1.csv, LOG_run2.csv, ...",
)
@click.option(
    "--by",
    "by",
    required=True,
    type=click.Choice(SPLITS),
    help="Where to cut: power-on (gaps of --min-gap or more), gap (every time gap), still (still "
    "segments of --min-still or more), temperature-turn (each heating or cooling leg).",
)
@click.option(
    "--min-gap",
    "min_gap_s",
    type=FINITE,
    default=60.0,
    show_default=True,
    help="power-on: the shortest gap between two power-ons [s].",
)
@click.option(
    "--min-still",
    "min_still_s",
    type=FINITE,
    default=600.0,
    show_default=True,
    help="still: the shortest still segment kept [s].",
)
@click.option(
    "--min-leg",
    "min_leg_degc",
    type=FINITE,
    default=2.0,
    show_default=True,
    help="temperature-turn: how far the temperature must come back for a turn to count [degC].",
)
@click.option(
    "--suffix",
    type=click.Choice(("csv", "tsv", "parquet")),
    default=None,
    help="Format of the runs written (default: the log's, for a table; csv for any other log).",
)
@read_options
@click.pass_context
def split(ctx, log, folder, by, min_gap_s, min_still_s, min_leg_degc, suffix, **kwargs):
    """Cut LOG into runs, one file each, so that a recording of several power-ons, poses or temperature legs
    becomes the runs a fit takes. A table's runs keep its columns and units (the project file that reads the
    log reads them), a text table's separator where the runs' names allow (a .csv run: commas or semicolons); any other log's
    are written in canonical columns."""
    opts = pop_read_options(kwargs)
    data = read_run(log, opts)
    recording = data.recording
    pieces = split_runs(recording, by, min_gap_s=min_gap_s, min_still_s=min_still_s, min_leg_degc=min_leg_degc)
    suffix = suffix or _table_suffix(log, data)
    out = Path(folder)
    names = [out / f"{Path(log).name.split('.')[0]}_run{k + 1}.{suffix}" for k in range(len(pieces))]
    existing = [str(p) for p in names if p.exists()]
    if existing:
        raise InputError(f"-o {folder}: {existing[0]} exists; split into an empty folder")
    for path in names:
        refuse_to_overwrite_inputs(path, [log], option="-o")
    out.mkdir(parents=True, exist_ok=True)
    t0 = float(recording.time_s[0])
    for piece, path in zip(pieces, names):
        write_rows(data, slice(piece.start, piece.stop), path)
    if not ctx.obj["quiet"]:
        echo(f"wrote {len(pieces)} run(s) of {log} to {folder} (by {by}):")
        for piece, path in zip(pieces, names):
            rec = piece.recording
            echo(
                f"  {path.name}: {rec.n_samples} rows, {rec.time_s[0] - t0:.6g} .. {rec.time_s[-1] - t0:.6g} s"
                + (
                    ""
                    if rec.temperature_degc is None
                    else f", {rec.temperature_degc.min():.2f} .. {rec.temperature_degc.max():.2f} degC"
                )
            )


def _table_suffix(log: str, data) -> str:
    """The suffix of the runs written by default: the log's own where it is a table (``.csv``, ``.tsv``,
    ``.parquet``; ``.txt`` and compressed tables as ``.csv``, or ``.tsv`` when tab-separated), else ``csv``."""
    name = Path(log).name.lower()
    if data.text_format is None:
        return "parquet" if name.endswith(PARQUET_SUFFIXES) else "csv"
    return "tsv" if data.text_format.delimiter == "\t" else "csv"


__all__ = ["split"]
