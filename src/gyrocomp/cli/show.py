"""``gyrocomp show``: what a model file holds, in one screen (or as JSON)."""

from __future__ import annotations

import json

import click
from rich.table import Table

from ..calibration import Calibration
from .common import make_console, echo
from .render import print_expected_drift


@click.command()
@click.argument("model", type=click.Path(dir_okay=False))
@click.option("--json", "as_json", is_flag=True, help="Print the summary as JSON (for scripts).")
@click.pass_context
def show(ctx, model, as_json):
    """What MODEL is: its axes (curve, range, lag, memory, G), the runs it came from (with their device ids), and
    the drift its held-out folds expect."""
    calibration = Calibration.load(model)
    summaries = calibration.summaries()
    expected = calibration.report.expected_drift()
    inputs = [i for i in (calibration.provenance or {}).get("inputs", ()) if isinstance(i, dict)]
    if as_json:
        echo(
            json.dumps(
                {
                    "model": calibration.model,
                    "schema_version": calibration.schema_version,
                    "target": calibration.fit_report.get("target", "model"),
                    "axes": [a.to_dict() for a in summaries],
                    "expected_held_out_drift": [e.to_dict() for e in expected.values()],
                    "provenance": calibration.provenance,
                },
                indent=2,
            ),
            lines=True,
        )
        return
    if ctx.obj["quiet"]:
        return
    console = make_console()
    prov = calibration.provenance or {}
    console.print(
        f"{model}: {calibration.model} (schema {calibration.schema_version}), fitted "
        f"{prov.get('created_utc', '?')} by gyrocomp {prov.get('gyrocomp_version', '?')} on "
        f"{len(inputs)} run(s)"
    )
    table = Table(title="axes")
    for col in ("axis", "model", "range [degC]", "lag [s]", "G [unit/g]", "turn-on constants"):
        table.add_column(col, justify="left" if col in ("axis", "model") else "right")
    for a in summaries:
        span = "-" if a.range_degc is None else f"{a.range_degc[0]:.1f} .. {a.range_degc[1]:.1f}"
        table.add_row(
            a.axis,
            a.model,
            span,
            f"{a.lag_time_constant_s:.3g}" if a.lag_time_constant_s else "-",
            "-" if a.g_row is None else " ".join(f"{g:+.3g}" for g in a.g_row),
            ", ".join(f"{c:+.3g}" for c in a.turn_on_biases[:4])
            + (" ..." if len(a.turn_on_biases) > 4 else "")
            + f" {a.unit}",
        )
    console.print(table)
    for name, triad in (("gyro", calibration.gyro_triad), ("accelerometer", calibration.accel_triad)):
        if triad is not None:
            console.print(f"{name} scale factor and misalignment: {triad.method}")
    ids = sorted({(i.get("device_id"), i.get("accel_device_id")) for i in inputs} - {(None, None)})
    if ids:
        console.print("device ids (gyro, accelerometer): " + ", ".join(f"{g}, {a}" for g, a in ids))
    print_expected_drift(expected)


__all__ = ["show"]
