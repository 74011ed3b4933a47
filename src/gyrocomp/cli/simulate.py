"""``gyrocomp simulate``: parse its options, call the library, print the result."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import click

from ..errors import InputError
from ..io import output_format, write_recording, write_text_atomic
from ..simulation import (
    ONE_TEMPERATURE_PROFILES,
    Simulation,
    preset_model,
    resolve_profile,
    run_profiles,
    truth_document,
)
from ..simulation import simulate as run_simulation
from .common import FINITE, OUTPUT_FILE, float_list, echo


@click.command()
@click.option(
    "--preset",
    default="mti10",
    show_default=True,
    help="Sensor: adxrs450, mti10, adis16488 or consumer (values from datasheets; see the docs).",
)
@click.option(
    "--profile",
    default="chamber",
    show_default=True,
    help="static, warmup, chamber, cycle, tumble, combined or ratetable.",
)
@click.option(
    "--duration",
    "duration_s",
    type=FINITE,
    default=None,
    help="Run length [s] (default: the profile's own; a set duration stretches the profile).",
)
@click.option("--rate", "rate_hz", type=FINITE, default=100.0, show_default=True, help="Sample rate [Hz].")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of run 0; run i uses seed + i.")
@click.option(
    "--runs",
    type=int,
    default=1,
    show_default=True,
    help="Write K power-ons (own turn-on bias and noise) as OUT_0.csv ... OUT_{K-1}.csv.",
)
@click.option(
    "--unit", type=int, default=None, help="Simulate unit N of the preset's production spread (default: nominal)."
)
@click.option("--axes", default=None, help="Gyro axes to simulate, e.g. z or x,y,z (default: all of the preset's).")
@click.option(
    "--disable",
    default=None,
    metavar="TERM,...",
    help="Switch error terms off: temperature, lag, hysteresis, g-sensitivity, scale-factor, "
    "misalignment, turn-on, noise, quantization, temperature-noise.",
)
@click.option(
    "--set-points",
    "set_points_degc",
    default=None,
    metavar="T1,T2,...",
    help="Chamber set points [degC] (default: the preset's range); static, tumble and ratetable: one run "
    "per set point.",
)
@click.option(
    "--ramp-rate", "ramp_rate_degc_per_min", type=FINITE, default=None, help="Ramp rate between set points [degC/min]."
)
@click.option("--dwell", "dwell_s", type=FINITE, default=None, help="Time held at each set point [s].")
@click.option("--cycles", type=int, default=None, help="Cold-hot-cold repetitions of the cycle profile.")
@click.option(
    "--position-time",
    "position_s",
    type=FINITE,
    default=None,
    help="Time at each tumble position or rate-table rate [s].",
)
@click.option(
    "--rates",
    "rates",
    default=None,
    metavar="R1,R2,...",
    help="ratetable: rates applied about each axis in turn [deg/s], e.g. 100,-100,300,-300 (the file gets "
    "ref_rate_x/y/z columns; the first --set-points value is the table's temperature).",
)
@click.option("-o", "--output", required=True, type=OUTPUT_FILE, help="Output CSV or Parquet.")
@click.option("--truth", type=OUTPUT_FILE, help="Write every parameter used as JSON here.")
@click.option(
    "--truth-columns",
    is_flag=True,
    help="Add true_error_gyro_*, true_noise_gyro_*, true_rate_gyro_* and true_structure_temperature columns.",
)
@click.pass_context
def simulate(
    ctx,
    preset,
    profile,
    duration_s,
    rate_hz,
    seed,
    runs,
    unit,
    axes,
    disable,
    set_points_degc,
    ramp_rate_degc_per_min,
    dwell_s,
    cycles,
    position_s,
    rates,
    output,
    truth,
    truth_columns,
):
    """Simulate calibration runs of a sensor preset through a test profile, with the exact truth."""
    model = _preset_model(preset, unit, axes, disable)
    if runs < 1:
        raise click.BadParameter("must be at least 1", param_hint="--runs")
    prof = resolve_profile(
        profile,
        preset,
        set_points_degc=float_list(set_points_degc, "--set-points"),
        ramp_rate_degc_per_min=ramp_rate_degc_per_min,
        dwell_s=dwell_s,
        cycles=cycles,
        position_s=position_s,
        rates_dps=float_list(rates, "--rates"),
    )
    if runs == 1 and prof.name in ONE_TEMPERATURE_PROFILES and len(prof.set_points_degc) > 1:
        runs = len(prof.set_points_degc)  # one run per temperature
    profiles = run_profiles(prof, runs)
    paths = _output_paths(output, runs, truth)
    records = []
    for i, path in enumerate(paths):
        sim = run_simulation(
            model, profile=profiles[i], duration_s=duration_s, rate_hz=rate_hz, seed=seed + i, source=str(path)
        )
        sim = Simulation(sim.recording, dataclasses.replace(sim.truth, preset=preset, unit=unit))
        write_recording(sim.recording, path, extra_columns=sim.truth.truth_columns() if truth_columns else None)
        records.append((path, sim))
        if not ctx.obj["quiet"]:
            rec = sim.recording
            gaps = f", {len(rec.gaps)} gaps" if rec.gaps else ""
            echo(f"wrote {path}: {rec.n_samples} rows, {rec.duration_s:g} s at {rate_hz:g} Hz{gaps}")
    if truth:
        doc = truth_document([(path.name, sim) for path, sim in records])
        write_text_atomic(truth, json.dumps(doc, indent=2) + "\n")


__all__ = ["simulate"]


def _preset_model(preset: str, unit: str, axes: str | None, disable: str | None):
    """The preset's sensor model in ``unit``, with the axes of ``--axes`` and without the terms of ``--disable``."""
    model = preset_model(preset, unit)
    if axes:
        model = model.subset(tuple(f"gyro_{a.strip()}" for a in axes.split(",") if a.strip()))
    if disable:
        model = model.without(*(t.strip() for t in disable.split(",") if t.strip()))
    return model


def _output_paths(output: str, runs: int, truth: str | None) -> list[Path]:
    """The file of each run (``output`` itself for one run, numbered beside it for several)."""
    output_format(output)
    out = Path(output)
    paths = [out] if runs == 1 else [out.with_name(f"{out.stem}_{i}{out.suffix}") for i in range(runs)]
    if truth and any(Path(truth).resolve() == p.resolve() for p in paths):
        raise InputError(f"--truth {truth}: the same file as a data output; choose another path")
    return paths
